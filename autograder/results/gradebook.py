"""The grader's write-back into the course gradebook, as nbgrader's own autograde leaves it.

nbgrader's ``autograde`` keeps a student's submission across re-grades (manual scores, comments,
extensions stay), records the submission time from ``timestamp.txt``, sets each grade's
``auto_score`` and, in its SaveAutoGrades preprocessor, ``needs_manual_grade``: True only when
the cell has a manual score or no automatic one. Then AssignLatePenalties computes each
notebook's late penalty from the final score. :func:`record` does the same with the grader's
scores, so the formgrader shows a graded submission as graded (not "needs manual grading"), with
the grader's scores, and ``nbgrader export`` applies the penalty.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path


def db_url(course: Path) -> str:
    return f"sqlite:///{Path(course).resolve() / 'gradebook.db'}"


def with_this_python(path: str) -> str:
    """A PATH with this interpreter's bin folder first: nbgrader runs `alembic` from PATH to stamp
    a new gradebook, and must find this environment's."""
    bindir = str(Path(sys.executable).parent)
    return os.pathsep.join([bindir] + [p for p in path.split(os.pathsep) if p and p != bindir])


def open_gradebook(course: Path):
    """nbgrader's Gradebook of the course (created when missing); use it with `with`."""
    from nbgrader import api

    if not (Path(course) / "gradebook.db").exists():
        # nbgrader stamps a new gradebook with the newest revision of its schema, which it asks
        # of `alembic heads` in a subprocess: 2-3 s of processor for a constant. The same
        # answer comes from its migration scripts in this process (0.15 s).
        api.get_alembic_version = schema_head
    return api.Gradebook(db_url(course))


def schema_head() -> str:
    """The newest revision of nbgrader's gradebook schema (the first line of `alembic heads`),
    read from the migration scripts nbgrader ships."""
    from alembic.script import ScriptDirectory
    from nbgrader import dbutil

    return ScriptDirectory(dbutil.ALEMBIC_DIR).get_heads()[0]


def submitted_timestamp(folder: Path):
    """The submission time in ``folder/timestamp.txt`` as nbgrader reads it (naive UTC), or None.

    Raises:
        ValueError: the file holds no date (the message names the file and the fix).
    """
    from nbgrader.utils import parse_utc

    path = Path(folder) / "timestamp.txt"
    if not path.is_file() or not path.read_text().strip():
        return None
    text = path.read_text().strip()
    try:
        return parse_utc(text)
    except (ValueError, OverflowError):
        raise ValueError(f"{path} holds {text[:60]!r}, which is not a date and time: write the submission time "
                         "in it (e.g. 2025-03-14 23:59:00 UTC) or delete it") from None


def record(course: Path, student: str, assignment: str, scores: dict, timestamp, config,
           earlier: bool = False) -> float:
    """Write a graded submission into the course gradebook and assign its late penalty.

    Args:
        scores: (notebook, grade cell) -> automatic score; a cell missing from it gets 0 (a notebook
            that could not be run earns nothing), None means it needs manual grading.
        timestamp: the submission time (naive UTC datetime) or None.
        config: the course's nbgrader configuration (autograder.config.load), for the late penalty.
        earlier: the scores are an earlier run's (nothing was graded again): when the gradebook has
            the submission, only its time and late penalty are updated, so the formgrader's manual
            grading (scores, cells marked as reviewed) stays as the instructor left it.

    Returns:
        The assignment's maximum score.
    """
    from nbgrader.api import MissingEntry

    max_score = 0.0
    with open_gradebook(course) as gb:
        gb.update_or_create_student(student)
        try:
            submission = gb.find_submission(assignment, student)
        except MissingEntry:
            # nbgrader's add_submission reads the assignment's notebooks before it adds the new
            # objects to the session; an autoflush meanwhile only raises SQLAlchemy warnings.
            with gb.db.no_autoflush:
                submission = gb.add_submission(assignment, student)
            earlier = False
        submission.timestamp = timestamp
        for notebook in submission.notebooks:
            for grade in notebook.grades:
                max_score += grade.max_score
                if earlier:
                    continue
                grade.auto_score = scores.get((notebook.name, grade.name), 0.0)
                # nbgrader's SaveAutoGrades rule
                grade.needs_manual_grade = grade.manual_score is not None or grade.auto_score is None
        gb.db.commit()
        notebooks = [notebook.name for notebook in submission.notebooks]
    for notebook in notebooks:
        assign_late_penalty(course, student, assignment, notebook, config)
    return max_score


def assign_late_penalty(course: Path, student: str, assignment: str, notebook: str, config) -> None:
    """Run nbgrader's AssignLatePenalties for one submitted notebook (with the plugin and settings
    of the course's configuration): it resets the penalty and assigns it again from the due date,
    the submission time and the notebook's current score."""
    import nbformat
    from nbgrader.preprocessors import AssignLatePenalties

    resources = {"nbgrader": {"notebook": notebook, "assignment": assignment, "student": student,
                              "db_url": db_url(course)}}
    AssignLatePenalties(config=config).preprocess(nbformat.v4.new_notebook(), resources)


def submission_scores(course: Path, student: str, assignment: str) -> dict | None:
    """A submission's scores as the gradebook holds them, the one record that the feedback page and
    grades.csv (autograder.term.export) read: each graded cell's score (a manual one where the
    formgrader gave it, as nbgrader counts it), the due date, submission time, seconds late,
    penalty (points), raw and final score; None when the gradebook has no such submission."""
    from nbgrader.api import MissingEntry

    if not (Path(course) / "gradebook.db").exists():
        return None
    with open_gradebook(course) as gb:
        try:
            submission = gb.find_submission(assignment, student)
        except MissingEntry:
            return None
        penalty = submission.late_submission_penalty or 0.0
        cells = [{"notebook": notebook.name, "cell": grade.name, "score": grade.score, "max_score": grade.max_score}
                 for notebook in submission.notebooks for grade in notebook.grades]
        return {"cells": cells, "duedate": submission.duedate, "timestamp": submission.timestamp,
                "seconds_late": submission.total_seconds_late, "penalty": penalty,
                "raw_score": submission.score, "score": max(0.0, submission.score - penalty),
                "max_score": submission.max_score}
