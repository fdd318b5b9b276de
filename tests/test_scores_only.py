"""Feedback before the due date with scores only (autograder.scores_only, coursehub.grading_job):
the checks' verdicts are left out, the student's own cells are not, and only while the rules say so."""

from __future__ import annotations

from datetime import datetime, timedelta, timezone

import nbformat
from import_support import module_fixture

from autograder.config import SubmitRules

# Each imports nbconvert or nbgrader.
scores_only_module = module_fixture("autograder.scores_only")
grading_job = module_fixture("coursehub.grading_job")


def test_the_checks_verdicts_are_replaced_and_the_students_outputs_kept(scores_only_module):
    nb = nbformat.v4.new_notebook()
    answer = nbformat.v4.new_code_cell("print(7)", outputs=[nbformat.v4.new_output("stream", text="7\n")])
    answer.metadata["nbgrader"] = {"solution": True, "grade": False, "grade_id": "answer"}
    check = nbformat.v4.new_code_cell(
        "grade()", outputs=[nbformat.v4.new_output("stream", text="✘ returned 255, expected 127\n")])
    check.metadata["nbgrader"] = {"solution": False, "grade": True, "grade_id": "check", "points": 4}
    nb.cells = [answer, check]
    scores_only_module.ScoresOnly().preprocess(nb, {})
    assert [o["text"] for o in nb.cells[0].outputs] == ["7\n"]
    assert [o["text"] for o in nb.cells[1].outputs] == [scores_only_module.NOTE]


def test_reasons_are_left_out_only_before_the_due_date_and_when_the_rules_say_so(grading_job):
    scores_only = grading_job.scores_only
    now = datetime.now(timezone.utc).replace(tzinfo=None)
    hide = SubmitRules(reasons_before_due=False)
    assert scores_only(hide, now + timedelta(days=1)) and scores_only(hide, None)
    assert not scores_only(hide, now - timedelta(minutes=1))
    assert not scores_only(SubmitRules(), now + timedelta(days=1))
