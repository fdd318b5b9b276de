"""The submissions in nbgrader's exchange (``<exchange>/<course>/inbound/``), read by the hub's
grading service (root): which entries are submissions, whose they are, and one copied into the
course's submitted/ as ``nbgrader collect`` copies it.

nbgrader's submit names a folder ``<student>+<assignment>+<timestamp>+<random>``, copies the
student's files into it, writes ``timestamp.txt`` and ``submission_secret.txt``, and makes the
folder mode 0777 last: a folder not yet 0777 is still being written, and is read at a later look.

inbound/ is writable by every student (nbgrader's exchange), so nothing in it is trusted: an entry
is looked at without following links (:func:`look`), counts only for the roster student who owns it
(the folder's uid is the student's, whatever its name says), and is copied by
autograder.sandbox.untrusted (:func:`collect`). What is refused says why to the student who made it.
"""

from __future__ import annotations

import dataclasses
import os
import pwd
import re
import shutil
import stat
from datetime import datetime
from pathlib import Path

from autograder.sandbox import untrusted
from course_lib.checks.validate import IGNORE

#: An assignment's name as nbgrader's folders and the course's specs spell it.
ASSIGNMENT_NAME = re.compile(r"^[A-Za-z0-9_-]{1,64}$")
#: The random part nbgrader's submit adds (url-safe base64).
RANDOM_PART = re.compile(r"^[A-Za-z0-9_=-]{1,64}$")


@dataclasses.dataclass(frozen=True)
class Entry:
    """One entry of inbound/, looked at: whose it is, and why it is refused (None: taken)."""
    path: Path
    student: str             # who it counts for: the account that owns it, a roster student
    assignment: str
    submitted: datetime      # naive UTC, as nbgrader reads the folder's timestamp
    refused: str | None = None

    @property
    def name(self) -> str:
        return self.path.name


def inbound(exchange: Path, course_id: str) -> Path:
    return Path(exchange) / course_id / "inbound"


def parse_name(name: str) -> tuple[str, str, datetime] | None:
    """(student, assignment, time) of a name in nbgrader's form, or None when it is not one."""
    from nbgrader.utils import parse_utc

    parts = name.split("+")
    if len(parts) not in (3, 4) or not ASSIGNMENT_NAME.match(parts[1]) or \
            (len(parts) == 4 and not RANDOM_PART.match(parts[3])):
        return None
    try:
        return parts[0], parts[1], parse_utc(parts[2])
    except (ValueError, OverflowError, TypeError):
        return None


def look(path: Path, students: dict[str, int]) -> Entry | None:
    """The Entry of an inbound entry, refused or not; None while nbgrader's submit is still writing
    it (or it is gone). `students`: the roster's user names and their uids.

    Never follows a link: the entry is judged by lstat, and a refused entry counts for its owner
    (the student who made it sees why on their page), or for nobody when its owner is not a student."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return None
    owner = next((name for name, uid in students.items() if uid == st.st_uid), None)
    parsed = parse_name(path.name)
    named, assignment, submitted = parsed if parsed else (None, "", datetime.fromtimestamp(st.st_mtime).replace(
        microsecond=0))
    shown = untrusted.shown(path.name)
    if stat.S_ISDIR(st.st_mode) and stat.S_IMODE(st.st_mode) & 0o777 != 0o777 and parsed:
        return None  # nbgrader's submit makes the folder 0777 last
    refused = None
    if not stat.S_ISDIR(st.st_mode):
        refused = (f"{shown} in the exchange is not a folder (a link or a file), so it is not a submission: press "
                   "Submit in the Assignments panel to hand in an assignment.")
    elif parsed is None:
        refused = (f"The folder {shown} in the exchange is not named as nbgrader's Submit names a submission "
                   "(student+assignment+time+random), so it was not taken: press Submit in the Assignments panel.")
    elif named not in students:
        refused = (f"The folder {shown} in the exchange names {untrusted.shown(named)}, who is not a student of this "
                   "course, so it was not taken: press Submit in the Assignments panel to hand in as yourself.")
    elif students[named] != st.st_uid:
        refused = (f"The folder {shown} in the exchange names {untrusted.shown(named)} but was made by another "
                   "account, so it was not taken: a submission counts only for the student who hands it in.")
    return Entry(path, named if not refused else owner or _account(st.st_uid), assignment, submitted, refused)


def _account(uid: int) -> str:
    """The name of an account that is not a roster student (for the instructor's log), in brackets
    so that it is never taken for a student's name."""
    try:
        return f"({pwd.getpwuid(uid).pw_name})"
    except KeyError:
        return f"(uid {uid})"


def new_entries(folder: Path, known: set[str], students: dict[str, int]) -> list[Entry]:
    """The entries of `folder` whose names are not in `known`, refused or not (look), oldest first."""
    try:
        names = os.listdir(folder)
    except FileNotFoundError:  # not released yet: nbgrader makes inbound/ at the first release
        return []
    found = [entry for name in names if name not in known
             for entry in [look(Path(folder) / name, students)] if entry is not None]
    return sorted(found, key=lambda e: (e.submitted, e.name))


def collect(folder: Path, student: str, assignment: str, uid: int, course: Path) -> Path:
    """Copy the submission `folder` of `student` (owned by `uid`) to
    COURSE_DIR/submitted/<student>/<assignment>/ (replacing what was there) as nbgrader's collect
    does, without following anything out of it; return that folder.

    Raises:
        autograder.sandbox.untrusted.Refused: the submission is not taken (the message says why).
    """
    target = Path(course) / "submitted" / student / assignment
    target.parent.mkdir(parents=True, exist_ok=True)
    staging = target.with_name(f".{assignment}.collecting")
    untrusted.copy_tree(folder, staging, owner=uid, ignore=IGNORE)
    old = target.with_name(f".{assignment}.replaced")
    if target.exists():
        os.replace(target, old)
    os.replace(staging, target)
    shutil.rmtree(old, ignore_errors=True)
    return target


def set_aside(path: Path, row_id: int, course: Path) -> Path | None:
    """Move a refused entry out of inbound/ (so that the instructor's collect takes the last one
    graded) to COURSE_DIR/autograder/refused/<row id> (a name of the service's: the entry's own may
    be anything), by a rename, which never follows a link; None when it cannot be moved (another
    file system): it stays, known to the queue."""
    target = Path(course) / "autograder" / "refused" / str(row_id)
    target.parent.mkdir(parents=True, exist_ok=True)
    try:
        os.rename(path, target)
    except OSError:
        return None
    return target
