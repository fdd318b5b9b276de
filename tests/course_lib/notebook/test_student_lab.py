"""Tests for course_lib.notebook.student_lab: a student's lab shows nbgrader's student side, Validate
on a lesson does not say "Success", and a refused Submit says why without a traceback.
(tests/browser/test_browser.py checks the running lab's extensions, tests/browser/test_browser_validate.py its
Validate, tests/coursehub/test_hub.py a refused Submit's dialog.)"""

import json
import subprocess
from pathlib import Path

import nbformat

from course_lib import contract
from course_lib.notebook import student_lab

ROOT = contract.ROOT


def test_make_lab_puts_the_student_config_on_the_jupyter_config_path():
    commands = subprocess.run(["make", "-n", "lab"], cwd=ROOT, capture_output=True, text=True, timeout=60).stdout
    assert f'JUPYTER_CONFIG_PATH="{ROOT}/course_lib/notebook/student_lab' in commands
    assert ".venv/bin/python -m autograder release-lab" in commands  # the assignments in its Assignments panel
    assert student_lab.CONFIG_DIR == ROOT / "course_lib" / "notebook" / "student_lab"


def test_the_lab_serves_validate_with_the_course_handler_instead_of_nbgraders():
    """nbgrader's validate extension is off and the course's, which serves the same URLs, is on
    (tests/browser/test_browser_validate.py presses Validate in the running lab)."""
    from nbgrader.server_extensions.validate_assignment import handlers as nbgrader_handlers

    from course_lib.notebook.student_lab import validate

    extensions = json.loads((student_lab.CONFIG_DIR / "jupyter_server_config.json").read_text())
    enabled = extensions["ServerApp"]["jpserver_extensions"]
    assert enabled["nbgrader.server_extensions.validate_assignment"] is False
    assert enabled["course_lib.notebook.student_lab.validate"] is True
    assert validate._jupyter_server_extension_points() == [{"module": "course_lib.notebook.student_lab.validate"}]
    assert [p for p, _ in nbgrader_handlers.default_handlers] == ["/assignments/validate", "/nbgrader_version"]
    assert issubclass(validate.ValidateHandler, nbgrader_handlers.ValidateAssignmentHandler)


def test_lessons_are_told_from_assignments(tmp_path):
    from course_lib.notebook.student_lab.validate import is_assignment, is_lesson_file

    graded = nbformat.v4.new_code_cell("assert True")
    graded.metadata["nbgrader"] = {"grade": True, "grade_id": "t1", "points": 1, "solution": False,
                                   "locked": True, "schema_version": 3}
    assert is_assignment(nbformat.v4.new_notebook(cells=[graded]))
    assert not is_assignment(nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("x = 1")]))
    for lesson in (ROOT / "notebooks").glob("*.ipynb"):
        assert is_lesson_file(lesson), lesson
    for assignment in (ROOT / "assignments" / "source").glob("*/*.ipynb"):
        assert not is_lesson_file(assignment), assignment
    # What is not a notebook is left to nbgrader, which says what is wrong with it.
    (tmp_path / "broken.ipynb").write_text("{not json")
    assert not is_lesson_file(tmp_path / "broken.ipynb") and not is_lesson_file(tmp_path / "missing.ipynb")


def test_the_lab_serves_the_assignments_panel_with_the_course_manager_instead_of_nbgraders():
    from nbgrader.server_extensions.assignment_list import handlers as nbgrader_handlers

    from course_lib.notebook.student_lab import assignment_list

    enabled = json.loads((student_lab.CONFIG_DIR / "jupyter_server_config.json").read_text())["ServerApp"][
        "jpserver_extensions"]
    assert enabled["nbgrader.server_extensions.assignment_list"] is False
    assert enabled["course_lib.notebook.student_lab.assignment_list"] is True
    assert assignment_list._jupyter_server_extension_points() == [
        {"module": "course_lib.notebook.student_lab.assignment_list"}]
    assert issubclass(assignment_list.AssignmentList, nbgrader_handlers.AssignmentList)


def _traceback_of(error: Exception) -> str:
    import traceback

    try:
        raise error
    except Exception:  # noqa: BLE001 - what nbgrader's panel formats
        return traceback.format_exc()


