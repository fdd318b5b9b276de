"""The submissions in nbgrader's exchange (``<exchange>/<course>/inbound/``), read by the hub's
grading service (root): which folders are complete submissions, whose they are, and one copied
into the course's submitted/ as ``nbgrader collect`` copies it.

nbgrader's submit names a folder ``<student>+<assignment>+<timestamp>+<random>``, copies the
student's files into it, writes ``timestamp.txt`` and ``submission_secret.txt``, and makes the
folder mode 0777 last: a folder not yet 0777 is still being written, and is read at a later look.
"""

from __future__ import annotations

import dataclasses
import os
import shutil
import stat
from datetime import datetime
from pathlib import Path

#: What nbgrader's collect leaves out of a copy (CourseDirectory.ignore's default).
IGNORED = (".ipynb_checkpoints", "*.pyc", "__pycache__", "feedback")


@dataclasses.dataclass(frozen=True)
class Entry:
    """One submission folder of inbound/."""
    path: Path
    student: str
    assignment: str
    submitted: datetime  # naive UTC, as nbgrader reads the folder's timestamp

    @property
    def name(self) -> str:
        return self.path.name


def inbound(exchange: Path, course_id: str) -> Path:
    return Path(exchange) / course_id / "inbound"


def parse(path: Path) -> Entry | None:
    """The Entry of an inbound folder, or None when its name is not nbgrader's."""
    from nbgrader.utils import parse_utc

    parts = path.name.rsplit("+", 3)
    if len(parts) < 3:
        return None
    try:
        submitted = parse_utc(parts[2])
    except (ValueError, OverflowError):
        return None
    return Entry(path, parts[0], parts[1], submitted)


def complete(path: Path) -> bool:
    """nbgrader's submit has finished writing the folder (its last step makes it 0777)."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return False
    return (stat.S_ISDIR(mode) and stat.S_IMODE(mode) & 0o777 == 0o777
            and (path / "timestamp.txt").is_file() and (path / "submission_secret.txt").is_file())


def new_entries(folder: Path, known: set[str]) -> list[Entry]:
    """The complete submissions in `folder` whose names are not in `known`, oldest first."""
    try:
        names = os.listdir(folder)
    except FileNotFoundError:  # not released yet: nbgrader makes inbound/ at the first release
        return []
    found = []
    for name in names:
        if name in known:
            continue
        entry = parse(folder / name)
        if entry is not None and complete(entry.path):
            found.append(entry)
    return sorted(found, key=lambda e: (e.submitted, e.name))


def collect(entry: Entry, course: Path) -> Path:
    """Copy the submission to COURSE_DIR/submitted/<student>/<assignment>/ (replacing what was
    there) as nbgrader's collect does; return that folder."""
    target = Path(course) / "submitted" / entry.student / entry.assignment
    target.parent.mkdir(parents=True, exist_ok=True)
    staging = target.with_name(f".{entry.assignment}.collecting")
    shutil.rmtree(staging, ignore_errors=True)
    shutil.copytree(entry.path, staging, ignore=shutil.ignore_patterns(*IGNORED))
    if target.exists():
        shutil.rmtree(target)
    os.replace(staging, target)
    return target


def set_aside(entry: Entry, course: Path) -> Path:
    """Move a refused submission out of inbound/ (so that the instructor's collect takes the last
    one graded) to COURSE_DIR/autograder/refused/; return where it went."""
    target = Path(course) / "autograder" / "refused" / entry.name
    target.parent.mkdir(parents=True, exist_ok=True)
    shutil.move(str(entry.path), target)
    return target
