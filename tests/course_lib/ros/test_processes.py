"""Tests for course_lib.ros.processes: real node processes over real DDS, and no orphans ever.

Orphans are found by a unique marker in the command line (psutil), so a test only sees the
processes it started itself.
"""

import os
import signal
import subprocess
import sys

import pytest
from support.process import marker, processes_with, sleeper, wait_until

from course_lib.ros import processes
from course_lib.ros.processes import Limits, NodeProcess, python_node

TALKER = '''
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import String


class Talker(Node):
    def __init__(self):
        super().__init__("talker")
        self.publisher = self.create_publisher(String, "chatter", 10)
        self.timer = self.create_timer(0.2, self.tick)
        self.count = 0

    def tick(self):
        self.count += 1
        self.publisher.publish(String(data=f"hello {self.count}"))
        self.get_logger().info(f"Publishing hello {self.count}")


def main(args=None):
    rclpy.init(args=args)
    node = Talker()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
        print("talker shut down cleanly", flush=True)
'''


@pytest.fixture
def talker_dir(tmp_path):
    (tmp_path / "course_talker.py").write_text(TALKER)
    return tmp_path


def test_talker_is_found_logged_and_stopped_cleanly(talker_dir, domain_id):
    """A real rclpy talker appears in its domain's graph, its log has rclpy's stderr lines,
    and SIGINT runs its try_shutdown path."""
    with python_node("course_talker:main", cwd=talker_dir, domain_id=domain_id) as talker:
        talker.wait_for_node("talker", timeout=30)
        talker.wait_for_node("/talker", timeout=5)
        assert wait_until(lambda: "Publishing hello" in talker.log), talker.log
        code = talker.stop(timeout=60)  # a backstop before SIGKILL: the talker ends on the signal
    assert code in (0, -signal.SIGINT), talker.describe_exit()
    assert talker.exit_reason == "stopped"
    assert "[INFO]" in talker.log and "[talker]" in talker.log  # rclpy's logger writes to stderr
    assert "talker shut down cleanly" in talker.log
    assert not talker.running()


def test_node_in_another_namespace_is_not_mistaken(talker_dir, domain_id):
    """wait_for_node with a namespace only accepts the node in that namespace."""
    with python_node("course_talker:main", "--ros-args", "-r", "__ns:=/robot1",
                     cwd=talker_dir, domain_id=domain_id) as talker:
        talker.wait_for_node("/robot1/talker", timeout=30)
        with pytest.raises(TimeoutError, match="'/robot2/talker' did not appear"):
            talker.wait_for_node("talker", namespace="robot2", timeout=1.0)


def test_wait_for_node_warns_when_another_program_runs_a_node_of_that_name(talker_dir, domain_id, capsys):
    """A camera the previous lesson's kernel left running makes two nodes of one name: the new
    one's wait_for_node says so plainly; a node that replaced its own earlier copy does not."""
    from course_lib.ros import session

    session.start(domain_id=domain_id)
    try:
        with python_node("course_talker:main", cwd=talker_dir, domain_id=domain_id, name="left_running") as old:
            old.wait_for_node("talker", timeout=30)
            with python_node("course_talker:main", cwd=talker_dir, domain_id=domain_id, name="camera") as new:
                new.wait_for_node("talker", timeout=30)
                said = capsys.readouterr().out
                assert "Warning: another node named /talker" in said and "Shut Down Kernel" in said, said
                old.stop()
                again = python_node("course_talker:main", cwd=talker_dir, domain_id=domain_id, name="camera")
                with again:  # a re-run cell: it replaces `new`, whose node leaves the graph
                    again.wait_for_node("talker", timeout=30)
                    assert not new.running()
        assert "Warning" not in capsys.readouterr().out
    finally:
        session.stop()


def test_a_node_is_not_taken_for_an_earlier_one_when_its_wait_comes_late(talker_dir, domain_id, capsys):
    """The nodes that ran before are the ones the session saw when start() began: a talker that the
    session already sees when wait_for_node is called (a later cell) is not a second talker."""
    from course_lib.ros import graph, session

    session.start(domain_id=domain_id)
    try:
        with python_node("course_talker:main", cwd=talker_dir, domain_id=domain_id, name="camera") as talker:
            assert "/talker" in graph.node_list(wait_for=["/talker"], timeout=30)
            talker.wait_for_node("talker", timeout=30)
        assert "Warning" not in capsys.readouterr().out
    finally:
        session.stop()


