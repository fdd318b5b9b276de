"""Tests for course_lib.supervision.process_tree, the one way the course ends a process tree."""

import os
import signal
import subprocess
import sys

import pytest
from support.process import processes_with, wait_until

from course_lib.supervision import process_tree


def _group(token: str, code: str) -> subprocess.Popen:
    """A python group leader (its own session) running `code`, with a sleeping child in its group."""
    child = ("import subprocess, sys; "
             f"subprocess.Popen([sys.executable, '-S', '-c', 'import time; time.sleep(60)', {token!r}]); ")
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
    code = ("import signal, time; signal.signal(signal.SIGINT, signal.SIG_IGN); print('ready', flush=True); "
            "time.sleep(60)")
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


def test_cpu_seconds_counts_the_whole_tree_and_what_it_reaped():
    """A parent that burns 0.3 s of processor time, a child of a second thread that burns 0.4 s and
    stays, and a reaped child that burned 0.2 s: all of it counts; a process that sleeps adds
    nothing; a grandchild whose parent exited (re-parented to init: course_lib.supervision.supervisor is a
    subreaper so that a node's such leftovers stay in its tree) is no longer part of it."""
    code = """
import os, sys, threading, time
def burn(seconds):
    start = time.process_time()
    while time.process_time() - start < seconds:
        pass
def stay(seconds, setsid=False):
    if os.fork() == 0:
        if setsid:
            os.setsid()
            if os.fork() == 0:
                burn(seconds); print('burnt', flush=True); time.sleep(60)
            os._exit(0)
        burn(seconds); print('burnt', flush=True); time.sleep(60)
thread = threading.Thread(target=stay, args=(0.4,)); thread.start(); thread.join()
stay(0.2, setsid=True)
if os.fork() == 0:
    burn(0.2); os._exit(0)
os.wait()
burn(0.3)
print('burnt', flush=True)
time.sleep(60)
"""
    parent = subprocess.Popen([sys.executable, "-S", "-c", code], stdout=subprocess.PIPE, text=True,
                              start_new_session=True)
    try:
        assert [parent.stdout.readline() for _ in range(3)] == ["burnt\n"] * 3
        used = process_tree.cpu_seconds(parent.pid)
        # Each process's time is counted in clock ticks (10 ms), rounded down.
        assert 0.85 <= used < 1.1, used
        assert process_tree.cpu_seconds(parent.pid) - used < 0.05  # asleep now: nothing more
        assert process_tree.cpu_seconds(parent.pid, include_self=False) <= used - 0.25  # not its own 0.3 s
    finally:
        process_tree.signal_tree(parent.pid, signal.SIGKILL)
        parent.wait(timeout=10)


def test_a_zombie_does_not_run():
    """A process that has ended runs no more, though /proc keeps it until its parent reaps it."""
    assert process_tree.running(os.getpid())
    proc = subprocess.Popen([sys.executable, "-S", "-c", "pass"])
    os.waitid(os.P_PID, proc.pid, os.WEXITED | os.WNOWAIT)  # ended, not reaped
    assert os.path.exists(f"/proc/{proc.pid}") and not process_tree.running(proc.pid)
    proc.wait(timeout=10)
    assert not process_tree.running(proc.pid)


#: A uid no process of this machine runs as: the grader's are 61000-62232, and
#: test_pipeline_budget.py, which may run beside this file, uses 64990 and 64991.
SPARE_UID = 64999


@pytest.mark.skipif(os.geteuid() != 0, reason="starting processes as another uid needs root")
def test_kill_uid_ends_every_process_of_the_uid_also_what_they_fork():
    """Processes of the uid, with children of theirs that left their session, are found and
    killed; processes of other uids are left alone."""
    started = [subprocess.Popen(["/bin/sh", "-c", "setsid sleep 60 & sleep 60"], user=SPARE_UID) for _ in range(2)]
    try:
        assert wait_until(lambda: len(process_tree.processes_of_uid(SPARE_UID)) == 6, timeout=10)  # sh, 2 sleeps
        assert process_tree.running(os.getpid())
        assert process_tree.kill_uid(SPARE_UID) == 6
        assert process_tree.processes_of_uid(SPARE_UID) == []  # zombies not reaped yet are not counted
        assert process_tree.kill_uid(SPARE_UID) == 0
    finally:
        for proc in started:
            proc.kill()
            proc.wait(timeout=10)


def test_cpu_seconds_of_a_process_that_has_gone_is_zero():
    proc = subprocess.Popen([sys.executable, "-S", "-c", "pass"])
    proc.wait(timeout=10)
    assert process_tree.cpu_seconds(proc.pid) == 0.0


def test_tree_and_uid_tasks_count_processes_and_threads(token):
    """tree_tasks: the descendants' processes and threads (what a fork bomb adds); uid_tasks: every
    process and thread of a user, what RLIMIT_NPROC counts."""
    code = "import threading, time; [threading.Thread(target=time.sleep, args=(60,)).start() for _ in range(2)]"
    leader = _group(token, code + "; print('ready', flush=True); time.sleep(60)")
    try:
        assert leader.stdout.readline() == "ready\n"
        assert wait_until(lambda: len(processes_with(token)) == 2)
        assert process_tree.tree_tasks(leader.pid) == 1  # its sleeping child
        assert process_tree.tree_tasks(os.getpid()) >= 4  # the leader's three threads and its child
        assert process_tree.uid_tasks(os.geteuid()) >= 4 + len(os.listdir("/proc/self/task"))
    finally:
        process_tree.signal_tree(leader.pid, signal.SIGKILL)
        leader.wait(timeout=10)
