"""How a check starts the student's processes: their resource limits, their environment, and
(graded, as root) the uid they run as."""

from __future__ import annotations

import os
from pathlib import Path

from course_lib.checks import answers
from course_lib.checks.runner import SEED_ENV, _pythonpath

#: Memory (address space, MB) of a student's process. rclpy with Fast DDS maps a few hundred MB.
STUDENT_MEMORY_MB = 2048

#: Largest file a student's process may write, MB.
STUDENT_FILE_MB = 128


def _student_env() -> dict:
    # Fast DDS's set-up for camera frames comes, as for every course process, from
    # course_lib.rosenv.ros_environment (its shared-memory segments need RLIMIT_FSIZE above 32 MB).
    return {"PYTHONPATH": _pythonpath(), "AUTOGRADER_SEED": None, SEED_ENV: None, STUDENT_UID_ENV: None,
            answers.MODE_ENV: None, answers.RECORD_ENV: None, "PYTHONDONTWRITEBYTECODE": "1"}


#: Set by the grader (as root) for the checks it runs: the uid (and its RLIMIT_NPROC) that the
#: student's processes run as, while the check itself stays root. The student's code can then
#: neither read nor signal nor trace the check, nor write its results.
STUDENT_UID_ENV = "AUTOGRADER_STUDENT_UID"
STUDENT_NPROC_ENV = "AUTOGRADER_STUDENT_NPROC"


def _student_uid() -> int | None:
    uid = os.environ.get(STUDENT_UID_ENV)
    return int(uid) if uid and os.geteuid() == 0 else None


def _student_limits(wall_seconds: float):
    """Bounds of a student process: time, memory, file size, and the grader's uid when given."""
    from course_lib import processes

    uid = _student_uid()
    nproc = int(os.environ.get(STUDENT_NPROC_ENV, "384")) if uid is not None else None
    return processes.Limits(wall_seconds=wall_seconds, memory_mb=STUDENT_MEMORY_MB, file_size_mb=STUDENT_FILE_MB,
                            user=uid, max_processes=nproc, grace_seconds=1.0)


def _give_to_student(path: Path) -> None:
    """Let the student's uid (if any) write the results of its calls into `path`."""
    uid = _student_uid()
    if uid is not None:
        os.chown(path, uid, uid)
