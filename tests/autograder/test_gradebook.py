"""The grader's write-back into the gradebook leaves it as nbgrader's own autograde would: what the
formgrader reads (nbgrader's API) shows graded cells as graded, with the grader's scores, the
submission time and the late penalty; a re-grade keeps manual scores and recomputes the penalty."""

from __future__ import annotations

import datetime
import shutil
import subprocess
import sys

import pytest

from autograder import config
from autograder.results import gradebook

SCORES = {("hw", "check_a"): 3.0, ("hw", "check_b"): 1.5}


@pytest.fixture(scope="module")
def template(tmp_path_factory):
    """A course with assignment hw (notebook hw: check_a 4 points, check_b 2), due 2025-03-14 12:00
    UTC, 50 % late penalty per day, and alice's submission handed in on 2025-03-15 10:00 UTC.
    Each test gets a copy."""
    root = tmp_path_factory.mktemp("template")
    config.write_config(root)
    with open(root / "nbgrader_config.py", "a") as handle:
        handle.write("c.LatePenalty.per_day = {'hw': 0.5}\n")
    with gradebook.open_gradebook(root) as gb:
        gb.update_or_create_assignment("hw", duedate="2025-03-14 12:00:00 UTC")
        gb.add_notebook("hw", "hw")
        gb.add_grade_cell("check_a", "hw", "hw", max_score=4, cell_type="code")
        gb.add_grade_cell("check_b", "hw", "hw", max_score=2, cell_type="code")
    for folder in ("submitted", "autograded"):
        (root / folder / "alice" / "hw").mkdir(parents=True)
    (root / "submitted" / "alice" / "hw" / "timestamp.txt").write_text("2025-03-15 10:00:00")
    return root


@pytest.fixture()
def course(template, tmp_path):
    shutil.copytree(template, tmp_path / "course")
    return tmp_path / "course"


def _record(course, scores=SCORES):
    timestamp = gradebook.submitted_timestamp(course / "submitted" / "alice" / "hw")
    return gradebook.record(course, "alice", "hw", scores, timestamp, config.load(course))


def _formgrader_view(course) -> dict:
    from nbgrader.apps.api import NbGraderAPI

    (submission,) = NbGraderAPI(config=config.load(course)).get_submissions("hw")
    return submission


def test_recorded_submission_is_graded_not_needs_manual_grading(course):
    """After a write-back the formgrader lists the submission as autograded, not needing manual
    grading, with the grader's score."""
    assert _record(course) == 6
    seen = _formgrader_view(course)
    assert seen["autograded"] and not seen["needs_manual_grade"]
    assert seen["score"] == pytest.approx(4.5)


def test_each_grade_holds_the_graders_score(course):
    """Every grade cell's score is the grader's, and none needs manual grading."""
    _record(course)
    with gradebook.open_gradebook(course) as gb:
        for grade in gb.find_submission_notebook("hw", "hw", "alice").grades:
            assert grade.score == SCORES["hw", grade.name] and not grade.needs_manual_grade


def test_cell_without_an_automatic_score_needs_manual_grading(course):
    """A cell the grader could not score (None) is flagged for the instructor, as nbgrader does."""
    _record(course, {("hw", "check_a"): 3.0, ("hw", "check_b"): None})
    assert _formgrader_view(course)["needs_manual_grade"]


def test_late_submission_gets_the_configured_penalty(course):
    """22 h late = 1 started day at 50 %: half the score, recorded where nbgrader's export reads it."""
    _record(course)
    with gradebook.open_gradebook(course) as gb:
        submission = gb.find_submission("hw", "alice")
        assert submission.timestamp == datetime.datetime(2025, 3, 15, 10, 0)
        assert submission.late_submission_penalty == pytest.approx(2.25)
    assert gradebook.submission_scores(course, "alice", "hw")["score"] == pytest.approx(2.25)


def test_regrade_keeps_manual_scores_and_recomputes_the_penalty(course):
    """A manual score survives a re-grade (and flags the cell, as nbgrader does); a due date moved
    past the submission removes the penalty on the next write-back."""
    _record(course)
    with gradebook.open_gradebook(course) as gb:
        gb.find_grade("check_a", "hw", "hw", "alice").manual_score = 4.0
        gb.db.commit()
        gb.update_or_create_assignment("hw", duedate="2025-03-16 12:00:00 UTC")
    _record(course)
    with gradebook.open_gradebook(course) as gb:
        grade = gb.find_grade("check_a", "hw", "hw", "alice")
        assert grade.manual_score == 4.0 and grade.needs_manual_grade
        assert not gb.find_submission("hw", "alice").late_submission_penalty


