"""The resource bounds of a child process (course_lib.ros.processes.NodeProcess, the checks' student
processes): wall time, memory, processor time, processes, file size, open files."""

from __future__ import annotations

import dataclasses


@dataclasses.dataclass(frozen=True)
class Limits:
    """Bounds for a child that runs untrusted code (the checks); None means no bound.

    Attributes:
        wall_seconds: real time after which the child is stopped (SIGINT, then SIGKILL after
            grace_seconds); its exit_reason becomes "wall_seconds".
        memory_mb: address space (RLIMIT_AS). Allocations beyond it fail (MemoryError in Python).
            rclpy with Fast DDS maps a few hundred MB of address space, so stay above ~1024 for
            ROS nodes.
        cpu_seconds: CPU time (RLIMIT_CPU); the child gets SIGXCPU when it is used up.
        max_processes: processes *and threads* of the child's user (RLIMIT_NPROC). Fast DDS
            starts about a dozen threads per node. The kernel does not enforce it for root (the
            grader, as root, runs the student's code as another uid: autograder.sandbox.run_as).
        stop_at_tasks: the processes and threads of the child's user at which its supervisor kills
            the child's tree at once, when the tree holds at least a quarter of them (exit_reason
            "max_processes"): the user's RLIMIT_NPROC where another step sets it (the grader's
            autograder.sandbox.run_as, after its switch of user). At that limit nothing of the user
            can fork or start a thread any more, and a fork bomb's copies would run on.
        file_size_mb: largest file the child may write (RLIMIT_FSIZE); SIGXFSZ beyond it.
        open_files: open file descriptors (RLIMIT_NOFILE).
        grace_seconds: time between SIGINT and SIGKILL when the wall time runs out.
    """

    wall_seconds: float | None = None
    memory_mb: int | None = None
    cpu_seconds: int | None = None
    max_processes: int | None = None
    stop_at_tasks: int | None = None
    file_size_mb: int | None = None
    open_files: int | None = None
    grace_seconds: float = 2.0

    def __post_init__(self):
        for field in ("wall_seconds", "memory_mb", "cpu_seconds", "max_processes", "stop_at_tasks", "file_size_mb",
                      "open_files"):
            value = getattr(self, field)
            if value is not None and not value > 0:
                raise ValueError(f"Limits.{field} is {value!r}: use a positive number, or None for no limit")
        if self.grace_seconds < 0:
            raise ValueError(f"Limits.grace_seconds is {self.grace_seconds!r}: use 0 or more seconds")

    def rlimits(self) -> dict[str, int]:
        """The limits to set, by name of the resource constant (RLIMIT_AS is in bytes)."""
        mb = 1024 * 1024
        values = {"RLIMIT_AS": self.memory_mb and self.memory_mb * mb,
                  "RLIMIT_CPU": self.cpu_seconds and int(self.cpu_seconds),
                  "RLIMIT_NPROC": self.max_processes,
                  "RLIMIT_FSIZE": self.file_size_mb and self.file_size_mb * mb,
                  "RLIMIT_NOFILE": self.open_files}
        return {name: int(value) for name, value in values.items() if value}

    def rlimit_pairs(self) -> dict[str, tuple[int, int]]:
        """(soft, hard) per resource. The CPU hard limit is one second above the soft one, so
        the child gets SIGXCPU (which says why) rather than a bare SIGKILL."""
        return {name: (value, value + 1 if name == "RLIMIT_CPU" else value)
                for name, value in self.rlimits().items()}
