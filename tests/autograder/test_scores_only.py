"""Feedback before the due date with scores only (autograder.term.scores_only, coursehub.grading_job):
the checks' verdicts are left out, the student's own cells are not, and only while the rules say so;
seen on the page the grading service releases into the exchange, which the student fetches."""

from __future__ import annotations

import html
from datetime import datetime, timedelta, timezone

import nbformat
import pytest
from support.feedback import VERDICT, graded_course
from support.imports import module_fixture

from autograder.config import SubmitRules
from coursehub.submit_queue import Row

# Each imports nbconvert or nbgrader.
scores_only_module = module_fixture("autograder.term.scores_only")
grading_job = module_fixture("coursehub.grading_job")


def test_the_checks_verdicts_are_replaced_and_the_students_outputs_kept(scores_only_module):
    nb = nbformat.v4.new_notebook()
    answer = nbformat.v4.new_code_cell("print(7)", outputs=[nbformat.v4.new_output("stream", text="7\n")])
    answer.metadata["nbgrader"] = {"solution": True, "grade": False, "grade_id": "answer"}
    check = nbformat.v4.new_code_cell(
        "grade()", outputs=[nbformat.v4.new_output("stream", text="✘ returned 255, expected 127\n")])
    check.metadata["nbgrader"] = {"solution": False, "grade": True, "grade_id": "check", "points": 4}
    nb.cells = [answer, check]
    scores_only_module.ScoresOnly()(nb, {})  # as an exporter calls it: a disabled one changes nothing
    assert [o["text"] for o in nb.cells[0].outputs] == ["7\n"]
    assert [o["text"] for o in nb.cells[1].outputs] == [scores_only_module.NOTE]


def test_reasons_are_left_out_only_before_the_due_date_and_when_the_rules_say_so(grading_job):
    scores_only = grading_job.scores_only
    now = datetime.now(timezone.utc).replace(tzinfo=None)
    hide = SubmitRules(reasons_before_due=False)
    assert scores_only(hide, now + timedelta(days=1)) and scores_only(hide, None)
    assert not scores_only(hide, now - timedelta(minutes=1))
    assert not scores_only(SubmitRules(), now + timedelta(days=1))


DAY = timedelta(days=1)


def _released_page(grading_job, course) -> str:
    """alice's feedback page of hw as the grading service releases it into the exchange (its text)."""
    from nbgrader.utils import notebook_hash

    hide = grading_job.scores_only(SubmitRules(reasons_before_due=False), grading_job.duedate(course.course_dir, "hw"))
    row = Row(1, "entry", "alice", "hw", "2025-01-01 00:00:00", 1, "graded")
    grading_job.release(course, "hw", [row], hide)
    name = notebook_hash(secret="secret", notebook_id="hw")
    return html.unescape((course.exchange / course.course_id / "feedback" / f"{name}.html").read_text())


@pytest.mark.parametrize("due", [None, DAY], ids=["no due date", "due tomorrow"])
def test_feedback_released_before_the_due_date_shows_the_score_and_the_note_not_the_verdict(
        grading_job, scores_only_module, tmp_path, due):
    note = scores_only_module.NOTE
    now = datetime.now(timezone.utc).replace(tzinfo=None)
    page = _released_page(grading_job, graded_course(tmp_path, due and now + due))
    assert "Score: 3.0 / 4.0" in page
    assert note.strip() in page and VERDICT.strip() not in page
    assert ">7\n" in page  # the student's own output stays


def test_feedback_released_after_the_due_date_shows_the_verdict(grading_job, scores_only_module, tmp_path):
    note = scores_only_module.NOTE
    now = datetime.now(timezone.utc).replace(tzinfo=None)
    page = _released_page(grading_job, graded_course(tmp_path, now - DAY))
    assert "Score: 3.0 / 4.0" in page
    assert VERDICT.strip() in page and note.strip() not in page
