"""Graded feedback for a student who works alone (``make lab``): ``python -m autograder grade-lab``.

Submit in the lab's Assignments panel files a copy in the lab's own exchange (``.lab/exchange``,
course_lib.notebook.student_lab.exchange), where no instructor collects it. This command does what
an instructor would, on the student's own machine: the latest submission of each assignment in the
exchange's inbound/ is collected into the lab's course folder (``.lab/course/submitted/<student>/
<assignment>/``), graded by the course's grader (autograder.term.grade: the sandbox, the hidden checks,
the answer keys), its feedback written (autograder.term.feedback) and released where nbgrader's Fetch
Feedback looks for it: ``<exchange>/<course>/feedback/<hash>.html``, the hash of the submission's
secret and the notebook's name, as ``nbgrader release_feedback`` names it.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

from autograder import config
from autograder.results.grade_result import GradeResult
from autograder.term.release import REPO


def latest_submissions(exchange: Path, assignments: list[str] | None = None) -> dict[tuple[str, str], Path]:
    """(student, assignment) -> the folder of the latest submission in the exchange's inbound/
    (nbgrader's names: ``<student>+<assignment>+<time>[+<random>]``), of the given assignments or all."""
    from nbgrader.utils import parse_utc

    inbound = Path(exchange) / config.COURSE_ID / "inbound"
    latest: dict[tuple[str, str], tuple] = {}
    for folder in sorted(inbound.iterdir()) if inbound.is_dir() else []:
        parts = folder.name.split("+")
        if len(parts) not in (3, 4) or not folder.is_dir() or (assignments and parts[1] not in assignments):
            continue
        try:
            when = parse_utc(parts[2])
        except ValueError:
            continue
        if (parts[0], parts[1]) not in latest or when > latest[parts[0], parts[1]][0]:
            latest[parts[0], parts[1]] = (when, folder)
    return {pair: folder for pair, (_when, folder) in sorted(latest.items())}


def collect(submission: Path, course: Path, student: str, assignment: str) -> Path:
    """Copy a submission of the exchange to course/submitted/<student>/<assignment>/, replacing the one there."""
    target = course / "submitted" / student / assignment
    if target.exists():
        shutil.rmtree(target)
    shutil.copytree(submission, target, symlinks=True)
    return target


def release_feedback(course: Path, exchange: Path, student: str, assignment: str) -> list[Path]:
    """Put the feedback pages of a graded submission where the student's Fetch Feedback finds them."""
    from nbgrader.utils import notebook_hash

    source = course / "feedback" / student / assignment
    target = Path(exchange) / config.COURSE_ID / "feedback"
    target.mkdir(parents=True, exist_ok=True)
    secret = (source / "submission_secret.txt").read_text()
    released = []
    for page in sorted(source.glob("*.html")):
        released.append(target / f"{notebook_hash(secret=secret, notebook_id=page.stem)}.html")
        shutil.copyfile(page, released[-1])
    return released


def grade_lab(lab_root=REPO, assignments: list[str] | None = None) -> list[GradeResult]:
    """Grade the latest submission of each assignment (or of the given ones) in the exchange of the
    lab served from lab_root, and release its feedback for Fetch Feedback; return the results."""
    from autograder.term import feedback, grade
    from course_lib.notebook.student_lab.exchange import local_course, local_exchange

    course, exchange = local_course(lab_root), local_exchange(lab_root)
    results = []
    for (student, assignment), submission in latest_submissions(exchange, assignments).items():
        collect(submission, course, student, assignment)
        print(f"Grading {assignment}, submitted {submission.name.split('+')[2]} (the quiz takes seconds, an "
              "assignment with nodes up to about half a minute)", file=sys.stderr, flush=True)
        (result,) = grade.grade(course, assignment, student=student, progress=False)
        if result.status != "failed":
            feedback.write_feedback(course, assignment, student)
            release_feedback(course, exchange, student, assignment)
        results.append(result)
    return results


def summary(result: GradeResult) -> str:
    """One line for the student: the score and where the feedback is, or why there is none."""
    if result.status == "failed":
        return (f"{result.assignment}: not graded: {result.reason.strip() or 'see the grading report'} "
                "(no feedback to fetch)")
    return (f"{result.assignment}: {result.score:g} / {result.max_score:g}; press Fetch Feedback in "
            f"Nbgrader > Assignment List, then open {result.assignment}/feedback/")
