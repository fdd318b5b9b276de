"""The repository's folders that students must not read, closed to the course's group on the real
filesystem with POSIX ACL entries (their servers hide them too, autograder.sandbox.namespaces; but a student
has a password and a shell, and so an ssh login): :func:`close_to_students` when a course is
created and its hub starts, :func:`reopen_to_students` when it is removed.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import grp
import os
import pwd
import struct
from pathlib import Path


def closed_folders() -> list[Path]:
    """The repository's folders no student may read: those their servers hide
    (autograder.sandbox.namespaces.HIDDEN_FROM_STUDENTS: solutions, answer keys, hidden tests), the git history
    (the same, committed), and those made_later()."""
    from autograder.sandbox.namespaces import HIDDEN_FROM_STUDENTS, REPO

    return [*HIDDEN_FROM_STUDENTS, REPO / ".git", *made_later()]


def made_later() -> list[Path]:
    """The closed folders that no clone has until something writes there: `make lab`'s course and
    exchange (.lab/: the source notebooks), the tests' screenshots (artifacts/: a validated solution)."""
    from autograder.sandbox.namespaces import REPO

    return [REPO / ".lab", REPO / "artifacts"]


def close_to_students(course) -> list[str]:
    """Deny the course's group the closed folders (closed_folders) on the real filesystem, with an
    entry of their POSIX ACL; the instructor, in that group too, keeps reading them with an entry of
    their own. Nobody else's access changes: not the repository's owner's, root's, the grader's uids'
    or other accounts', and a test's course leaves the checkout as every other test sees it.

    A folder of made_later() that is missing is made, empty and the repository owner's, so that
    what is written there later is closed from the start.

    Returns:
        What could not be closed, each with why (a filesystem without ACLs); empty when all were.
    """
    from autograder.sandbox.namespaces import REPO

    owner = os.stat(REPO)
    for folder in made_later():
        with contextlib.suppress(FileExistsError):
            folder.mkdir(mode=0o755)
            os.chown(folder, owner.st_uid, owner.st_gid)
    return _set_course_entries(course, close=True)


def reopen_to_students(course) -> None:
    """Remove the course's entries that close_to_students added (before its accounts are removed)."""
    _set_course_entries(course, close=False)


_ACL = "system.posix_acl_access"  # acl(5) as Linux stores it: a version, then (tag, permissions, id) entries
_ACL_VERSION, _ACL_ENTRY, _NO_ID = 2, struct.Struct("<HHI"), 0xFFFFFFFF
_USER_OBJ, _USER, _GROUP_OBJ, _GROUP, _MASK, _OTHER = 0x01, 0x02, 0x04, 0x08, 0x10, 0x20


def _set_course_entries(course, close: bool) -> list[str]:
    from autograder.sandbox.namespaces import REPO

    ids = []
    with contextlib.suppress(KeyError):
        ids.append((_GROUP, grp.getgrnam(course.group).gr_gid))
    with contextlib.suppress(KeyError):
        ids.append((_USER, pwd.getpwnam(course.instructor).pw_uid))
    failed = []
    lock = os.open(REPO, os.O_RDONLY)  # the courses of one checkout (the tests' hubs) edit an ACL in turn
    try:
        fcntl.flock(lock, fcntl.LOCK_EX)
        for folder in closed_folders():
            try:
                entries = {key: perm for key, perm in _read_acl(folder).items() if key not in ids and _named(key)}
                if close:
                    entries.update({key: 0 if key[0] == _GROUP else 5 if folder.is_dir() else 4 for key in ids})
                _write_acl(folder, entries)
            except FileNotFoundError:
                continue
            except OSError as error:
                if error.errno not in (errno.EOPNOTSUPP, errno.ENOTSUP):
                    raise
                failed.append(f"{folder}: the filesystem has no POSIX ACLs ({error.strerror})")
    finally:
        os.close(lock)
    return failed


def _named(key: tuple[int, int]) -> bool:
    """Whether an ACL entry names an account or group that exists (an entry of a course removed by
    hand does not: its number may go to a new group)."""
    tag, number = key
    try:
        if tag == _USER:
            pwd.getpwuid(number)
        elif tag == _GROUP:
            grp.getgrgid(number)
    except KeyError:
        return False
    return True


def _read_acl(path: Path) -> dict[tuple[int, int], int]:
    try:
        raw = os.getxattr(path, _ACL)
    except OSError as error:
        if error.errno != errno.ENODATA:
            raise
        mode = os.stat(path).st_mode  # no ACL: the mode's three
        return {(_USER_OBJ, _NO_ID): mode >> 6 & 7, (_GROUP_OBJ, _NO_ID): mode >> 3 & 7, (_OTHER, _NO_ID): mode & 7}
    return {(tag, number): perm for tag, perm, number in _ACL_ENTRY.iter_unpack(raw[4:])}


def _write_acl(path: Path, entries: dict[tuple[int, int], int]) -> None:
    """Write an ACL; its mask is what the group class may have at most (the kernel turns an ACL with
    no named entry back into the mode's bits)."""
    entries = {key: perm for key, perm in entries.items() if key[0] != _MASK}
    named = [perm for (tag, _), perm in entries.items() if tag in (_USER, _GROUP)]
    if named:
        mask = entries[(_GROUP_OBJ, _NO_ID)]
        for perm in named:
            mask |= perm
        entries[(_MASK, _NO_ID)] = mask
    os.setxattr(path, _ACL, struct.pack("<I", _ACL_VERSION)
                + b"".join(_ACL_ENTRY.pack(tag, perm, number) for (tag, number), perm in sorted(entries.items())))
