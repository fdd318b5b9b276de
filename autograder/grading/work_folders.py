"""The gradings' work folders (``autograder-work-*`` in the temporary directory): made, removed,
and swept when the process that made them ended without removing them.

A grading copies the student's submission into a folder of its own (autograder.grading.pipeline) and
removes it when it ends; a process killed meanwhile removes nothing. So each folder holds a lock
file that the process which made it holds with flock for the grading's life. The kernel lets the
lock go when the process ends, however it ends (and a pid used again takes nothing over), so:

- :func:`sweep`, when a grading process starts (the hub's grading service, ``python -m
  autograder grade``), removes every folder whose lock it can take; a grading that runs in
  another process (a second service, a parallel grade run, another test worker) keeps its folder.
  A folder without a lock file (made by an older grader, or half made when its process was
  killed) goes only when nothing in it changed for UNLOCKED_SECONDS: no grading lasts that long.
- :func:`end_gradings`, when a process stops while its threads grade (the service at the hub's
  SIGINT or SIGTERM), turns the process into a remover of its folders (execv): the threads end at
  once, so none sees its folder go and records a failure for the student, and their sandboxed
  processes die with them (PR_SET_PDEATHSIG); the locks stay held until the folders are gone.

The lock file goes last, so a folder that could not be emptied (a sandboxed process of a killed
grading still wrote in it) is taken again by the next sweep.
"""

from __future__ import annotations

import fcntl
import os
import shutil
import signal
import stat
import sys
import tempfile
import threading
import time
from pathlib import Path

#: The start of every work folder's name.
PREFIX = "autograder-work-"
#: The lock file in each work folder (root-only when the grader runs as root: no student code can hold it).
LOCK_NAME = ".grading.lock"
#: A folder without a lock file is removed by a sweep only when its last change is this old.
UNLOCKED_SECONDS = 24 * 3600.0
#: Passes of emptying a folder in which a process of the grading may still write for a moment.
PASSES = 3

_held: dict[Path, int] = {}  # this process's folders and their locks' descriptors
_held_lock = threading.Lock()  # end_gradings holds it to the exec: no folder half made or let go


def make(parent: Path | None = None) -> Path:
    """A new empty work folder (mode 0700) in `parent` (default: the temporary directory), held by
    this process until :func:`remove`."""
    with _held_lock:
        path = Path(tempfile.mkdtemp(prefix=PREFIX, dir=parent))
        try:
            # Locked under another name, then renamed: a sweep never finds the lock file unlocked.
            new = path / f"{LOCK_NAME}.new"
            fd = os.open(new, os.O_RDWR | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o600)
            fcntl.flock(fd, fcntl.LOCK_EX)
            os.rename(new, path / LOCK_NAME)
        except BaseException:
            shutil.rmtree(path, ignore_errors=True)
            raise
        _held[path] = fd
    return path


def remove(path: Path) -> None:
    """Remove a work folder this process made, its lock file last, and let its lock go. What cannot
    be removed yet stays with its lock file, for the next sweep."""
    _remove_held(path)
    with _held_lock:
        fd = _held.pop(path, None)
        if fd is not None:
            os.close(fd)


def sweep(parent: Path | None = None) -> list[Path]:
    """Remove the work folders of this user's in `parent` (default: the temporary directory) whose
    process has ended: those whose lock this process can take, and those without a lock file
    unchanged for UNLOCKED_SECONDS. Returns the folders removed."""
    removed = []
    for path in sorted(Path(parent or tempfile.gettempdir()).glob(f"{PREFIX}*")):
        if _ours(path) and _remove_if_abandoned(path):
            removed.append(path)
    return removed


