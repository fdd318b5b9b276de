"""A student's folder, copied by root (or the instructor) without following anything out of it.

Students can write their submission folders in the exchange's inbound/ as they like: a file can be
a symbolic link to the instructor's solution or to /etc/shadow, a FIFO that blocks whoever reads
it, a hard link to a file elsewhere, 300 MB of data or thousands of files, or can change while it is
read. :func:`copy_tree` therefore opens every folder and file relative to its parent's descriptor
with O_NOFOLLOW (a link is never followed, not even by a race between a look and an open), judges
what it opened by ``fstat`` of that descriptor, and takes regular files and folders only: owned by
the student (when an owner is given), with one name each, within MAX_BYTES and MAX_FILES. Anything
else refuses the whole submission (:class:`Refused`, whose message says what and how to fix it),
and nothing is left in the target.
"""

from __future__ import annotations

import dataclasses
import errno
import fnmatch
import os
import shutil
import stat
from pathlib import Path

#: What one submission may hold: bytes of all its files together (nbgrader's own default for one
#: file, CourseDirectory.max_file_size), files and folders, and levels of folders.
MAX_BYTES = 100 * 1000 * 1000
MAX_FILES = 1000
MAX_DEPTH = 24

_OPEN = os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_NOCTTY | os.O_CLOEXEC
_KINDS = {stat.S_IFLNK: "a symbolic link", stat.S_IFIFO: "a FIFO (named pipe)", stat.S_IFSOCK: "a socket",
          stat.S_IFCHR: "a device", stat.S_IFBLK: "a device"}


class Refused(Exception):
    """A folder that is not taken; the message says why and what to do, in the student's words."""


@dataclasses.dataclass
class Limits:
    max_bytes: int = MAX_BYTES
    max_files: int = MAX_FILES
    max_depth: int = MAX_DEPTH


@dataclasses.dataclass
class _Walk:
    owner: int | None
    ignore: tuple
    limits: Limits
    files: int = 0
    bytes: int = 0


def shown(name: str) -> str:
    """A file name as a message shows it: quoted, control characters escaped."""
    return repr(name) if not name.isprintable() else f"'{name}'"


def copy_tree(source, target=None, *, owner: int | None = None, ignore=(), limits: Limits | None = None) -> None:
    """Copy the folder `source` to `target` (a new folder; None: only check it), leaving out names
    matching `ignore` (fnmatch patterns, e.g. course_lib.checks.validate.IGNORE).

    Raises:
        Refused: `source` or something in it is not a plain folder or file, belongs to another uid
            than `owner`, has several names (hard links) or a name with control characters, or the
            whole is over the limits. `target` is then left as it was (not made).
    """
    walk = _Walk(owner, tuple(ignore), limits or Limits())
    try:
        folder = os.open(source, _OPEN | os.O_DIRECTORY)
    except OSError as error:
        raise Refused(_not_a_folder(Path(source), error)) from None
    staging = None if target is None else Path(target).with_name(f".{Path(target).name}.copying")
    try:
        if staging is not None:
            staging.parent.mkdir(parents=True, exist_ok=True)
            shutil.rmtree(staging, ignore_errors=True)
        _copy_folder(folder, "", staging, walk, depth=0)
    except BaseException:
        if staging is not None:
            shutil.rmtree(staging, ignore_errors=True)
        raise
    finally:
        os.close(folder)
    if staging is not None:
        os.replace(staging, target)


def _not_a_folder(path: Path, error: OSError) -> str:
    try:
        kind = _KINDS.get(stat.S_IFMT(os.lstat(path).st_mode), "not a folder")
    except OSError:
        kind = f"not readable ({error.strerror})"
    return (f"The submission {shown(path.name)} is {kind}, not a folder of files, so it was not taken. "
            "Press Submit in the Assignments panel to hand in your assignment's folder.")


def _check(st: os.stat_result, relative: str, walk: _Walk) -> None:
    """Refuse what is not a plain folder or file of the owner's with one name."""
    kind = stat.S_IFMT(st.st_mode)
    if kind not in (stat.S_IFDIR, stat.S_IFREG):
        what = _KINDS.get(kind, "not a plain file")
        raise Refused(f"{shown(relative)} in your submission is {what}, and a submission holds plain files and "
                      "folders only, so it was not taken. Replace it by the file itself (or remove it) and submit "
                      "again.")
    if walk.owner is not None and st.st_uid != walk.owner:
        raise Refused(f"{shown(relative or '.')} in your submission belongs to another account than yours, so the "
                      "submission was not taken: hand in only files you made (copy another file's text into a "
                      "file of your own) and submit again.")
    if kind == stat.S_IFREG and st.st_nlink != 1:
        raise Refused(f"{shown(relative)} in your submission is a hard link (the same file under {st.st_nlink} "
                      "names), so the submission was not taken: replace it by a copy of the file and submit again.")


