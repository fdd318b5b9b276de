"""The grader's student uid: the checks' student processes run as the worker's uid, not as root.

The grader runs a submission's hidden checks as root (autograder.grading.hidden_checks_process) and sets
contract.STUDENT_UID_ENV (and STUDENT_NPROC_ENV) for them. :class:`StudentUid` is then what the checks
(course_lib.checks.context.Context) start the student's code with: the same limits as a
self-check, plus the uid (autograder.sandbox.run_as) and a fresh HOME it owns. The student's code can
then neither read nor signal nor trace the check, nor write its results.
"""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

from autograder.sandbox import run_as
from course_lib import contract
from course_lib.checks.student_processes import StudentProcesses


class StudentUid(StudentProcesses):
    """Starts the student's processes as `uid`, with at most `max_processes` processes and threads."""

    def __init__(self, uid: int, max_processes: int | None = contract.MAX_PROCESSES):
        self.uid = uid
        self.max_processes = max_processes

    @classmethod
    def from_environment(cls) -> StudentProcesses:
        """StudentUid when the grader asked for one (contract.STUDENT_UID_ENV) and this process is root, else
        the self-check's StudentProcesses (same user)."""
        uid = os.environ.get(contract.STUDENT_UID_ENV)
        if not uid or os.geteuid() != 0:
            return StudentProcesses()
        return cls(int(uid), int(os.environ.get(contract.STUDENT_NPROC_ENV, str(contract.MAX_PROCESSES))))

    def limits(self, wall_seconds: float):
        """A self-check's bounds; and the tree is killed at once when the uid reaches max_processes
        (which run_as sets after its switch) and the tree holds at least a quarter of them."""
        return dataclasses.replace(super().limits(wall_seconds), stop_at_tasks=self.max_processes)

    def confine(self, command: list[str], env: dict) -> tuple[list[str], dict, list[Path]]:
        home = run_as.home_for(self.uid)
        env = {**env, "HOME": home, "ROS_HOME": home, "ROS_LOG_DIR": None,
               contract.STUDENT_UID_ENV: None, contract.STUDENT_NPROC_ENV: None}
        return run_as.command(self.uid, command, self.max_processes), env, [Path(home)]

    def give(self, path: Path) -> None:
        os.chown(path, self.uid, self.uid)

    def probe_started(self) -> None:
        share_shared_memory()


def share_shared_memory() -> None:
    """Let the student's uid use this (root) process's Fast DDS shared-memory files.

    Fast DDS creates its segments, ports and port mutexes 0644, so a node of another uid can
    neither deliver into a root participant's port nor release buffers in its segment: root and
    student nodes would not even discover each other. The grader's /dev/shm is a private tmpfs of
    the submission's sandbox, so opening this process's files to "others" opens them to that
    student's processes only.
    """
    me = os.geteuid()
    for path in Path("/dev/shm").glob("*fastrtps_*"):
        try:
            if path.stat().st_uid == me:
                os.chmod(path, 0o666)
        except OSError:  # another participant's file went away meanwhile
            pass
