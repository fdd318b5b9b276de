"""Tests for course_lib.ros.session: a background ROS session that survives re-run notebook cells."""

import subprocess
import sys
import threading
import time

import pytest
import rclpy
from rclpy.exceptions import InvalidHandle
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

from course_lib.ros import discovery, graph, rosenv, run_limits, session


class Counter(Node):
    """Counts the ticks of a fast timer and remembers which thread ran them."""

    def __init__(self, name="counter", period=0.02):
        super().__init__(name)
        self.ticks = 0
        self.threads = set()
        self.create_timer(period, self.tick)

    def tick(self):
        self.ticks += 1
        self.threads.add(threading.current_thread().name)


class Failing(Node):
    """A node whose timer callback always raises, like a student's buggy callback."""

    def __init__(self):
        super().__init__("failing")
        self.create_timer(0.02, self.tick)

    def tick(self):
        raise ValueError("boom from a callback")


@pytest.fixture(autouse=True)
def no_session_left():
    """Every test starts without a session and leaves none behind."""
    session.stop()
    session.clear_errors()
    yield
    session.stop()
    session.clear_errors()


@pytest.fixture
def quick_graph(monkeypatch):
    """graph queries without the discovery wait: these tests only look at in-process nodes."""
    monkeypatch.setattr(discovery, "SETTLE_SECONDS", 0.0)


def test_start_twice_is_idempotent(domain_id):
    """A second start() keeps the running executor thread and the same ROS context."""
    session.start(domain_id=domain_id)
    first = (session._state.thread, session._state.context)
    session.start()
    session.start(domain_id=domain_id)
    assert session.is_running()
    assert (session._state.thread, session._state.context) == first
    assert rclpy.utilities.get_default_context().get_domain_id() == domain_id


def test_start_on_another_domain_names_the_fix(domain_id):
    """Asking a running session for another domain fails and says to stop first."""
    session.start(domain_id=domain_id)
    other = domain_id + 1 if domain_id < 101 else domain_id - 1
    with pytest.raises(ValueError, match="session.stop"):
        session.start(domain_id=other)


def test_readding_a_node_replaces_the_old_one(domain_id, quick_graph):
    """Re-running a cell that adds a node leaves one node of that name, the new one."""
    session.start(domain_id=domain_id)
    old = session.add_node(Counter())
    assert session.wait_for(lambda: old.ticks >= 2, timeout=10)
    new = session.add_node(Counter())
    assert session.nodes() == [new]
    with pytest.raises(InvalidHandle, match="destruction was requested"):  # the old node was destroyed
        old.get_fully_qualified_name()
    assert session.wait_for(lambda: graph.node_list().count("/counter") == 1, timeout=30), \
        graph.node_list()
    ticks_of_old = old.ticks
    assert session.wait_for(lambda: new.ticks >= 3, timeout=10)
    assert old.ticks == ticks_of_old


def test_recreating_a_node_replaces_it_without_warning_and_keeps_the_graph_right(domain_id, quick_graph, capfd):
    """Re-running `listener = session.add_node(Listener())`: the old node goes before the new one
    exists, so rcl does not warn "Publisher already registered" and the graph names the new
    node's subscription (not _NODE_NAME_UNKNOWN_)."""
    from std_msgs.msg import String

    class Listener(Node):
        def __init__(self):
            super().__init__("listener")
            self.create_subscription(String, "chatter", lambda msg: None, 10)

    session.start(domain_id=domain_id)
    old = session.add_node(Listener())
    new = session.add_node(Listener())
    # The old node was destroyed when the new one was created.
    with pytest.raises(InvalidHandle, match="destruction was requested"):
        old.get_fully_qualified_name()
    assert session.nodes() == [new]
    subscribers = [endpoint.node for endpoint in graph.topic_info("/chatter").subscriptions]
    assert subscribers == ["/listener"]
    assert "already registered" not in capfd.readouterr().err


def test_a_node_created_after_stop_says_to_start_the_session(domain_id):
    """After the clean-up cell, re-running a node cell names session.start(), not rclpy.init()."""
    session.start(domain_id=domain_id)
    session.stop()
    with pytest.raises(session.SessionStopped, match=r"Run session.start\(\)"):
        Counter()
    session.start(domain_id=domain_id)
    assert session.add_node(Counter()).get_name() == "counter"


