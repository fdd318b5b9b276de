"""How a check starts the student's processes: their resource limits and their environment.

:class:`StudentProcesses` runs them as the check's own user, bounded in time, memory and file
size: what a self-check does in the student's notebook. The course's grader, as root, hands the
check a subclass (autograder.sandbox.student_uid.StudentUid) that also runs them as the worker's uid, so
that the student's code can neither read nor signal nor trace the check, nor write its results.
course_lib never imports the grader: it only calls the methods below.
"""

from __future__ import annotations

from pathlib import Path

from course_lib import contract
from course_lib.checks.runner import child_pythonpath
from course_lib.imaging import frame_memory

#: Largest file a student's process may write, MB.
STUDENT_FILE_MB = 128


def student_env() -> dict:
    """The variables of a student process: course_lib importable, none of the grader's seeds or answers."""
    # Fast DDS's set-up for camera frames comes, as for every course process, from
    # course_lib.ros.rosenv.ros_environment (its shared-memory segments need RLIMIT_FSIZE above 32 MB).
    return {"PYTHONPATH": child_pythonpath(), contract.SEED_ENV: None, contract.CHECK_SEED_ENV: None,
            contract.ANSWERS_ENV: None, contract.ANSWER_KEYS_ENV: None, contract.RECORD_ANSWERS_ENV: None,
            "PYTHONDONTWRITEBYTECODE": "1", **MALLOC_ENV}


#: glibc's allocator, fixed: blocks below 32 MB come from the heap, which keeps 128 MB before it
#: gives memory back. Left to itself it decides per process, from its history, whether a camera
#: frame's buffers (6 MB each at 1080p, several per frame) are mapped afresh or reused, and a frame
#: then costs 10 or 25 ms of processor time in the same node: the brightness check's throughput
#: item compares processor time per frame (course_lib.checks.brightness), and with this setting a
#: good node costs what the grader's yardstick does, 0.9-1.1 times, idle or loaded.
MALLOC_ENV = frame_memory.ENVIRONMENT


class StudentProcesses:
    """Starts a check's student processes as the check's own user (see the module docstring)."""

    def start(self, command: list[str], *, name: str, cwd, domain_id: int, wall_seconds: float,
              env: dict | None = None):
        """Start `command` (the student's code) and return its running course_lib.ros.processes.NodeProcess;
        `env`: variables on top of student_env() (a sourced workspace, course_lib.checks.packages)."""
        from course_lib.ros import processes

        command, env, private_dirs = self.confine(list(command), {**student_env(), **(env or {})})
        return processes.NodeProcess(command, name=name, cwd=cwd, domain_id=domain_id, env=env,
                                     limits=self.limits(wall_seconds), private_dirs=private_dirs).start()

    def limits(self, wall_seconds: float):
        """Bounds of a student process: time, memory, file size."""
        from course_lib.ros import processes

        return processes.Limits(wall_seconds=wall_seconds, memory_mb=contract.STUDENT_MEMORY_MB,
                                file_size_mb=STUDENT_FILE_MB, grace_seconds=1.0)

    def confine(self, command: list[str], env: dict) -> tuple[list[str], dict, list[Path]]:
        """(command, environment, folders to remove after it) of a student process; here unchanged."""
        return command, env, []

    def give(self, path: Path) -> None:
        """Let the student's processes write the results of their calls into `path` (theirs already)."""

    def probe_started(self) -> None:
        """Called when the check's ROS probe has started (nothing to share: one user)."""
