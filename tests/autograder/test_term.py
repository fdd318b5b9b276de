"""A term on one machine, end to end, with the real nbgrader CLI, gradebook and sandbox.

roster -> release with a due date -> an LMS download (a zip with Blackboard's file names: one
submission on time, one late, one notebook renamed by the LMS) -> collect -> grade -> what the
formgrader reads from the gradebook -> export for the LMS (late penalty applied) -> feedback; then
a changed due date changes the penalty, and a partial re-grade (one student, one assignment,
with a seed) keeps every other grade in every file. (nbgrader's own autograde, which the grader
runs in its sandbox here, refuses outside it: tests/autograder/test_guard.py.)

Three submissions are graded in the sandbox (pubsub twice, the quiz once: no ROS, no build; the
brightness reference's whole grading is tests/assignments/test_autograder_zoo.py's); the renamed one is not
run at all.
"""

from __future__ import annotations

import csv
import subprocess
import sys
import zipfile
from pathlib import Path

import nbformat
import pytest
from support import course as course_support
from support import zoo

from course_lib import contract
from course_lib.checks.result import round_points

pytestmark = [pytest.mark.slow, pytest.mark.timeout(900)]

REPO = contract.ROOT

DUE = "2025-03-14 23:59:00 UTC"
#: Blackboard's "Download assignment" names: <assignment>_<user>_attempt_<time>_<file name>.
ON_TIME, LATE = "2025-03-14-20-15-00", "2025-03-16-09-30-00"  # LATE: 1 d 9.5 h late, 2 started days
PER_DAY = 0.1
#: bob's subscriber raises in its constructor: the publisher's points only, and a traceback of his module.
BROKEN_SUBSCRIBER = [("        self.subscription = self.create_subscription(\n"
                       "            MsgTutorial, TOPIC, self.on_message, QUEUE_DEPTH)",
                      "        raise RuntimeError('subscriber not written yet')")]
ROSTER = "id,first_name,last_name,email,Section\nalice,Alice,Ang,alice@example.org,A\nbob,Bob,\"Baker, Jr.\",,A\n" \
         "carol,Carol,Chen,,B\ndave,Dave,Dunn,,B\n"


def _run(*args: str, env=None) -> subprocess.CompletedProcess:
    import os

    done = subprocess.run([sys.executable, "-m", "autograder", *args], capture_output=True, text=True,
                          env={**os.environ, **(env or {})}, timeout=600, cwd=REPO)
    assert done.returncode == 0, done.stdout + done.stderr
    return done


def _lms_zip(course: Path, folder: Path, assignment: str, entries: dict) -> Path:
    """A zip as the LMS's "download all" gives it: one notebook and one receipt per attempt."""
    path = folder / f"gradebook_{assignment}_download.zip"
    with zipfile.ZipFile(path, "w") as archive:
        for (student, when, file_name), edits in entries.items():
            nb = zoo.edited_notebook(course, assignment, edits, student)
            archive.writestr(f"{assignment}_{student}_attempt_{when}_{file_name}", nbformat.writes(nb))
            archive.writestr(f"{assignment}_{student}_attempt_{when}.txt", f"Name: {student}\nDate Submitted: {when}\n")
    return path


def _rows(path: Path, key=("student_id", "assignment")) -> dict:
    with open(path, newline="") as handle:
        return {tuple(row[k] for k in key): row for row in csv.DictReader(handle)}


@pytest.fixture(scope="module")
def term(tmp_path_factory):
    from autograder import config
    from autograder.results import store

    course = tmp_path_factory.mktemp("term") / "course"
    downloads = tmp_path_factory.mktemp("downloads")
    (downloads / "roster.csv").write_text(ROSTER)
    _run("roster", str(course), str(downloads / "roster.csv"))
    _run("release", str(course), "--assignment", "pubsub", "--assignment", "quiz", "--duedate", DUE)
    course_support.seed_interface_cache(tmp_path_factory, course, ["pubsub"])  # built once per test run
    settings = config.write_config(course)
    settings.write_text(settings.read_text() + f"c.LatePenalty.per_day = {{'pubsub': {PER_DAY}}}\n")
    pubsub = _lms_zip(course, downloads, "pubsub", {
        ("alice", ON_TIME, "pubsub.ipynb"): [],
        ("bob", LATE, "pubsub.ipynb"): BROKEN_SUBSCRIBER,
        ("carol", ON_TIME, "pubsub (1).ipynb"): [],
    })
    quiz = _lms_zip(course, downloads, "quiz", {("alice", ON_TIME, "quiz.ipynb"): []})
    collected = _run("collect", str(course), "pubsub", str(pubsub)).stdout
    _run("collect", str(course), "quiz", str(quiz))
    graded = _run("grade", str(course), "--workers", "2")
    results = {(r.student, r.assignment): r for r in store.recorded_results(course)}
    return {"course": course, "collected": collected, "results": results, "grade_output": graded.stdout + graded.stderr}