def test_a_node_in_a_context_of_its_own_is_left_alone(domain_id):
    """A node made with context=... (e.g. a helper's watcher) neither replaces a session node
    nor needs the session."""
    from rclpy.context import Context

    session.start(domain_id=domain_id)
    held = session.add_node(Counter())
    context = Context()
    rclpy.init(context=context, domain_id=domain_id)
    try:
        Node("counter", context=context).destroy_node()
        assert session.nodes() == [held] and held.get_name() == "counter"
    finally:
        context.try_shutdown()


def test_adding_the_same_node_twice_keeps_it(domain_id):
    """add_node() of a node the session already spins returns it and changes nothing."""
    session.start(domain_id=domain_id)
    node = session.add_node(Counter())
    assert session.add_node(node) is node
    assert session.nodes() == [node]


def test_stop_then_start_again_works(domain_id):
    """After stop(), start() brings up a fresh session, and stale nodes are refused by name."""
    session.start(domain_id=domain_id)
    assert session.domain_id() == domain_id
    old = session.add_node(Counter())
    session.stop()
    assert not session.is_running() and session.domain_id() is None
    assert session.nodes() == []
    assert not rclpy.ok()
    session.start(domain_id=domain_id)
    assert session.is_running()
    new = session.add_node(Counter())
    assert session.wait_for(lambda: new.ticks >= 3, timeout=10)
    with pytest.raises(ValueError, match="create it again"):
        session.add_node(old)


def test_stop_without_start_does_nothing():
    """stop() is safe to call when nothing runs (a notebook's last cell, re-run)."""
    session.stop()
    assert not session.is_running()


def test_spin_for_keeps_callbacks_running_in_the_background(domain_id):
    """While a cell waits in spin_for(), timer callbacks run, in the session's thread."""
    session.start(domain_id=domain_id)
    node = session.add_node(Counter())
    before = node.ticks
    waited = session.spin_for(1.0)
    assert waited >= 1.0
    assert node.ticks > before
    assert node.threads == {"course_lib.ros.session"}


def test_wait_for_returns_false_when_time_runs_out(domain_id):
    """wait_for() is bounded: a predicate that never holds gives False, not a hang."""
    session.start(domain_id=domain_id)
    assert session.wait_for(lambda: False, timeout=0.2) is False


def test_an_interrupted_wait_leaves_the_session_spinning(domain_id):
    """KeyboardInterrupt (the kernel's interrupt button) ends the wait, not the session."""
    session.start(domain_id=domain_id)
    node = session.add_node(Counter())
    calls = []

    def interrupted():
        calls.append(1)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return False

    with pytest.raises(KeyboardInterrupt):
        session.wait_for(interrupted, timeout=10)
    assert session.is_running()
    ticks = node.ticks
    assert session.wait_for(lambda: node.ticks > ticks + 2, timeout=10)


def test_a_failing_callback_is_reported_once_and_spinning_goes_on(domain_id, capsys):
    """A callback's exception is printed once, kept in errors(), and other nodes keep running."""
    session.start(domain_id=domain_id)
    session.add_node(Failing())
    counter = session.add_node(Counter())
    assert session.wait_for(lambda: len(session.errors()) >= 3 and counter.ticks >= 3,
                            timeout=10)
    assert session.is_running()
    assert all(isinstance(error, ValueError) for error in session.errors())
    assert capsys.readouterr().err.count("ValueError: boom from a callback") == 1


def test_remove_node_by_plain_name(domain_id):
    """remove_node('name') destroys that node and keeps the others."""
    session.start(domain_id=domain_id)
    first = session.add_node(Counter("first"))
    second = session.add_node(Counter("second"))
    session.remove_node("first")
    assert session.nodes() == [second]
    with pytest.raises(InvalidHandle, match="destruction was requested"):
        first.get_fully_qualified_name()
    session.remove_node(second)
    assert session.nodes() == []


TWO_REMOVALS = """
import threading
from course_lib.ros import session
from rclpy.node import Node
session.start()
begun, cell_waits = threading.Event(), threading.Event()
leaving = session.add_node(Node("leaving"))
removed_by_callback = []

def remove_when_asked():
    if cell_waits.is_set() and not removed_by_callback:
        begun.set()
        session.remove_node(leaving)
        removed_by_callback.append(leaving)

session.add_node(Node("view")).create_timer(0.01, remove_when_asked)
deliver = session.node_logs.deliver

def deliver_once_the_callback_began():
    # _remove calls node_logs.deliver first: in the cell's call, hold there until the callback runs
    if threading.current_thread() is threading.main_thread() and not begun.is_set():
        cell_waits.set()
        assert begun.wait(10), "the timer callback did not run"
    deliver()

session.node_logs.deliver = deliver_once_the_callback_began
session.add_node(Node("in_the_cell"))
session.remove_node("in_the_cell")
print("left:", [node.get_name() for node in session.nodes()], "removed by the callback:",
      [node is leaving for node in removed_by_callback], flush=True)
session.stop()
"""


