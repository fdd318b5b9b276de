"""Tests for course_lib.process_tree, the one way the course ends a process tree."""

import signal
import subprocess
import sys

from process_support import processes_with, wait_until

from course_lib import process_tree


def _group(token: str, code: str) -> subprocess.Popen:
    """A python group leader (its own session) running `code`, with a sleeping child in its group."""
    child = f"import subprocess, sys; subprocess.Popen([sys.executable, '-S', '-c', 'import time; time.sleep(60)', {token!r}]); "
    return subprocess.Popen([sys.executable, "-S", "-c", child + code, token], start_new_session=True,
                            stdout=subprocess.PIPE, text=True)


def test_signal_tree_reaches_the_whole_group(token):
    leader = _group(token, "print('ready', flush=True); import time; time.sleep(60)")
    assert leader.stdout.readline() == "ready\n"
    assert wait_until(lambda: len(processes_with(token)) == 2)
    process_tree.signal_tree(leader.pid, signal.SIGKILL)
    assert leader.wait(timeout=10) == -signal.SIGKILL
    assert wait_until(lambda: not processes_with(token))


def test_stop_group_escalates_past_a_leader_that_ignores_sigint(token):
    code = "import signal, time; signal.signal(signal.SIGINT, signal.SIG_IGN); print('ready', flush=True); time.sleep(60)"
    leader = _group(token, code)
    assert leader.stdout.readline() == "ready\n"
    steps = ((signal.SIGINT, 0.3), (signal.SIGTERM, 5.0), (signal.SIGKILL, 5.0))
    assert process_tree.stop_group(leader, steps) == -signal.SIGTERM
    assert wait_until(lambda: not processes_with(token))  # its child got SIGINT with the group


def test_signalling_a_group_that_has_gone_does_nothing():
    done = subprocess.Popen(["true"], start_new_session=True)
    done.wait()
    process_tree.signal_group(done.pid, signal.SIGKILL)
    process_tree.signal_tree(done.pid, signal.SIGKILL)
    assert process_tree.stop_group(done) == 0
