"""course_lib.ros.sigterm: `kill` (SIGTERM) ends a node's spin as Ctrl-C does.

The node here has no timer and no interface package: what lesson 04's server and the services_actions
reference node (tests/lessons/test_find_pictures_server.py, tests/assignments/test_pan_camera_node.py)
have in common. Without end_spin_as_ctrl_c() its main() hung after SIGTERM in each of three runs of
support.sigterm_rounds (rounds 6, 19 and 26: the main thread waiting in
Executor._wait_for_ready_callbacks's wait_set.wait, the context down).
"""

from __future__ import annotations

import signal
import subprocess
import sys
import threading

import pytest
from support import sigterm_rounds

from course_lib import contract
from course_lib.ros import rosenv, sigterm

#: A node without timers, spun by a MultiThreadedExecutor, main() as the course's nodes write it.
PLAIN_NODE = """\
import rclpy
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.node import Node

from course_lib.ros import sigterm


def main(args=None):
    sigterm.end_spin_as_ctrl_c()
    rclpy.init(args=args)
    node = None
    try:
        node = Node("plain_node")
        rclpy.spin(node, executor=MultiThreadedExecutor())
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
"""

#: Calls the handler while the main thread holds the default context's lock (as when SIGTERM
#: interrupts rclpy.ok() or the executor's context.ok()), with the context up, then down.
HANDLER_TIMES = """\
import time
import rclpy
from rclpy.utilities import get_default_context
from course_lib.ros import sigterm

def handler_time():
    start = time.monotonic()
    try:
        sigterm._end_as_ctrl_c(15, None)
    except KeyboardInterrupt:
        return time.monotonic() - start

rclpy.init()
with get_default_context()._lock:
    up = handler_time()
rclpy.shutdown()
print(up, handler_time())
"""


def environment() -> dict:
    env = rosenv.ros_environment()
    env["PYTHONPATH"] = str(contract.ROOT) + ":" + env.get("PYTHONPATH", "")
    return env


@pytest.mark.slow
def test_sigterm_ends_a_spinning_main_every_time(tmp_path):
    """SIGTERM ends each of ROUNDS main() calls spinning a node without timers, within ENDS_WITHIN s."""
    (tmp_path / "plain_node.py").write_text(PLAIN_NODE)
    env = environment()
    env["PYTHONPATH"] = f"{tmp_path}:{env['PYTHONPATH']}"
    ran = sigterm_rounds.run_rounds("plain_node", env)
    assert ran.returncode == 0 and sigterm_rounds.DONE in ran.stdout, ran.stdout + ran.stderr[-2000:]


def test_the_handler_waits_for_the_shutdown_without_rclpys_lock():
    """With the context up the handler waits SHUTDOWN_WAIT for rclpy's thread to shut it down, even
    when the thread it interrupted holds the context's lock (rclpy.ok() would wait for ever); once the
    context is down it raises KeyboardInterrupt at once."""
    ran = subprocess.run([sys.executable, "-c", HANDLER_TIMES], env=environment(), capture_output=True, text=True,
                         timeout=60)
    assert ran.returncode == 0, ran.stderr[-2000:]
    up, down = map(float, ran.stdout.split())
    assert sigterm.SHUTDOWN_WAIT <= up < sigterm.SHUTDOWN_WAIT + 2 and down < 0.5


def test_the_handler_is_installed_from_the_main_thread_only():
    """In the main thread SIGTERM gets the handler; in another thread (no Python signal handling
    there) the call changes nothing and raises nothing."""
    before = signal.getsignal(signal.SIGTERM)
    try:
        outcome = []
        thread = threading.Thread(target=lambda: outcome.append(sigterm.end_spin_as_ctrl_c()))
        thread.start()
        thread.join()
        assert outcome == [None] and signal.getsignal(signal.SIGTERM) is before
        sigterm.end_spin_as_ctrl_c()
        assert signal.getsignal(signal.SIGTERM) is sigterm._end_as_ctrl_c
    finally:
        signal.signal(signal.SIGTERM, before)


def _spinning_mains() -> list:
    """The node modules of the course's packages whose main() spins a node without a timer (a node
    that may wait for messages that never come), and that import course_lib already. pubsub's
    nodes stay plain rclpy, as upstream's examples (they depend on nothing of the course's)."""
    from autograder.builds.reference import REFERENCE_SRC

    modules = []
    for path in sorted(REFERENCE_SRC.glob("*/*/*.py")):
        source = path.read_text()
        if "rclpy.spin(" in source and "create_timer(" not in source and "from course_lib" in source:
            modules.append(pytest.param(source, id=f"{path.parent.name}.{path.stem}"))
    return modules


@pytest.mark.parametrize("source", _spinning_mains())
def test_the_course_packages_nodes_hand_sigterm_on_before_rclpy_init(source):
    """As lesson 04's server and pan_camera (whose SIGTERM rounds are tested): a `kill` of an idle
    brightness, marker_reader or pillar node ends it as Ctrl-C does, and their templates show it."""
    main = source[source.index("def main("):]
    assert "sigterm.end_spin_as_ctrl_c()" in main
    assert main.index("sigterm.end_spin_as_ctrl_c()") < main.index("rclpy.init(")
