"""The grading report lists every submission graded so far: a run of one student or one
assignment replaces its own rows and keeps the others."""

from __future__ import annotations

import csv
import dataclasses
import json

from autograder.results import report, store
from autograder.results.grade_result import GradeResult


def _recorded(course, student, assignment, score, **fields):
    result = GradeResult(student, assignment, "digest", score=score, max_score=10, **fields)
    folder = store.state_dir(course, student, assignment)
    folder.mkdir(parents=True)
    (folder / store.STATE_FILE).write_text(json.dumps(dataclasses.asdict(result)))
    return result


def _rows(course):
    with open(course / report.FILE_NAME, newline="") as handle:
        return {(r["student_id"], r["assignment"]): r for r in csv.DictReader(handle)}


def test_a_partial_run_keeps_the_other_rows(tmp_path):
    """Re-grading bob's pubsub rewrites that row; alice's and bob's other rows stay, marked as earlier."""
    _recorded(tmp_path, "alice", "pubsub", 10)
    _recorded(tmp_path, "alice", "brightness", 11)
    _recorded(tmp_path, "bob", "brightness", 4)
    bob = _recorded(tmp_path, "bob", "pubsub", 3)
    bob.score = 6
    report.write_report(tmp_path, [bob])
    rows = _rows(tmp_path)
    assert {key: row["score"] for key, row in rows.items()} == {
        ("alice", "pubsub"): "10", ("alice", "brightness"): "11", ("bob", "brightness"): "4", ("bob", "pubsub"): "6"}
    assert rows["bob", "pubsub"]["from_cache"] == "0" and rows["alice", "pubsub"]["from_cache"] == "1"


def test_reason_for_the_student_and_note_for_the_instructor(tmp_path):
    """Both columns hold the first line: the student's reason, and the instructor's fix."""
    _recorded(tmp_path, "carol", "pubsub", 0, status="failed", reason="Named wrong.\nmore",
              detail="Rename it: mv a b\nlog...")
    report.write_report(tmp_path)
    row = _rows(tmp_path)
    assert (row["carol", "pubsub"]["reason"], row["carol", "pubsub"]["instructor_note"]) == \
        ("Named wrong.", "Rename it: mv a b")


def test_results_of_an_older_grader_are_read(tmp_path):
    """A state file without the newer fields (detail) and with a field no longer known still reads."""
    folder = store.state_dir(tmp_path, "alice", "pubsub")
    folder.mkdir(parents=True)
    (folder / store.STATE_FILE).write_text(json.dumps({"student": "alice", "assignment": "pubsub", "digest": "d",
                                                          "score": 5.0, "max_score": 10.0, "retired": 1}))
    report.write_report(tmp_path)
    assert _rows(tmp_path)["alice", "pubsub"]["score"] == "5"
