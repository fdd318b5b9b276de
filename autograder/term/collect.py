"""Submissions from an LMS download into submitted/: ``python -m autograder collect COURSE_DIR A ZIP...``.

This is nbgrader's ``zip_collect`` with the course's settings: the downloaded archives (or loose
notebooks) go to COURSE_DIR/downloaded/<assignment>/archive/, nbgrader extracts them and copies
each notebook to COURSE_DIR/submitted/<student>/<assignment>/, and writes the submission time it
reads from the file name into timestamp.txt there (the late penalty is computed from it). The
course's nbgrader_config.py makes :class:`LmsFileNames` zip_collect's file-name plugin: by
default it reads Blackboard's names (:data:`LMS_FILE_NAME`), whose times nbgrader's own date
parser misreads ("2025-03-16-09-30-00" becomes 09:00), in the time zone ``c.LmsFileNames.timezone``.
Of two attempts of one student, the later one is kept.

A student's earlier submission of the assignment is replaced by the one in the download. After
collecting, what nbgrader would not grade is reported at once: notebooks under another name
than the released one (autograder.grading.intake), and students who are not in the roster.
"""

from __future__ import annotations

import datetime
import re
import shutil
from pathlib import Path

from dateutil import tz
from nbgrader.plugins import FileNameCollectorPlugin
from traitlets import Unicode

#: The file names of submissions in an LMS download, as Blackboard names them ("Download
#: assignment", the example of nbgrader's documentation):
#: ``<assignment>_<student id>_attempt_<YYYY-MM-DD-HH-MM-SS>_<file name>``. Another LMS: set
#: c.FileNameCollectorPlugin.named_regexp in the course's nbgrader_config.py (groups student_id,
#: file_id and, for the submission time, timestamp).
LMS_FILE_NAME = (r".*?_(?P<student_id>[^_/]+)_attempt_(?P<timestamp>\d{4}-\d\d-\d\d-\d\d-\d\d-\d\d)"
                 r"_(?P<file_id>[^/]+)$")

_DASHED_TIME = re.compile(r"\d{4}-\d\d-\d\d-\d\d-\d\d-\d\d")


class LmsFileNames(FileNameCollectorPlugin):
    """nbgrader's file-name collector with Blackboard's names by default, and their times read right."""

    named_regexp = Unicode(LMS_FILE_NAME, help=FileNameCollectorPlugin.named_regexp.help).tag(config=True)
    timezone = Unicode("UTC", help="The time zone of the times in the file names (e.g. Europe/Berlin)").tag(config=True)

    def collect(self, submitted_file: str):
        info = super().collect(submitted_file)
        if info and isinstance(info.get("timestamp"), str) and _DASHED_TIME.fullmatch(info["timestamp"]):
            zone = tz.gettz(self.timezone)
            if zone is None:
                self.log.error("c.LmsFileNames.timezone = %r is no time zone (e.g. Europe/Berlin, UTC)", self.timezone)
                raise ValueError(f"c.LmsFileNames.timezone = {self.timezone!r} is no time zone: use a name like "
                                 "Europe/Berlin or UTC")
            local = datetime.datetime.strptime(info["timestamp"], "%Y-%m-%d-%H-%M-%S").replace(tzinfo=zone)
            # nbgrader keeps times as naive UTC
            info["timestamp"] = local.astimezone(datetime.timezone.utc).replace(tzinfo=None)
        return info


def collect(course_dir, assignment: str, archives: list) -> list[str]:
    """Collect an assignment's submissions from LMS downloads; return one line per student and per problem.

    Raises:
        FileNotFoundError: an archive does not exist.
        ValueError: the assignment was not released, or nothing in the download matched the file names.
    """
    from autograder import nbgrader_cli
    from autograder.grading import intake
    from autograder.results import gradebook
    from autograder.term import release

    course = release.prepare_course(course_dir)
    if not (course / "release" / assignment).is_dir():
        raise ValueError(f"{assignment} has not been released in {course}: run python -m autograder release {course} "
                         f"--assignment {assignment} first (zip_collect compares the names with the released "
                         "notebooks)")
    inbox = course / "downloaded" / assignment / "archive"
    inbox.mkdir(parents=True, exist_ok=True)
    for archive in map(Path, archives):
        if not archive.is_file():
            raise FileNotFoundError(f"{archive} does not exist: give the path of the LMS download (a .zip or "
                                    "notebooks)")
        shutil.copy2(archive, inbox / archive.name)
    before = _files(course, assignment)
    log = nbgrader_cli.zip_collect(course, assignment)
    after = _files(course, assignment)
    students = sorted({path.parent.parent.name for path, stamp in after.items() if before.get(path) != stamp})
    if not students:
        raise ValueError(f"No submission of {assignment} was collected from {inbox}: the file names do not match "
                         "c.FileNameCollectorPlugin.named_regexp (autograder.term.collect.LMS_FILE_NAME explains the "
                         "default); "
                         f"nbgrader said:\n{log[-2000:]}")
    with gradebook.open_gradebook(course) as gb:
        roster = {student.id for student in gb.students}
    lines = []
    for student in students:
        folder = course / "submitted" / student / assignment
        when = gradebook.submitted_timestamp(folder) if (folder / "timestamp.txt").exists() else None
        notebooks = ", ".join(sorted(p.name for p in folder.glob("*.ipynb")))
        lines.append(f"{student}: {notebooks} (submitted {when or 'at an unknown time'}{' UTC' if when else ''})")
        problem = intake.check(course, student, assignment, folder)
        if problem is not None:
            lines.append(f"  ! {problem.reason}\n    {problem.fix}")
        if roster and student not in roster:
            lines.append(f"  ! {student} is not in the roster: check the id, or add the student to the roster and "
                         f"import it again (python -m autograder roster {course} ROSTER.csv)")
    return lines


def _files(course: Path, assignment: str) -> dict:
    """The files of every student's submission of an assignment, and when each was written."""
    return {path: path.stat().st_mtime_ns for path in (course / "submitted").glob(f"*/{assignment}/*")}
