"""A network namespace held by an open descriptor, so that "the processes of this namespace"
still means that namespace after the processes that made it have ended.

/proc/PID/ns/net names a namespace by its inode number (``net:[4026532177]``), and the kernel
gives a freed number to the next namespace it makes, within milliseconds. On a hub the grader
makes namespaces all the time (one per sandboxed build, notebook run and check), so the name of a
student's namespace, read while the student's server ran, soon names a grading's: killing "every
process in net:[N]" once the server has stopped killed a grading's colcon build. An open
descriptor of the namespace keeps it alive, and so its number can go to no other namespace.
"""

from __future__ import annotations

import os


def identity(pid: int | str) -> tuple[int, int]:
    """What tells the network namespace of process `pid` ("self": the caller) from every other
    namespace alive now. Raises OSError when the process has ended."""
    info = os.stat(f"/proc/{pid}/ns/net")
    return info.st_dev, info.st_ino


class PinnedNamespace:
    """The network namespace of one process, kept alive until close()."""

    def __init__(self, pid: int):
        """Raises OSError when process `pid` has ended (or may not be looked at)."""
        self._fd: int | None = os.open(f"/proc/{pid}/ns/net", os.O_RDONLY | os.O_CLOEXEC)
        info = os.fstat(self._fd)
        self.identity = (info.st_dev, info.st_ino)

    @classmethod
    def of(cls, pid: int) -> PinnedNamespace | None:
        """The namespace of process `pid` when it has one of its own (not the caller's); None when
        it shares the caller's (it has not entered its own yet) or has ended."""
        try:
            pinned = cls(pid)
        except OSError:
            return None
        if pinned.identity == identity("self"):
            pinned.close()
            return None
        return pinned

    def processes(self) -> list[int]:
        """The ids of the processes in this namespace, now."""
        found = []
        for entry in os.listdir("/proc"):
            if entry.isdigit():
                try:
                    if identity(entry) == self.identity:
                        found.append(int(entry))
                except OSError:  # it ended meanwhile
                    pass
        return found

    def fileno(self) -> int:
        """The open descriptor of the namespace (``nsenter --net=/proc/self/fd/N`` enters it)."""
        if self._fd is None:
            raise ValueError("the namespace was let go (close())")
        return self._fd

    def close(self) -> None:
        """Let the namespace go (it ends with its last process). Closing again does nothing."""
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def __enter__(self) -> PinnedNamespace:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