def test_collect_keeps_the_submission_time_and_names_the_renamed_notebook(term):
    """zip_collect puts each attempt in submitted/<student>/<assignment>/ with its time in
    timestamp.txt; the notebook the LMS renamed is reported at once, with the fix."""
    course = term["course"]
    assert (course / "submitted" / "bob" / "pubsub" / "timestamp.txt").read_text().startswith("2025-03-16 09:30:00")
    assert (course / "submitted" / "alice" / "quiz" / "timestamp.txt").is_file()
    assert "'pubsub (1).ipynb', not 'pubsub.ipynb'" in term["collected"]
    assert "mv " in term["collected"]


def test_formgrader_shows_graded_submissions_as_graded_with_the_graders_scores(term):
    """What the formgrader reads (nbgrader's API on the gradebook): every submission autograded,
    none "needs manual grading", each cell's score the grader's."""
    from nbgrader.api import Gradebook
    from nbgrader.apps.api import NbGraderAPI

    from autograder import config

    course, results = term["course"], term["results"]
    assert results["alice", "pubsub"].score == results["alice", "pubsub"].max_score == 10, \
        zoo.graded_outputs(course, "alice", "pubsub")
    assert 0 < results["bob", "pubsub"].score < 10, zoo.graded_outputs(course, "bob", "pubsub")
    api = NbGraderAPI(config=config.load(course))
    for assignment in ("pubsub", "quiz"):
        for submission in api.get_submissions(assignment):
            if not submission["submitted"]:
                continue
            result = results[submission["student"], assignment]
            assert submission["autograded"] and not submission["needs_manual_grade"], submission
            assert submission["score"] == pytest.approx(result.score)
    with Gradebook(f"sqlite:///{course / 'gradebook.db'}") as gb:
        for (student, assignment), result in results.items():
            if result.status == "failed":
                continue
            grades = {g.name: g for nb in gb.find_submission(assignment, student).notebooks for g in nb.grades}
            for cell in result.cells:
                assert grades[cell["cell"]].score == pytest.approx(cell["auto_score"])
                assert not grades[cell["cell"]].needs_manual_grade


def test_renamed_notebook_gets_a_reason_and_the_fix_not_an_exit_code(term):
    """The notebook the LMS renamed is not run; the report says why and how to fix it, the
    student's feedback says why."""
    row = _rows(term["course"] / "grading_report.csv")["carol", "pubsub"]
    assert row["status"] == "failed" and row["score"] == "0"
    assert "'pubsub (1).ipynb', not 'pubsub.ipynb'" in row["reason"]
    assert "exit code" not in row["reason"] and row["instructor_note"].startswith("Rename it")
    assert "--student carol --assignment pubsub" in row["instructor_note"]


def test_export_has_every_student_and_assignment_with_the_late_penalty(term):
    """grades.csv: one row per roster student and assignment; bob's late pubsub loses 10 % of his
    score per started day (2 days); names with a comma stay one field."""
    results = term["results"]
    rows = _rows(term["course"] / "grades.csv")
    assert set(rows) == {(s, a) for s in ("alice", "bob", "carol", "dave") for a in ("pubsub", "quiz")}
    bob = rows["bob", "pubsub"]
    raw = results["bob", "pubsub"].score
    assert float(bob["raw_score"]) == pytest.approx(raw)
    assert float(bob["late_submission_penalty"]) == pytest.approx(round_points(raw * 2 * PER_DAY))
    assert float(bob["score"]) == pytest.approx(raw - round_points(raw * 2 * PER_DAY))
    assert bob["last_name"] == "Baker, Jr."
    assert float(rows["alice", "pubsub"]["late_submission_penalty"]) == 0
    assert float(rows["alice", "pubsub"]["score"]) == 10
    assert float(rows["dave", "pubsub"]["score"]) == 0 and rows["dave", "pubsub"]["timestamp"] == ""