WAITS_FOR_GO = """
import pathlib, sys, time
go = pathlib.Path(sys.argv[1])
while not go.exists():
    time.sleep(0.05)
import course_talker
course_talker.main()
"""


def test_a_killed_nodes_name_is_not_taken_for_the_next_node_of_that_name(talker_dir, domain_id):
    """A node killed a moment ago stays in the graph until its lease ends: the next process's
    wait_for_node waits for that process's own node, not the dead one's name."""
    with python_node("course_talker:main", cwd=talker_dir, domain_id=domain_id) as first:
        first.wait_for_node("talker", timeout=30)
        os.killpg(first.pid, signal.SIGKILL)
        first.stop()
    (talker_dir / "waits.py").write_text(WAITS_FOR_GO)
    go = talker_dir / "go"
    with NodeProcess([sys.executable, "waits.py", str(go)], cwd=talker_dir, domain_id=domain_id) as second:
        with pytest.raises(TimeoutError, match="'talker' did not appear"):
            second.wait_for_node("talker", timeout=2.0)  # its node does not exist yet
        go.touch()
        second.wait_for_node("talker", timeout=30)


LEFT_RUNNING = """
import sys, time
from course_lib.ros.processes import NodeProcess
NodeProcess([sys.executable, "-c", "import time; time.sleep(60)", sys.argv[1]], name="camera").start()
print("started", flush=True)
time.sleep(60)
"""


def test_start_names_the_notebook_that_still_runs_a_process_of_that_name(token, domain_id, capsys):
    """Lesson 02's kernel, left running, still runs its "camera": lesson 03's camera says so at once,
    naming the notebook; in another domain, or once that kernel is gone, nothing is said."""
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain_id), JPY_SESSION_NAME="/home/me/notebooks/02_images.ipynb")
    other_kernel = subprocess.Popen([sys.executable, "-c", LEFT_RUNNING, token], env=env, stdout=subprocess.PIPE,
                                    text=True)
    try:
        assert other_kernel.stdout.readline() == "started\n"
        with NodeProcess(sleeper(token), name="camera", domain_id=domain_id) as camera:
            said = capsys.readouterr().out
            assert "another node process named 'camera'" in said and "notebook 02_images.ipynb" in said, said
            assert camera.warned_duplicate
        with NodeProcess(sleeper(token), name="camera", domain_id=domain_id + 1 if domain_id < 101 else 1):
            assert "Warning" not in capsys.readouterr().out
    finally:
        other_kernel.kill()
        other_kernel.wait()
    assert wait_until(lambda: not processes_with(token), timeout=10)  # its camera died with it
    with NodeProcess(sleeper(token), name="camera", domain_id=domain_id):
        assert "Warning" not in capsys.readouterr().out


def test_module_target_runs_with_arguments(tmp_path):
    """'package.module' runs as python -m with the given arguments."""
    (tmp_path / "echo_args.py").write_text("import sys\nprint('args', sys.argv[1:])\n")
    process = python_node("echo_args", "a", "b c", cwd=tmp_path)
    assert process.wait(timeout=30) == 0
    assert "args ['a', 'b c']" in process.log
    assert process.name == "echo_args"


def test_entry_point_target_returns_its_exit_code(tmp_path):
    """'module:function' calls the function like a console script; its return value is the exit code."""
    (tmp_path / "entry.py").write_text("import sys\ndef main():\n    print('argv0', sys.argv[0])\n    return 4\n")
    process = python_node("entry:main", cwd=tmp_path)
    assert process.wait(timeout=30) == 4
    assert "argv0 entry:main" in process.log


@pytest.mark.parametrize("target", ["", "a-b.c", "pkg:", "pkg:main()", "pkg mod"])
def test_bad_targets_are_refused_with_the_forms(target):
    with pytest.raises(ValueError, match="package.module:function"):
        python_node(target)


