"""A course with graded submissions as a grading leaves them, for the tests of feedback and its
release (no grading run: the gradebook, the grader's records and the autograded notebooks)."""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path

import nbformat

#: What the graded check printed (its verdict).
VERDICT = "✘ returned 255, expected 127\n"


@dataclasses.dataclass
class HubCourse:
    """What coursehub.grading_job.release reads of the hub's course (coursehub.course.Course)."""
    course_dir: Path
    exchange: Path
    course_id: str
    instructor: str


def secret_of(student: str) -> str:
    """The submission secret of a student's graded submission (its feedback page's name derives from it)."""
    return "secret" if student == "alice" else f"secret-{student}"


def graded_course(root, duedate, students=("alice",)) -> HubCourse:
    """A course whose assignment hw (notebook hw: check 4 points, due at `duedate` or never) has
    each student's submission graded 3 of 4, as a grading leaves it: the gradebook, the grader's
    record and the autograded notebook, whose check printed VERDICT (secret: secret_of)."""
    import pwd

    from autograder import config
    from autograder.results import gradebook, store
    from autograder.results.grade_result import GradeResult

    course = root / "course"
    course.mkdir()
    config.write_config(course)
    with gradebook.open_gradebook(course) as gb:
        gb.update_or_create_assignment("hw", duedate=duedate and f"{duedate:%Y-%m-%d %H:%M:%S} UTC")
        gb.add_notebook("hw", "hw")
        gb.add_solution_cell("answer", "hw", "hw")
        gb.add_grade_cell("check", "hw", "hw", max_score=4, cell_type="code")
    for student in students:
        (course / "submitted" / student / "hw").mkdir(parents=True)
        graded = course / "autograded" / student / "hw"
        graded.mkdir(parents=True)
        (graded / "submission_secret.txt").write_text(secret_of(student))
        nb = nbformat.v4.new_notebook()
        answer = nbformat.v4.new_code_cell("print(7)", outputs=[nbformat.v4.new_output("stream", text="7\n")])
        answer.metadata["nbgrader"] = {"solution": True, "grade": False, "locked": False, "grade_id": "answer",
                                       "schema_version": 3}
        check = nbformat.v4.new_code_cell("grade()", outputs=[nbformat.v4.new_output("stream", text=VERDICT)])
        check.metadata["nbgrader"] = {"solution": False, "grade": True, "locked": True, "grade_id": "check",
                                      "points": 4, "schema_version": 3}
        nb.cells = [answer, check]
        nbformat.write(nb, graded / "hw.ipynb")
        store.save_result(course, GradeResult(student, "hw", "digest", score=3, max_score=4, cells=[
            {"notebook": "hw", "cell": "check", "auto_score": 3.0, "max_score": 4}]), config.load(course))
    (root / "exchange" / "c101").mkdir(parents=True)  # the hub made it when it released hw
    return HubCourse(course, root / "exchange", "c101", pwd.getpwuid(os.getuid()).pw_name)
