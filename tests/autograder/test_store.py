"""The recorded results (autograder.results.store): written beside each submission and into the course
gradebook, read back for the report and the feedback, and reused while a submission is unchanged."""

from __future__ import annotations

import json
import shutil

import pytest

from autograder import config
from autograder.results import gradebook, store
from autograder.results.grade_result import GradeResult
from autograder.results.submissions import Submission, submission_digest


@pytest.fixture(scope="module")
def pubsub_gradebook(tmp_path_factory):
    """A gradebook with pubsub (one notebook, two graded cells of 5 points), made once: nbgrader
    takes seconds to create one (it asks alembic in a subprocess)."""
    folder = tmp_path_factory.mktemp("gradebook")
    with gradebook.open_gradebook(folder) as gb:
        gb.add_assignment("pubsub")
        gb.add_notebook("pubsub", "pubsub")
        for cell in ("check_publisher", "check_subscriber"):
            gb.add_grade_cell(cell, "pubsub", "pubsub", max_score=5, cell_type="code")
    return folder / "gradebook.db"


@pytest.fixture
def course(tmp_path, pubsub_gradebook):
    """A course with that gradebook and alice's submission of pubsub."""
    config.write_config(tmp_path)
    shutil.copyfile(pubsub_gradebook, tmp_path / "gradebook.db")
    folder = tmp_path / "submitted" / "alice" / "pubsub"
    folder.mkdir(parents=True)
    (folder / "pubsub.ipynb").write_text("{}")
    return tmp_path


def _graded(course, sub: Submission) -> GradeResult:
    cells = [{"notebook": "pubsub", "cell": "check_publisher", "auto_score": 5.0, "max_score": 5.0},
             {"notebook": "pubsub", "cell": "check_subscriber", "auto_score": 2.5, "max_score": 5.0}]
    return GradeResult(sub.student, sub.assignment, submission_digest(sub, course), score=7.5, cells=cells)


def test_a_saved_result_is_read_back_and_its_scores_are_in_the_gradebook(course):
    """save_result writes autograder.json under COURSE_DIR/autograder/ (not autograded/) and the
    cells' scores into the gradebook; recorded_results reads the same result back."""
    sub = Submission("alice", "pubsub", course / "submitted" / "alice" / "pubsub")
    result = _graded(course, sub)
    store.save_result(course, result, config.load(course))
    assert result.max_score == 10.0
    assert (course / "autograder" / "alice" / "pubsub" / store.STATE_FILE).is_file()
    assert store.recorded_results(course) == [result]
    with gradebook.open_gradebook(course) as gb:
        assert gb.find_submission("pubsub", "alice").score == 7.5


def test_an_unchanged_submission_reuses_its_result_until_it_changes(course):
    """cached_result returns the recorded result (marked from_cache) while the digest matches, and
    nothing once the submission changed or when nothing was recorded."""
    sub = Submission("alice", "pubsub", course / "submitted" / "alice" / "pubsub")
    assert store.cached_result(course, sub) is None
    store.save_result(course, _graded(course, sub), config.load(course))
    cached = store.cached_result(course, sub)
    assert cached is not None and cached.from_cache and cached.score == 7.5
    (sub.path / "pubsub.ipynb").write_text('{"cells": []}')
    assert store.cached_result(course, sub) is None


def test_recorded_results_are_sorted_and_filtered(tmp_path):
    """Results come sorted by student and assignment; one student's or one assignment's on request."""
    for student, assignment in [("bob", "pubsub"), ("alice", "pubsub"), ("alice", "brightness")]:
        folder = store.state_dir(tmp_path, student, assignment)
        folder.mkdir(parents=True)
        (folder / store.STATE_FILE).write_text(json.dumps({"student": student, "assignment": assignment,
                                                           "digest": "d", "from_an_older_grader": 1}))
    assert [(r.student, r.assignment) for r in store.recorded_results(tmp_path)] == [
        ("alice", "brightness"), ("alice", "pubsub"), ("bob", "pubsub")]
    assert [r.student for r in store.recorded_results(tmp_path, assignment="pubsub")] == ["alice", "bob"]
    assert [r.assignment for r in store.recorded_results(tmp_path, student="alice")] == ["brightness", "pubsub"]


def test_an_unreadable_record_names_the_command_that_grades_it_again(tmp_path):
    """A damaged autograder.json stops the report with the file and the re-grade command."""
    folder = store.state_dir(tmp_path, "alice", "pubsub")
    folder.mkdir(parents=True)
    (folder / store.STATE_FILE).write_text("{not json")
    with pytest.raises(ValueError, match="--student alice --assignment pubsub --force"):
        store.recorded_results(tmp_path)