def test_a_refused_submit_shows_its_reason_alone_in_short_lines():
    from nbgrader.exchange import ExchangeError

    from course_lib.notebook.student_lab.assignment_list import LINE_WIDTH, refusal

    reason = "brightness allows 2 graded submissions before the due date, and you have made 2: " * 2
    shown = refusal(_traceback_of(ExchangeError(reason.strip() + "\nSee the page.")))
    assert " ".join(shown.split()) == " ".join((reason + "See the page.").split()) and "Traceback" not in shown
    assert shown.endswith("\nSee the page.") and max(len(line) for line in shown.splitlines()) <= LINE_WIDTH
    # Not a refusal but a fault: nbgrader's traceback stays, for the instructor.
    assert refusal(_traceback_of(KeyError("assignment_id"))) is None


def test_validate_progress_counts_the_code_cells_the_validation_runs():
    """The step Validate's button shows: 0 of m before the first cell (the kernel starts), then each
    code cell nbclient runs; empty code cells and markdown are not counted; nothing once it ended."""
    from course_lib.notebook.student_lab.validate_progress import ValidateProgress

    notebook = nbformat.v4.new_notebook(cells=[
        nbformat.v4.new_markdown_cell("# Title"), nbformat.v4.new_code_cell("import os\nx = 1"),
        nbformat.v4.new_code_cell("  \n"), nbformat.v4.new_code_cell("checks.selfcheck('node')")])
    progress = ValidateProgress()
    assert progress.of("a/b.ipynb") == {"running": False}
    progress.start("a/b.ipynb", notebook)
    assert progress.of("a/b.ipynb") == {"running": True, "cell": 0, "cells": 2, "line": "", "doing": ""}
    hook = progress.hook("a/b.ipynb")
    hook(cell=notebook.cells[1], cell_index=1)
    assert progress.of("a/b.ipynb") == {"running": True, "cell": 1, "cells": 2, "line": "import os", "doing": ""}
    hook(cell=notebook.cells[3], cell_index=3)
    assert progress.of("a/b.ipynb")["cell"] == 2 and progress.of("other.ipynb") == {"running": False}
    progress.finish("a/b.ipynb")
    assert progress.of("a/b.ipynb") == {"running": False}


def test_validate_progress_says_what_a_long_cell_does():
    """A build cell says it builds (35-67 s under "cell 11 of 14" said nothing), a graded test cell
    that it runs the checks; an ordinary cell, a solution cell and a cell that only mentions
    colcon say nothing more than their number."""
    from course_lib.notebook.student_lab.validate_progress import ValidateProgress

    def graded(source, **meta):
        return nbformat.v4.new_code_cell(source, metadata={"nbgrader": {"grade": True, "points": 1, **meta}})

    cells = [nbformat.v4.new_code_cell("!python -m course_lib build ros2_ws --symlink-install"),
             graded("checks.selfcheck('node')"), graded("def f():\n    pass", solution=True),
             nbformat.v4.new_code_cell("print('colcon build')"), nbformat.v4.new_code_cell("x = 1")]
    progress = ValidateProgress()
    progress.start("a.ipynb", nbformat.v4.new_notebook(cells=cells))
    hook, said = progress.hook("a.ipynb"), []
    for index, cell in enumerate(cells):
        hook(cell=cell, cell_index=index)
        said.append(progress.of("a.ipynb")["doing"])
    assert said == ["building the workspace (colcon)", "running the graded checks", "", "", ""]


def test_the_lab_loads_the_validate_progress_extension_from_the_student_config():
    """Jupyter reads jupyter_server_config.py on the student's config path, which names the folder
    of the lab extension; JupyterLab finds the extension there (its script is served from it)."""
    from jupyterlab_server.config import get_federated_extensions
    from traitlets.config.loader import PyFileConfigLoader

    config = PyFileConfigLoader("jupyter_server_config.py", path=str(student_lab.CONFIG_DIR)).load_config()
    found = get_federated_extensions(config.LabApp.extra_labextensions_path)
    for name in ("@course-lib/validate-progress", "@course-lib/validate-lesson"):
        extension = found[name]
        assert (Path(extension["ext_path"]) / extension["jupyterlab"]["_build"]["load"]).is_file()
