"""Signal and stop a process tree: a process group and what left it. Standard library only (the
supervisor, course_lib.supervisor, runs without site-packages)."""

from __future__ import annotations

import os


def _children(pid: int) -> list[int]:
    """Direct children of process `pid` (this supervisor has a single thread)."""
    try:
        with open(f"/proc/{pid}/task/{pid}/children") as handle:
            return [int(p) for p in handle.read().split()]
    except FileNotFoundError:  # kernel without CONFIG_PROC_CHILDREN: scan /proc
        found = []
        for entry in os.listdir("/proc"):
            if entry.isdigit():
                try:
                    with open(f"/proc/{entry}/stat") as handle:
                        stat = handle.read()
                except OSError:
                    continue
                if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                    found.append(int(entry))
        return found



def _killpg(pgid: int, sig: int) -> None:
    try:
        os.killpg(pgid, sig)
    except (ProcessLookupError, PermissionError):
        pass


def _signal_tree(pid: int, sig: int) -> None:
    """Signal the process group `pid` leads, and `pid` itself only if it left that group.

    Signalling a group member twice would deliver SIGINT twice: the second one can land in the
    node's own clean-up (its finally block) and turn a clean exit into a traceback.
    """
    _killpg(pid, sig)
    try:
        if os.getpgid(pid) != pid:
            os.kill(pid, sig)
    except ProcessLookupError:
        pass
