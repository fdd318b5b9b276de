"""Tests for autograder.sandbox.student_uid: graded as root, the checks' student processes run as the
worker's uid, with a HOME of their own, and can reach the check's ROS shared memory."""

import os
import time

import pytest

from autograder.sandbox import student_uid
from autograder.sandbox.student_uid import StudentUid
from course_lib import contract
from course_lib.checks.student_processes import StudentProcesses
from course_lib.supervision import process_tree

needs_root = pytest.mark.skipif(os.geteuid() != 0, reason="running as the student's uid needs root")

UID = 61997

#: What the student's process reports: uid, gid, HOME = ROS_HOME, HOME's owner, RLIMIT_NPROC,
#: RLIMIT_AS in MB, the grader's variable (shell and /proc only: no interpreter needed).
REPORT = ("id -u; id -g; test \"$HOME\" = \"$ROS_HOME\" && echo True; stat -c %u \"$HOME\"; "
          "grep 'Max processes' /proc/self/limits | awk '{print $3}'; "
          "grep 'Max address space' /proc/self/limits | awk '{print $4 / 1048576}'; "
          "echo \"${AUTOGRADER_STUDENT_UID:-None}\"")


@needs_root
def test_the_students_process_runs_as_the_uid_with_a_home_it_owns(tmp_path, monkeypatch):
    monkeypatch.setenv(contract.STUDENT_UID_ENV, str(UID))
    process = StudentUid(UID, max_processes=64).start(["sh", "-c", REPORT], name="student-test", cwd="/",
                                                      domain_id=0, wall_seconds=30)
    process.wait(timeout=30)
    assert process.log.split() == [str(UID), str(UID), "True", str(UID), "64", str(contract.STUDENT_MEMORY_MB),
                                   "None"], process.log


#: Forks children that sleep, and tries again each fork that fails (the system's Python: the uid
#: cannot enter a virtual environment under root's folders).
SYSTEM_PYTHON = "/usr/bin/python3"
BOMB = """
import os, time
while True:
    try:
        if os.fork() == 0:
            time.sleep(1000)
    except BlockingIOError:
        time.sleep(0.01)
"""


@needs_root
@pytest.mark.skipif(not os.access(SYSTEM_PYTHON, os.X_OK), reason=f"no {SYSTEM_PYTHON}")
def test_a_fork_bomb_is_killed_once_the_uid_reaches_its_process_limit():
    """A tree that fills its uid's process limit is killed at once, its exit says why; without the
    supervisor's stop it would fork for its whole wall time (60 s)."""
    process = StudentUid(UID, max_processes=24).start([SYSTEM_PYTHON, "-I", "-S", "-c", BOMB], cwd="/",
                                                      name="student-test-bomb", domain_id=0, wall_seconds=60)
    started = time.monotonic()
    process.wait(timeout=60)
    assert time.monotonic() - started < 20
    assert process.exit_reason == "max_processes"
    assert "most processes and threads it may have (24" in process.describe_exit()
    assert process_tree.uid_tasks(UID) == 0


@needs_root
def test_a_tree_below_its_uids_process_limit_runs_to_its_end():
    """Processes and threads well within the limit are left alone (the watch counts, and stops nothing)."""
    process = StudentUid(UID, max_processes=24).start(["sh", "-c", "sleep 0.3 & sleep 0.3 & sleep 1; wait"],
                                                      name="student-test-few", cwd="/", domain_id=0, wall_seconds=60)
    process.wait(timeout=60)
    assert (process.returncode, process.exit_reason) == (0, "exited")


@needs_root
def test_confine_wraps_the_command_and_makes_a_home_that_is_removed_with_the_process(tmp_path):
    command, env, private = StudentUid(UID).confine(["id", "-u"], {"PATH": os.environ["PATH"]})
    assert command[-3:] == ["--", "id", "-u"] and str(UID) in command
    assert env["HOME"] == env["ROS_HOME"] == str(private[0]) and env["ROS_LOG_DIR"] is None
    assert os.stat(private[0]).st_uid == UID
    os.rmdir(private[0])


@needs_root
def test_give_hands_a_job_folder_to_the_uid(tmp_path):
    StudentUid(UID).give(tmp_path)
    assert os.stat(tmp_path).st_uid == UID


def test_without_the_graders_uid_the_student_runs_as_the_check(monkeypatch):
    monkeypatch.delenv(contract.STUDENT_UID_ENV, raising=False)
    assert type(StudentUid.from_environment()) is StudentProcesses


@needs_root
def test_the_graders_uid_and_process_limit_come_from_the_environment(monkeypatch):
    monkeypatch.setenv(contract.STUDENT_UID_ENV, str(UID))
    monkeypatch.setenv(contract.STUDENT_NPROC_ENV, "99")
    students = StudentUid.from_environment()
    assert isinstance(students, StudentUid) and (students.uid, students.max_processes) == (UID, 99)


def test_the_checks_shared_memory_files_are_opened_to_the_students_uid():
    """Fast DDS makes its files 0644; the probe's own ones become 0666, so the student's node can
    deliver into them."""
    path = f"/dev/shm/course_lib_test_fastrtps_{os.getpid()}"
    with open(path, "w"):
        pass
    try:
        os.chmod(path, 0o644)
        student_uid.share_shared_memory()
        assert os.stat(path).st_mode & 0o777 == 0o666
    finally:
        os.remove(path)
