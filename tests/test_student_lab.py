"""Tests for course_lib.student_lab: a student's lab shows nbgrader's student side, and Validate
on a lesson does not say "Success". (tests/test_browser.py checks the running lab's extensions.)"""

import json
import subprocess
from pathlib import Path

import nbformat
import pytest

from course_lib import student_lab

ROOT = Path(__file__).resolve().parents[1]


def test_make_lab_puts_the_student_config_on_the_jupyter_config_path():
    commands = subprocess.run(["make", "-n", "lab"], cwd=ROOT, capture_output=True, text=True, timeout=60).stdout
    assert f'JUPYTER_CONFIG_PATH="{ROOT}/course_lib/student_lab' in commands
    assert student_lab.CONFIG_DIR == ROOT / "course_lib" / "student_lab"


def test_validate_on_a_lesson_points_at_its_self_checks(tmp_path):
    """The lab's nbgrader_config.py, loaded as the Validate button's server handler loads it,
    makes nbgrader's executor refuse a lesson (no nbgrader cells) with its task still a stub,
    before any cell runs, instead of answering 'Success'."""
    from nbgrader.apps import NbGrader

    app = NbGrader()
    app.config_file_paths.append([str(ROOT)])  # the handler adds the lab's working directory
    app.load_config_file()
    hook = app.config.Execute.on_notebook_start
    lesson = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("answer = None  # TODO")])
    with pytest.raises(student_lab.NotAnAssignment, match="self-check cell"):
        hook(notebook=lesson)


def test_assignments_are_told_from_lessons():
    graded = nbformat.v4.new_code_cell("assert True")
    graded.metadata["nbgrader"] = {"grade": True, "grade_id": "t1", "points": 1, "solution": False,
                                   "locked": True, "schema_version": 3}
    assert student_lab.is_assignment(nbformat.v4.new_notebook(cells=[graded]))
    assert not student_lab.is_assignment(nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("x = 1")]))
    for lesson in (ROOT / "notebooks").glob("*.ipynb"):
        assert not student_lab.is_assignment(json.loads(lesson.read_text())), lesson
    student_lab.refuse_lessons(notebook=nbformat.v4.new_notebook(cells=[graded]))  # no error
