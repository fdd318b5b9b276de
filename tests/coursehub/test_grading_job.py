"""The feedback the hub's grading service releases (coursehub.grading_job.release): a submission
whose feedback cannot be written or released fails alone, and the others' pages are released."""

from __future__ import annotations

from support.feedback import graded_course, secret_of
from support.imports import module_fixture

from coursehub.submit_queue import Row

grading_job = module_fixture("coursehub.grading_job")  # imports nbgrader


def _page(course, student):
    from nbgrader.utils import notebook_hash

    name = notebook_hash(secret=secret_of(student), notebook_id="hw")
    return course.exchange / course.course_id / "feedback" / f"{name}.html"


def test_one_submission_whose_feedback_breaks_holds_up_no_other(grading_job, tmp_path):
    """bob's graded folder lost its submission secret (as a failed collect leaves it): his row
    fails with the error, alice's and cy's pages are released in the same batch."""
    course = graded_course(tmp_path, None, students=("alice", "bob", "cy"))
    (course.course_dir / "autograded" / "bob" / "hw" / "submission_secret.txt").unlink()
    rows = [Row(n, f"entry{n}", student, "hw", "2025-01-01 00:00:00", 1, "graded")
            for n, student in enumerate(("alice", "bob", "cy"), 1)]
    failures = grading_job.release(course, "hw", rows, hide_reasons=False)
    assert list(failures) == [2] and "submission_secret.txt" in failures[2]
    assert _page(course, "alice").is_file() and _page(course, "cy").is_file()
