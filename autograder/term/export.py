"""COURSE_DIR/grades.csv for an LMS: one row per student and assignment, final scores with the late
penalty, from the gradebook.

The course's nbgrader_config.py makes :class:`CourseCsvExport` nbgrader's export plugin and
COURSE_DIR/grades.csv its destination, so ``nbgrader export`` (in the course directory),
``python -m autograder export COURSE_DIR`` and every grading run write the same file in the same
format: nbgrader's CSV columns, quoted as CSV (a name with a comma stays one field), written to a
temporary file and then moved into place. It always holds every student of the gradebook (roster
and submitters) for every assignment: a student without a submission gets a row with score 0.
A filtered ``nbgrader export --assignment X`` may not replace grades.csv with fewer rows; it
needs a ``--to`` of its own.
"""

from __future__ import annotations

import csv
import os
from pathlib import Path

from nbgrader.api import MissingEntry
from nbgrader.plugins import CsvExportPlugin

#: nbgrader's CsvExportPlugin columns, in its order.
COLUMNS = ["assignment", "duedate", "timestamp", "student_id", "last_name", "first_name", "email", "raw_score",
           "late_submission_penalty", "score", "max_score"]

FILE_NAME = "grades.csv"


class CourseCsvExport(CsvExportPlugin):
    """nbgrader's CSV export, quoted, written atomically, and never partial under the full name."""

    def export(self, gradebook) -> None:
        dest = Path(self.to or FILE_NAME)
        if (self.student or self.assignment) and dest.name == FILE_NAME:
            only = ", ".join(str(x) for x in [*self.assignment, *self.student])
            message = (f"An export of {only} only would replace {dest} (every student and assignment) with fewer "
                       f"rows: give it a file of its own, e.g. --to {dest.with_name('grades-partial.csv')}")
            if hasattr(self.parent, "fail"):  # nbgrader's export command: its error line and exit status
                self.parent.fail(message)
            raise ValueError(message)
        rows = rows_of(gradebook, [str(x) for x in self.assignment], [str(x) for x in self.student])
        self.log.info("Exporting %d grades to %s", len(rows), dest)
        temporary = dest.with_name(f".{dest.name}.{os.getpid()}.tmp")
        with open(temporary, "w", newline="") as handle:
            writer = csv.writer(handle)
            writer.writerow(COLUMNS)
            writer.writerows([row[key] for key in COLUMNS] for row in rows)
        os.replace(temporary, dest)


def rows_of(gradebook, assignments: list[str] = (), students: list[str] = ()) -> list[dict]:
    """One dict per (assignment, student id) of the gradebook, as nbgrader's CsvExportPlugin computes
    it (no submission: score 0), values as text ('' for none)."""
    rows = []
    for assignment in gradebook.assignments:
        if assignments and assignment.name not in assignments:
            continue
        for student in sorted(gradebook.students, key=lambda student: student.id):
            if students and student.id not in students:
                continue
            row = {"assignment": assignment.name, "duedate": assignment.duedate, "student_id": student.id,
                   "last_name": student.last_name, "first_name": student.first_name, "email": student.email,
                   "max_score": assignment.max_score}
            try:
                submission = gradebook.find_submission(assignment.name, student.id)
            except MissingEntry:
                row.update(timestamp="", raw_score=0.0, late_submission_penalty=0.0, score=0.0)
            else:
                penalty = submission.late_submission_penalty
                row.update(timestamp=submission.timestamp, raw_score=submission.score, late_submission_penalty=penalty,
                           score=max(0.0, submission.score - penalty))
            rows.append({key: "" if value is None else str(value) for key, value in row.items()})
    return rows


def export(course_dir) -> Path:
    """Write the course's grades.csv (every student and assignment of the gradebook); return its path."""
    from autograder import config
    from autograder.results import gradebook

    course = Path(course_dir).resolve()
    plugin = CourseCsvExport(config=config.load(course))
    with gradebook.open_gradebook(course) as gb:
        plugin.export(gb)
    return Path(plugin.to or course / FILE_NAME)