def _copy_folder(folder: int, relative: str, target: Path | None, walk: _Walk, depth: int) -> None:
    _check(os.fstat(folder), relative, walk)
    if depth > walk.limits.max_depth:
        raise Refused(f"{shown(relative)} in your submission is more than {walk.limits.max_depth} folders deep, so "
                      "the submission was not taken: flatten it and submit again.")
    if target is not None:
        os.mkdir(target, 0o700)
    for name in sorted(os.listdir(folder)):
        path = f"{relative}/{name}" if relative else name
        if any(fnmatch.fnmatch(name, pattern) for pattern in walk.ignore):
            continue
        if not name.isprintable():
            raise Refused(f"The name {shown(path)} in your submission has a control character (such as a newline), "
                          "so the submission was not taken: rename it and submit again.")
        walk.files += 1
        if walk.files > walk.limits.max_files:
            raise Refused(f"Your submission holds more than {walk.limits.max_files} files and folders, so it was not "
                          "taken: leave out what the assignment does not ask for (recordings, builds, data) and "
                          "submit again.")
        try:
            opened = os.open(name, _OPEN, dir_fd=folder)
        except OSError as error:  # ELOOP: a link; ENXIO: a socket; EACCES: not readable
            kind = _KINDS.get(stat.S_IFMT(os.stat(name, dir_fd=folder, follow_symlinks=False).st_mode))
            if kind is None and error.errno not in (errno.ELOOP, errno.ENXIO):
                raise Refused(f"{shown(path)} in your submission cannot be read ({error.strerror}), so the "
                              "submission was not taken: make it readable and submit again.") from None
            raise Refused(f"{shown(path)} in your submission is {kind or 'a symbolic link'}, and a submission holds "
                          "plain files and folders only, so it was not taken. Replace it by the file itself (or "
                          "remove it) and submit again.") from None
        try:
            st = os.fstat(opened)
            if stat.S_ISDIR(st.st_mode):
                _copy_folder(opened, path, None if target is None else target / name, walk, depth + 1)
            else:
                _check(st, path, walk)
                _copy_file(opened, st, path, None if target is None else target / name, walk)
        finally:
            os.close(opened)


def _copy_file(source: int, st: os.stat_result, relative: str, target: Path | None, walk: _Walk) -> None:
    """Copy an opened regular file; the bytes read, not its size at the look, count (it may grow)."""
    left = walk.limits.max_bytes - walk.bytes
    if st.st_size > left:
        _too_large(relative, walk)
    out = None if target is None else open(target, "xb")  # noqa: SIM115 - closed below
    try:
        while True:
            chunk = os.read(source, min(1 << 20, left + 1))
            if not chunk:
                break
            walk.bytes += len(chunk)
            left -= len(chunk)
            if left < 0:
                _too_large(relative, walk)
            if out is not None:
                out.write(chunk)
    finally:
        if out is not None:
            out.close()


def _too_large(relative: str, walk: _Walk) -> None:
    megabytes = walk.limits.max_bytes / 1e6
    raise Refused(f"Your submission holds more than {megabytes:g} MB (at {shown(relative)}), so it was not taken: "
                  "leave out large files (recordings, builds, data sets) and submit again.")


def read_entry(path) -> tuple[str, bytes]:
    """What a file a student's code may still change is, read without following it or blocking:
    ("link", its target), ("file", its bytes) or ("other", b"") for a FIFO, socket or device. For
    the digests root takes of a workspace the student's kernel wrote (a link swapped in, or a FIFO
    made, between a look and the read is caught by what was opened)."""
    try:
        opened = os.open(path, _OPEN)
    except OSError as error:
        if error.errno == errno.ELOOP:
            return "link", os.readlink(path).encode()
        if error.errno == errno.ENXIO:  # a socket
            return "other", b""
        raise
    try:
        if not stat.S_ISREG(os.fstat(opened).st_mode):
            return "other", b""
        with os.fdopen(os.dup(opened), "rb") as handle:
            return "file", handle.read()
    finally:
        os.close(opened)