def test_earlier_result_keeps_the_instructors_review_and_updates_the_penalty(course):
    """Writing an earlier run's result again (nothing re-graded) leaves a cell the instructor
    reviewed in the formgrader as reviewed, and recomputes the penalty for a moved due date."""
    _record(course)
    with gradebook.open_gradebook(course) as gb:
        grade = gb.find_grade("check_a", "hw", "hw", "alice")
        grade.manual_score, grade.needs_manual_grade = 4.0, False  # what the formgrader's save does
        gb.db.commit()
        gb.update_or_create_assignment("hw", duedate="2025-03-16 12:00:00 UTC")
    timestamp = gradebook.submitted_timestamp(course / "submitted" / "alice" / "hw")
    gradebook.record(course, "alice", "hw", SCORES, timestamp, config.load(course), earlier=True)
    with gradebook.open_gradebook(course) as gb:
        grade = gb.find_grade("check_a", "hw", "hw", "alice")
        assert (grade.manual_score, grade.needs_manual_grade) == (4.0, False)
        assert not gb.find_submission("hw", "alice").late_submission_penalty


def test_unreadable_timestamp_names_the_file_and_the_fix(course):
    """A timestamp.txt without a date gives an error that names the file and what to write."""
    folder = course / "submitted" / "alice" / "hw"
    (folder / "timestamp.txt").write_text("yesterday-ish")
    with pytest.raises(ValueError, match="timestamp.txt holds 'yesterday-ish'.*or delete it"):
        gradebook.submitted_timestamp(folder)


def test_no_sqlalchemy_warning_when_a_submission_is_created(course):
    """Creating a submission prints no SQLAlchemy warning (nbgrader's add_submission autoflushes)."""
    # Not the course's configuration: it also filters that warning where nbgrader itself raises it.
    code = ("import sys, warnings; from pathlib import Path; from sqlalchemy.exc import SAWarning; "
            "from traitlets.config import Config; from autograder.results import gradebook; "
            "warnings.simplefilter('error', SAWarning); "
            "gradebook.record(Path(sys.argv[1]), 'alice', 'hw', {}, None, Config())")
    done = subprocess.run([sys.executable, "-c", code, str(course)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and "SAWarning" not in done.stderr, done.stderr


def test_a_new_gradebook_is_stamped_with_the_revision_alembic_heads_names(tmp_path):
    """A gradebook created by the grader carries the schema revision nbgrader's own creation
    would ask of the `alembic heads` command (the grader reads it without starting alembic)."""
    from pathlib import Path

    from nbgrader import dbutil
    from sqlalchemy import create_engine, text

    with dbutil._temp_alembic_ini("sqlite:///unused.db") as ini:
        heads = subprocess.run([str(Path(sys.executable).parent / "alembic"), "-c", ini, "heads"],
                               capture_output=True, text=True, timeout=120, check=True).stdout
    with gradebook.open_gradebook(tmp_path):
        pass
    engine = create_engine(gradebook.db_url(tmp_path))
    with engine.connect() as connection:
        stamped = connection.execute(text("SELECT version_num FROM alembic_version")).scalar_one()
    engine.dispose()
    assert stamped == heads.split()[0] == gradebook.schema_head()


def test_the_feedback_page_reads_every_score_from_the_gradebook(course):
    """The feedback index reads the record grades.csv is made from: a manual score given in the
    formgrader shows in its check's line and in the total, not the grader's earlier score."""
    from autograder.results.grade_result import GradeResult
    from autograder.term import feedback

    _record(course)
    with gradebook.open_gradebook(course) as gb:
        gb.find_grade("check_a", "hw", "hw", "alice").manual_score = 4.0
        gb.db.commit()
    graded = GradeResult("alice", "hw", "digest", score=4.5, max_score=6,
                         cells=[{"notebook": "hw", "cell": name, "auto_score": SCORES["hw", name], "max_score": 4}
                                for name in ("check_a", "check_b")])
    page = feedback._write_index(course, "alice", [graded]).read_text()
    assert "check_a: 4 / 4" in page and "check_b: 1.5 / 2" in page
    assert "3.25 / 6" in page and "5.5 points − late penalty 2.25" in page
