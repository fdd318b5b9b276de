"""Tests for course_lib.supervision.supervisor, through the NodeProcess that starts it: no orphans ever, even
when the caller dies; output relayed without blocking the child; the limits it sets bite."""

import signal
import subprocess
import sys
import threading

import pytest
from support.process import processes_with, sleeper, sleeper_script, sleepers, wait_until

from course_lib.ros.processes import Limits, NodeProcess


def test_child_that_ignores_sigint_is_killed_after_the_timeout(token):
    code = ("import signal, time; signal.signal(signal.SIGINT, signal.SIG_IGN); print('ready', flush=True); "
            "time.sleep(100)")
    process = NodeProcess([sys.executable, "-c", code, token]).start()
    assert wait_until(lambda: "ready" in process.log), process.log
    assert process.stop(timeout=0.5) == -signal.SIGKILL
    assert "SIGKILL" in process.describe_exit()
    assert processes_with(token) == []


def test_send_signal_passes_one_signal_on_and_the_exit_counts_as_stopped(token):
    """A caller that paces its own stop (ros2 launch) signals through the supervisor: SIGINT is
    ignored here, SIGTERM ends the child, and the supervisor kills nothing on its own."""
    code = ("import signal, time; signal.signal(signal.SIGINT, signal.SIG_IGN); print('ready', flush=True); "
            "time.sleep(100)")
    process = NodeProcess([sys.executable, "-c", code, token]).start()
    assert wait_until(lambda: "ready" in process.log), process.log
    process.send_signal(signal.SIGINT)
    process.send_signal(signal.SIGTERM)
    assert process.wait(timeout=30) == -signal.SIGTERM
    assert process.exit_reason == "stopped"
    process.send_signal(signal.SIGKILL)  # after the end: nothing, no error
    assert processes_with(token) == []


def test_grandchildren_are_killed_by_stop_even_if_they_left_the_group(token):
    """sh's background children, one in its process group and one in a new session, die with it."""
    run = sleeper_script(token)
    process = NodeProcess(["sh", "-c", f"{run} & setsid {run} & echo started; exec {run}"]).start()
    assert wait_until(lambda: len(sleepers(token)) == 3), process.log
    process.stop(timeout=2)
    assert processes_with(token) == []


def test_leftovers_die_when_the_child_exits_on_its_own(token):
    """A child that exits normally does not leave its background processes running."""
    process = NodeProcess(["sh", "-c", f"{sleeper_script(token)} & echo started"]).start()
    assert process.wait(timeout=30) == 0
    assert "started" in process.log
    assert processes_with(token) == []


def test_on_output_gets_stdout_and_stderr_apart_as_they_arrive():
    """on_output sees each stream's own bytes; the log still has both."""
    pieces = []
    code = "import sys\nprint('to out', flush=True)\nprint('to err', file=sys.stderr, flush=True)\n"
    process = NodeProcess([sys.executable, "-c", code],
                          on_output=lambda stream, data: pieces.append((stream, data))).start()
    assert process.wait(timeout=10) == 0
    assert wait_until(lambda: len(pieces) >= 2)
    assert b"".join(data for stream, data in pieces if stream == "stdout") == b"to out\n"
    assert b"".join(data for stream, data in pieces if stream == "stderr") == b"to err\n"
    assert "to out" in process.log and "to err" in process.log


def test_a_slow_on_output_never_blocks_the_child(tmp_path):
    """A callback that stalls loses echoed output (and is told how much), not the child's time."""
    pieces = []
    released = threading.Event()

    def stalled(stream, data):
        if not pieces:
            released.wait(120)  # until the child has written everything
        pieces.append(data)

    # 4 MB through a 64 KB pipe: a child that waited for the callback would never get to the end.
    written, go = tmp_path / "written", tmp_path / "go"
    code = (f"import os, sys, time\nfor _ in range(4096):\n    sys.stdout.write('x' * 1023 + '\\n')\n"
            f"sys.stdout.flush()\nopen({str(written)!r}, 'w').close()\n"
            f"while not os.path.exists({str(go)!r}):\n    time.sleep(0.01)\n")
    process = NodeProcess([sys.executable, "-c", code], on_output=stalled).start()
    try:
        assert wait_until(written.exists, timeout=120), process.log_tail()
    finally:
        released.set()  # before the child ends, so that the supervisor can say what it dropped
        go.touch()
    assert process.wait(timeout=60) == 0
    assert wait_until(lambda: b"bytes of output not shown" in b"".join(pieces), timeout=30)


CALLER = """
import os, signal, sys, time
import rclpy
from course_lib.ros.processes import NodeProcess
# Like a notebook kernel, the caller runs DDS threads. Without rclpy's signal handlers, so that
# SIGTERM ends it (rclpy's handler would only shut the context down and keep the caller alive).
rclpy.init(signal_handler_options=rclpy.signals.SignalHandlerOptions.NO)
node = rclpy.create_node("caller")
process = NodeProcess([sys.executable, "-c", "import time; time.sleep(100)", sys.argv[2]]).start()
print("started", flush=True)
if sys.argv[1] == "exit":
    sys.exit(0)  # no stop(): atexit must do it
if sys.argv[1] == "exception":
    with process:
        raise KeyboardInterrupt
time.sleep(100)
"""


@pytest.mark.parametrize("ending", ["exit", "exception", "SIGTERM", "SIGKILL"])
def test_children_never_outlive_their_caller(ending, token):
    """However a caller running rclpy ends (exit, KeyboardInterrupt, SIGTERM, SIGKILL), its child dies."""
    caller = subprocess.Popen([sys.executable, "-c", CALLER, ending, token], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)
    try:
        assert caller.stdout.readline() == "started\n", caller.stderr.read()
        if ending.startswith("SIG"):
            assert processes_with(token)
            caller.send_signal(getattr(signal, ending))
        caller.wait(timeout=30)
        assert wait_until(lambda: not processes_with(token), timeout=10), processes_with(token)
    finally:
        caller.kill()
        caller.wait()


def test_wall_limit_stops_a_sleeper(token):
    process = NodeProcess(sleeper(token), limits=Limits(wall_seconds=0.5, grace_seconds=1)).start()
    code = process.wait(timeout=30)
    assert process.exit_reason == "wall_seconds"
    assert code != 0 and "wall-time limit of 0.5 s" in process.describe_exit()
    assert processes_with(token) == []


def test_memory_limit_stops_a_child_that_allocates_too_much():
    code = "block = bytearray(400 * 1024 * 1024); print('allocated', flush=True)"
    process = NodeProcess([sys.executable, "-c", code], limits=Limits(memory_mb=200)).start()
    assert process.wait(timeout=30) != 0
    assert "MemoryError" in process.log and "allocated" not in process.log


def test_file_size_limit_ends_a_child_that_writes_too_much_with_sigxfsz(tmp_path):
    # Not python: it ignores SIGXFSZ (the write fails with EFBIG instead).
    command = ["sh", "-c", f"exec head -c 3145728 /dev/zero > {tmp_path / 'big'}"]
    process = NodeProcess(command, limits=Limits(file_size_mb=1)).start()
    assert process.wait(timeout=30) == -signal.SIGXFSZ
    assert "file size limit of 1 MB" in process.describe_exit()


def test_cpu_limit_ends_a_busy_loop_with_sigxcpu():
    process = NodeProcess([sys.executable, "-c", "while True: pass"], limits=Limits(cpu_seconds=1)).start()
    assert process.wait(timeout=60) == -signal.SIGXCPU
    assert "CPU time limit" in process.describe_exit()