def test_a_callback_that_removes_a_node_while_a_cell_removes_another_deadlocks_neither(domain_id):
    """A live view's redraw timer removes its own node when its time is up (course_lib.live), from
    the session's thread, which holds the executor during the callback; a cell may remove a node at
    that very moment. Lesson 02 hung for 306 s in a suite run: the cell held the session's lock
    while it waited for the executor, and the callback held the executor while it waited for the
    lock. Here the cell's removal goes on exactly when the callback has begun (in a process of its
    own: a deadlock would hold the session's lock for good)."""
    try:
        result = subprocess.run([sys.executable, "-c", TWO_REMOVALS], capture_output=True, text=True,
                                env=rosenv.ros_environment(domain_id=domain_id), timeout=60)
    except subprocess.TimeoutExpired:
        pytest.fail("the two removals deadlocked: the process still ran after 60 s")
    assert result.returncode == 0, result.stderr
    assert "left: ['view'] removed by the callback: [True]" in result.stdout, result.stdout


def test_stop_while_a_callback_removes_its_node_waits_for_the_callback_only(domain_id, capsys):
    """stop() waits for the running callback without holding the session's lock: a live view's
    timer that removes its own node as stop() begins ends at once, and stop() does not report a
    callback still running (it held the lock, the callback waited for it until stop's timeout)."""
    session.start(domain_id=domain_id)
    in_callback, armed, removed = threading.Event(), threading.Event(), []
    view = session.add_node(Node("view"))

    def remove_own_node_when_stopping():
        if armed.is_set() and not in_callback.is_set():
            in_callback.set()
            assert session._state.stopping.wait(10)
            session.remove_node(view)
            removed.append(view)

    view.create_timer(0.01, remove_own_node_when_stopping)
    armed.set()
    assert in_callback.wait(10), "the timer callback did not run"
    session.stop(timeout=30)
    assert removed == [view] and not session.is_running()
    assert "still running" not in capsys.readouterr().err


def test_remove_node_of_an_unknown_name_lists_the_known_ones(domain_id):
    """A wrong name in remove_node() gets an error that lists the names to use."""
    session.start(domain_id=domain_id)
    session.add_node(Counter("present"))
    with pytest.raises(ValueError, match="/present"):
        session.remove_node("absent")


def test_add_node_refuses_what_is_not_a_node(domain_id):
    """Passing the class instead of an instance (a common slip) gets a TypeError."""
    session.start(domain_id=domain_id)
    with pytest.raises(TypeError, match="MyNode"):
        session.add_node(Counter)


def test_add_node_starts_the_session_when_rclpy_was_initialised_by_hand(domain_id):
    """A notebook that called rclpy.init() itself can still hand its nodes to the session."""
    rclpy.init(domain_id=domain_id, signal_handler_options=SignalHandlerOptions.NO)
    try:
        node = session.add_node(Counter())
        assert session.is_running()
        assert session.wait_for(lambda: node.ticks >= 2, timeout=10)
    finally:
        session.stop()
        rclpy.try_shutdown()


def test_tool_node_is_hidden_lazy_and_single(domain_id):
    """The tool node is made on first use, once, and is not among the student's nodes."""
    session.start(domain_id=domain_id)
    assert session._state.tool is None
    tool = session.tool_node()
    assert session.tool_node() is tool
    assert tool.get_name() == session.tool_node_name()
    assert tool.get_name().startswith("_")
    assert session.nodes() == []


def test_unbounded_spin_for_ends_under_test(domain_id, monkeypatch):
    """spin_for() with no duration, which runs until interrupted live, returns under test: its
    wait asks for TEST_TIME_LIMIT (how much longer it took is the machine's doing)."""
    assert rosenv.under_test()
    session.start(domain_id=domain_id)
    asked, wait_for = [], session.wait_for
    monkeypatch.setattr(session, "wait_for", lambda predicate, timeout=10.0, poll=0.02: (
        asked.append(timeout), wait_for(predicate, timeout, poll))[1])
    assert session.spin_for() >= run_limits.TEST_TIME_LIMIT
    assert asked == [run_limits.TEST_TIME_LIMIT]


KERNEL_EXIT = """
import atexit
# Registered before the session's handler, so it runs after it (atexit is last-in, first-out).
atexit.register(lambda: print("running at exit:", session.is_running(), flush=True))
from course_lib import session
from rclpy.node import Node
session.start()
session.add_node(Node("exiting"))
print("started:", session.is_running(), flush=True)
"""