def test_nbgrader_export_writes_the_same_file(term):
    """`nbgrader export` in the course directory writes grades.csv in the same format, same rows."""
    course = term["course"]
    before = (course / "grades.csv").read_text()
    (course / "grades.csv").unlink()
    done = subprocess.run([sys.executable, "-m", "nbgrader", "export"], cwd=course, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    assert (course / "grades.csv").read_text() == before


def test_no_sqlalchemy_warnings_on_the_commands(term):
    """No SAWarning is printed by grade (which creates the gradebook's submissions)."""
    assert "SAWarning" not in term["grade_output"]


@pytest.fixture(scope="module")
def feedback(term):
    _run("feedback", str(term["course"]))
    return term["course"] / "feedback"


def test_feedback_shows_the_penalty_and_wraps_and_hides_the_graders_paths(term, feedback):
    """Feedback pages: the due date, submission time and penalty; verdict lines that wrap; no
    temporary path of the grader, no instructor note."""
    bob = (feedback / "bob" / "index.html").read_text()
    assert "due 2025-03-14 23:59 UTC" in bob and "submitted 2025-03-16 09:30 UTC" in bob and "late penalty" in bob
    page = (feedback / "bob" / "pubsub" / "pubsub.html").read_text()
    assert "subscriber not written yet" in page and 'pubsub/topic_subscriber.py"' in page.replace("&quot;", '"')
    assert "white-space: pre-wrap" in page
    carol = (feedback / "carol" / "index.html").read_text()
    assert "not &#x27;pubsub.ipynb&#x27;" in carol
    for path in feedback.rglob("*.html"):
        text = path.read_text()
        assert "autograder-work" not in text and "/tmp/" not in text, path
        assert "mv " not in text and "AutogradeApp" not in text and "manual grading" not in text, path


def test_changed_due_date_changes_the_penalty_on_the_next_grade_run(term):
    """Grading again after the due date moved (nothing re-run: the submissions did not change)
    recomputes the penalty from the new date."""
    from autograder.term import grade, late

    course = term["course"]
    late.set_duedate(course, "pubsub", "2025-03-20 12:00 UTC")
    again = grade.grade(course, "pubsub", progress=False)
    assert all(r.from_cache for r in again)
    assert float(_rows(course / "grades.csv")["bob", "pubsub"]["late_submission_penalty"]) == 0
    late.set_duedate(course, "pubsub", DUE)
    grade.grade(course, "pubsub", progress=False)
    assert float(_rows(course / "grades.csv")["bob", "pubsub"]["late_submission_penalty"]) > 0


def test_partial_regrade_keeps_every_other_grade(term, feedback):
    """Re-grading one student's assignment with a seed (grade --student --assignment --force) and
    writing that feedback only runs that submission and keeps every other row of the report,
    grades.csv, the student's other assignment and the other students' feedback pages. (alice's
    quiz is the one re-graded: the cheapest submission of the term to grade again.)"""
    course = term["course"]
    regraded = ("alice", "quiz")
    report_before = _rows(course / "grading_report.csv")
    export_before = _rows(course / "grades.csv")
    bob_page = (feedback / "bob" / "index.html").read_text()
    alice_pubsub = (course / "autograded" / "alice" / "pubsub" / "pubsub.ipynb").stat().st_mtime_ns
    alice_quiz = (course / "autograded" / "alice" / "quiz" / "quiz.ipynb").stat().st_mtime_ns
    _run("grade", str(course), "--student", "alice", "--assignment", "quiz", "--force",
         env={"AUTOGRADER_SEED": "4242"})
    _run("feedback", str(course), "--student", "alice", "--assignment", "quiz")
    report, export = _rows(course / "grading_report.csv"), _rows(course / "grades.csv")
    assert set(report) == set(report_before) and set(export) == set(export_before)
    same = ("score", "max_score", "status", "reason")
    for key in report_before:
        if key != regraded:
            assert [report[key][k] for k in same] == [report_before[key][k] for k in same], key
            assert report[key]["from_cache"] == "1"
    assert report[regraded]["from_cache"] == "0"
    assert {k: v for k, v in export.items() if k != regraded} == \
        {k: v for k, v in export_before.items() if k != regraded}
    # Graded again (the quiz draws nothing from its seed, so its verdict shows none).
    assert (course / "autograded" / "alice" / "quiz" / "quiz.ipynb").stat().st_mtime_ns != alice_quiz
    assert "[graded] " in zoo.graded_outputs(course, *regraded)
    assert (course / "autograded" / "alice" / "pubsub" / "pubsub.ipynb").stat().st_mtime_ns == alice_pubsub
    assert (feedback / "bob" / "index.html").read_text() == bob_page
    # One assignment's feedback for everyone keeps the other assignments in each index.
    _run("feedback", str(course), "--assignment", "pubsub")
    assert "<td>quiz</td>" in (feedback / "alice" / "index.html").read_text()