def end_gradings() -> None:
    """For a process that stops while its threads may grade: when it holds work folders, replace the
    process by a remover of them that keeps their locks (execv ends every other thread at once).
    Returns only when it holds none."""
    for stream in (sys.stdout, sys.stderr):  # what the process printed, before the exec drops it
        try:
            stream.flush()
        except (OSError, ValueError):  # the hub that read it is gone
            pass
    _held_lock.acquire()  # kept to the exec: no thread makes or lets go of a folder meanwhile
    if not _held:
        _held_lock.release()
        return
    for fd in _held.values():
        os.set_inheritable(fd, True)
    interrupt = signal.signal(signal.SIGINT, signal.SIG_IGN)  # kept by the remover: a second Ctrl-C leaves no folder
    try:
        # -I -S: a quick start, with nothing on sys.path but the standard library (all the remover needs).
        os.execv(sys.executable, [sys.executable, "-I", "-S", os.path.abspath(__file__),
                                  *(f"{fd}:{path}" for path, fd in _held.items())])
    except OSError:  # the next sweep takes the folders
        signal.signal(signal.SIGINT, interrupt)
        _held_lock.release()
        raise


def _ours(path: Path) -> bool:
    """Whether `path` is a folder (not a link) of this process's user: in the sticky temporary
    directory, no other user can put another in its place (a link to a folder of the system's)."""
    try:
        found = os.lstat(path)
    except OSError:
        return False
    return stat.S_ISDIR(found.st_mode) and found.st_uid == os.geteuid()


def _remove_if_abandoned(path: Path) -> bool:
    """Remove `path` when its lock can be taken (its process ended), or it has none and is old."""
    lock = path / LOCK_NAME
    try:
        fd = os.open(lock, os.O_RDONLY | os.O_NOFOLLOW)
    except FileNotFoundError:
        return _unchanged_for(path, UNLOCKED_SECONDS) and _remove_held(path, locked=False)
    except OSError:
        return False
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:  # its grading runs
            return False
        return _is_lock_of(fd, path) and _remove_held(path)
    finally:
        os.close(fd)


def _is_lock_of(fd: int, path: Path) -> bool:
    """Whether `fd` is still the lock file of `path` (another sweep may have removed the folder
    while this one waited, and a grading made one of that name again)."""
    try:
        found, held = os.stat(path / LOCK_NAME, follow_symlinks=False), os.fstat(fd)
    except OSError:
        return False
    return (found.st_dev, found.st_ino) == (held.st_dev, held.st_ino)


def _unchanged_for(path: Path, seconds: float) -> bool:
    try:
        return time.time() - path.lstat().st_mtime > seconds
    except OSError:
        return False


def _remove_held(path: Path, locked: bool = True) -> bool:
    """Empty `path` but its lock file, then remove the lock file and the folder; True when gone."""
    for done in range(PASSES + 1):
        try:
            left = [entry for entry in os.scandir(path) if not (locked and entry.name == LOCK_NAME)]
        except FileNotFoundError:
            return True
        if not left:
            break
        if done == PASSES:
            return False
        for entry in left:
            _remove_entry(entry)
    try:
        if locked:
            os.unlink(path / LOCK_NAME)
        os.rmdir(path)
    except FileNotFoundError:
        pass
    except OSError:
        return False
    return True


def _remove_entry(entry: os.DirEntry) -> None:
    """Remove a file or a tree; a folder a student made unwritable is made writable (as a user
    who is not root), and what a process still running removes or writes meanwhile is let be."""
    def retry(function, name, _exc):
        try:
            os.chmod(os.path.dirname(name), 0o700)
            function(name)
        except OSError:
            pass
    try:
        if entry.is_dir(follow_symlinks=False):
            shutil.rmtree(entry.path, onerror=retry)
        else:
            os.unlink(entry.path)
    except OSError:
        pass


def _remove_inherited(arguments: list[str]) -> int:
    """The remover end_gradings becomes: FD:PATH arguments, each a folder whose lock came with the process."""
    left = []
    for argument in arguments:
        fd, path = argument.split(":", 1)
        if not (_is_lock_of(int(fd), Path(path)) and _remove_held(Path(path))):
            left.append(path)
    if left:
        print(f"autograder.grading.work_folders: {len(left)} grading work folder(s) could not be removed now (the next "
              f"sweep takes them): {', '.join(left)}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(_remove_inherited(sys.argv[1:]))