def test_the_session_stops_itself_when_the_interpreter_exits(domain_id):
    """A kernel that exits with a running session shuts ROS down cleanly (exit code 0)."""
    result = subprocess.run([sys.executable, "-c", KERNEL_EXIT], capture_output=True, text=True,
                            env=rosenv.ros_environment(domain_id=domain_id), timeout=60)
    assert result.returncode == 0, result.stderr
    assert "started: True" in result.stdout
    assert "running at exit: False" in result.stdout


class SlowToNote:
    """An action client's handle that, after sending a goal request, holds the sending thread a
    moment, as a busy machine may between rclpy's send and its note of the request's number."""

    def __init__(self, handle):
        self._handle = handle

    def __getattr__(self, name):
        return getattr(self._handle, name)

    def __enter__(self):
        return self._handle.__enter__()

    def __exit__(self, *exc):
        return self._handle.__exit__(*exc)

    def send_goal_request(self, request):
        number = self._handle.send_goal_request(request)
        time.sleep(0.3)  # the session's thread meanwhile gets the server's answer
        return number


def test_a_goal_answered_before_the_client_noted_its_request_still_completes(domain_id):
    """rclpy issue #1123 (course_lib.ros.rclpy_backports): a goal sent from a cell while the
    session's thread spins the client completes even when the answer comes before rclpy has
    noted the request (without the fix rclpy drops it as from 'more than one action server')."""
    from rclpy.action import ActionClient, ActionServer
    from test_msgs.action import Fibonacci

    def execute(goal_handle):
        goal_handle.succeed()
        return Fibonacci.Result(sequence=[0, 1])

    session.start(domain_id=domain_id)
    node = session.add_node(Node("goal_pair"))
    ActionServer(node, Fibonacci, "fibonacci", execute)
    client = ActionClient(node, Fibonacci, "fibonacci")
    assert session.wait_for(client.server_is_ready, timeout=30)
    client._client_handle = SlowToNote(client._client_handle)
    sent = client.send_goal_async(Fibonacci.Goal(order=1))
    assert session.wait_for(sent.done, timeout=30), "the goal's answer was dropped"
    assert sent.result().accepted
    finished = sent.result().get_result_async()
    assert session.wait_for(finished.done, timeout=30) and list(finished.result().result.sequence) == [0, 1]


FIX_ON_IMPORT = """
import sys
from course_lib.ros import rclpy_backports
rclpy_backports.install()
print("numpy" in sys.modules, "rclpy.action" in sys.modules)
from rclpy.action import ActionClient
fixed_upstream = "_lock" in ActionClient.__init__.__code__.co_names
print(fixed_upstream or all(hasattr(getattr(ActionClient, name), "__wrapped__")
                            for name in rclpy_backports.LOCKED_METHODS))
"""


def test_the_fix_is_applied_when_rclpy_action_is_imported_after_the_session_started():
    """A process that starts the session before it imports rclpy.action (a ros2 command, a cell
    that makes its first action client) gets the fix at that import; until then neither rclpy.action
    nor numpy is imported (a fifth of a ros2 command's processor time)."""
    done = subprocess.run([sys.executable, "-c", FIX_ON_IMPORT], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["False", "False", "True"], done.stdout + done.stderr


@pytest.mark.parametrize("end", ["remove_node", "stop"])
def test_a_node_with_an_action_client_and_server_leaves_the_graph(domain_id, end):
    """Jazzy's destroy_node() leaves the action clients and servers made on a node, and they keep
    the node in the graph; the session destroys them with the node. (A client a cell made and
    never destroyed kept the lesson 04 check's node in the domain, where a later check saw it.)"""
    from rclpy.action import ActionClient, ActionServer
    from test_msgs.action import Fibonacci

    from course_lib.checks.probe import RosProbe

    session.start(domain_id=domain_id)
    node = session.add_node(Node("with_actions"))
    ActionClient(node, Fibonacci, "fibonacci")
    ActionServer(node, Fibonacci, "fibonacci", lambda goal_handle: Fibonacci.Result())
    with RosProbe(domain_id) as probe:
        def listed():
            return "with_actions" in [name for name, _ in probe.node.get_node_names_and_namespaces()]

        assert probe.spin_until(listed, 30.0), "the node never appeared"
        session.remove_node(node) if end == "remove_node" else session.stop()
        assert probe.spin_until(lambda: not listed(), 30.0), f"the node stayed in the graph after {end}()"
