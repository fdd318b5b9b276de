"""Tests for course_lib.checks.student_processes: how a check (self-check or graded) starts the
student's code: bounded in time, memory and file size, without the grader's variables."""

import sys

from course_lib import contract
from course_lib.checks.student_processes import STUDENT_FILE_MB, StudentProcesses

REPORT = ("import os, resource; print(resource.getrlimit(resource.RLIMIT_AS)[0] // 2**20, "
          "resource.getrlimit(resource.RLIMIT_FSIZE)[0] // 2**20, os.environ.get('AUTOGRADER_CHECK_SEED'), "
          "os.environ.get('AUTOGRADER_SEED'), os.getuid() == os.geteuid())")


def test_a_students_process_gets_the_memory_and_file_limits_and_no_seed(tmp_path, monkeypatch):
    monkeypatch.setenv("AUTOGRADER_CHECK_SEED", "1234")
    monkeypatch.setenv("AUTOGRADER_SEED", "99")
    process = StudentProcesses().start([sys.executable, "-S", "-c", REPORT], name="student-limits", cwd=tmp_path,
                                       domain_id=0, wall_seconds=30)
    assert process.wait(timeout=30) == 0, process.log
    assert process.log.split() == [str(contract.STUDENT_MEMORY_MB), str(STUDENT_FILE_MB), "None", "None", "True"]


def test_a_students_process_is_stopped_at_its_wall_time(tmp_path):
    process = StudentProcesses().start([sys.executable, "-S", "-c", "import time; time.sleep(60)"],
                                       name="student-sleeps", cwd=tmp_path, domain_id=0, wall_seconds=0.5)
    process.wait(timeout=30)
    assert process.exit_reason == "wall_seconds"
