"""COURSE_DIR/grading_report.csv: how each submission was graded, for the instructor.

One row per submission graded so far (every recorded result, not only the last run's, so a run
of one student or one assignment drops no row): raw score, status, whether this run took it from
an earlier one, seconds, the sandbox's isolation, the reason the student reads and the
instructor's note (the fix, or the end of nbgrader's log), and the seconds of each step of the
pipeline (``run_notebook=5.4 build_workspace=3.6 ...``: where the time went). Final scores with the late penalty,
for the LMS, are in grades.csv (autograder.term.export). The file is written to a temporary file and
then moved into place.
"""

from __future__ import annotations

import csv
import os
from pathlib import Path

from course_lib.checks.result import points_text

FILE_NAME = "grading_report.csv"

FIELDS = ["student_id", "assignment", "score", "max_score", "status", "from_cache", "seconds", "isolation",
          "reason", "instructor_note", "step_seconds"]


def _first_line(text: str) -> str:
    text = text.strip()
    return text.splitlines()[0] if text else ""


def step_seconds(result) -> str:
    """The seconds of each pipeline step that took a tenth of a second or more: "run_notebook=5.4 ..."."""
    return " ".join(f"{name}={seconds:.1f}" for name, seconds in result.steps.items() if seconds >= 0.1)


def write_report(course_dir, results=()) -> Path:
    """Write the report of every recorded result, this run's `results` in place of their records."""
    from autograder.results import store

    course = Path(course_dir)
    rows = {(r.student, r.assignment): r for r in store.recorded_results(course)}
    this_run = {(r.student, r.assignment): r for r in results}
    rows.update(this_run)
    path = course / FILE_NAME
    temporary = path.with_name(f".{FILE_NAME}.{os.getpid()}.tmp")
    with open(temporary, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(FIELDS)
        for key in sorted(rows):
            r = rows[key]
            writer.writerow([r.student, r.assignment, points_text(r.score), points_text(r.max_score), r.status,
                             int(r.from_cache or key not in this_run), f"{r.seconds:g}", r.isolation,
                             _first_line(r.reason), _first_line(r.detail), step_seconds(r)])
    os.replace(temporary, path)
    return path