def test_missing_program_raises_file_not_found():
    with pytest.raises(FileNotFoundError, match="no such file or program"):
        NodeProcess(["course-lib-no-such-program"]).start()


def test_wait_for_node_names_the_exit_code_of_a_crashing_child(domain_id):
    code = "import sys; print('about to fail', flush=True); sys.exit(3)"
    process = NodeProcess([sys.executable, "-c", code], domain_id=domain_id).start()
    with pytest.raises(RuntimeError, match=r"exit code 3(.|\n)*about to fail"):
        process.wait_for_node("talker", timeout=30)


def test_wait_for_node_times_out_with_the_log_tail(domain_id, token):
    with NodeProcess(sleeper(token), domain_id=domain_id) as process:
        assert wait_until(lambda: "ready" in process.log)
        with pytest.raises(TimeoutError, match=r"did not appear(.|\n)*ready"):
            process.wait_for_node("talker", timeout=0.5)
        assert process.running()
    assert processes_with(token) == []


def test_log_survives_stop_and_its_files_are_removed():
    process = NodeProcess(["sh", "-c", "echo kept; exec sleep 100"]).start()
    log_dir = process._log_dir
    assert wait_until(lambda: "kept" in process.log)
    process.stop(timeout=2)
    assert process.log == "kept\n"
    assert not log_dir.exists()
    assert process.stop() == process.returncode  # idempotent


def test_context_manager_stops_the_child_on_an_exception(token):
    with pytest.raises(ZeroDivisionError, match="inside the block"):
        with NodeProcess(sleeper(token)).start():
            assert wait_until(lambda: processes_with(token))
            raise ZeroDivisionError("inside the block")
    assert processes_with(token) == []


def test_stop_all_stops_every_running_child():
    tokens = [marker(), marker()]
    started = [NodeProcess(sleeper(token)).start() for token in tokens]
    processes.stop_all(timeout=2)
    assert all(not p.running() for p in started)
    assert all(processes_with(token) == [] for token in tokens)


def test_a_forked_child_neither_stops_nor_pins_the_parents_nodes(token):
    """A process forked by the caller (multiprocessing's fork) leaves the caller's nodes alone."""
    process = NodeProcess(sleeper(token)).start()
    try:
        pid = os.fork()
        if pid == 0:  # the forked child does what its atexit would do, then checks it owns nothing
            processes.stop_all(timeout=1)
            os._exit(0 if process.stop() is None and not process.running() else 1)
        _, status = os.waitpid(pid, 0)
        assert os.waitstatus_to_exitcode(status) == 0
        assert process.running()
    finally:
        process.stop()
    assert processes_with(token) == []


def test_starting_a_named_process_again_replaces_the_old_one():
    """Re-running a notebook cell that starts 'sleeper' does not leave two running."""
    first = NodeProcess(sleeper(marker()), name="sleeper").start()
    second = NodeProcess(sleeper(marker()), name="sleeper").start()
    try:
        assert not first.running() and first.exit_reason == "stopped"
        assert second.running()
    finally:
        second.stop()


@pytest.mark.parametrize("field", ["wall_seconds", "memory_mb", "max_processes", "stop_at_tasks"])
def test_limits_refuse_non_positive_values(field):
    with pytest.raises(ValueError, match=f"Limits.{field}.*positive"):
        Limits(**{field: 0})


def test_wait_for_output_sees_a_line_and_reports_an_early_exit():
    with processes.NodeProcess([sys.executable, "-c", "import time; print('ready', flush=True); time.sleep(30)"],
                               name="printer").start() as proc:
        assert "ready" in proc.wait_for_output("ready", timeout=10)
        with pytest.raises(TimeoutError, match="did not print 'never'"):
            proc.wait_for_output("never", timeout=0.3)
    with processes.NodeProcess([sys.executable, "-c", "raise SystemExit(4)"], name="quitter").start() as proc:
        with pytest.raises(RuntimeError, match=r"quitter ended \(exit code 4\) before printing"):
            proc.wait_for_output("ready", timeout=10)
