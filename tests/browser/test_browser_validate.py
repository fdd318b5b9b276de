"""nbgrader in JupyterLab for the released brightness assignment: the Validate button and the
Assignments panel, used as a student uses them.

The brightness assignment is released as `make lab` releases the assignments for a student who
works alone (the real nbgrader CLI): into the lab's own course folder and exchange, .lab/ under the
lab's root, which the repository's nbgrader_config.py, copied there unchanged, names. Two students
work on the released notebook,
each in a folder of their own under the lab's root (the notebook writes and builds its workspace
ros2_ws next to itself): ``correct/`` holds the reference solution, ``incorrect/`` the reference with
``average_brightness`` returning 0. Each presses Validate; nbgrader saves the notebook, runs it
top to bottom on the server and answers with a dialog, whose text the tests read; no kernel it
started may be left running. A lesson (lesson/, no graded cells) gets a short answer instead.
Screenshots go to artifacts/browser/validate_<student>.png, validate_lesson.png and assignment_list.png.
"""

import json
import re
import shutil
from pathlib import Path

import pytest
from support import zoo
from support.browser import running_jupyterlab
from support.browser_nbgrader import (
    assignment_lists,
    chosen_course,
    kernel_processes,
    kernels_left,
    open_assignment_list,
    validate,
    wait_for_assignment,
)
from support.browser_notebook import close_notebook, open_notebook
from support.zoo import brightness as brightness_zoo

from course_lib import contract

ROOT = contract.ROOT
SCREENSHOTS = ROOT / "artifacts" / "browser"
ASSIGNMENT = "brightness"
#: A lesson in the student's lab, where a student may press Validate too.
LESSON = "lesson/00_setup_and_workspace.ipynb"
# Validate runs the whole notebook on the server: ~30 s on an idle 2-core machine (the node
# check alone ~20 s), several times that when the machine is busy.
VALIDATE_TIMEOUT = 300

STUDENTS = {
    "correct": [],
    "incorrect": [(brightness_zoo.SUM, "return 0")],
}

# The student's nbgrader settings as `make lab` has them: the repository's nbgrader_config.py,
# unchanged (nbgrader's lab handlers read nbgrader_config.py from the server's working directory,
# here the lab's root, never from a course directory), which names the lab's own exchange under the
# root; and a scratch cache for nbgrader's records of fetches and submissions, instead of the user's.
STUDENT_NBGRADER_CONFIG = (ROOT / "nbgrader_config.py").read_text() + """
c.Exchange.cache = {cache!r}
"""

pytestmark = pytest.mark.browser


@pytest.fixture(scope="module")
def lab_root(tmp_path_factory):
    return tmp_path_factory.mktemp("validate-lab-root")


@pytest.fixture(scope="module")
def course(lab_root):
    """The lab's own course folder, brightness released from it into the lab's exchange, as `make
    lab` releases the assignments (python -m autograder release-lab)."""
    from autograder.term import release
    from course_lib.notebook.student_lab.exchange import local_course

    assert release.release_for_lab(lab_root, [ASSIGNMENT]) == [ASSIGNMENT]
    return local_course(lab_root)


@pytest.fixture(scope="module")
def lab(course, lab_root, tmp_path_factory):
    """JupyterLab on a student's root: <student>/brightness.ipynb for each of STUDENTS, a lesson,
    nbgrader_config.py, and the lab's exchange in .lab/."""
    root = lab_root
    for student, edits in STUDENTS.items():
        # The zoo makes the submission (released notebook, reference solution, edits) in the
        # course's submitted/ folder; the student's working copy is that notebook.
        submitted = zoo.submit(course, student, ASSIGNMENT, edits)
        (root / student).mkdir()
        shutil.copy(submitted, root / student / f"{ASSIGNMENT}.ipynb")
    (root / LESSON).parent.mkdir()
    shutil.copy(ROOT / "notebooks" / Path(LESSON).name, root / LESSON)
    cache = tmp_path_factory.mktemp("nbgrader-cache")
    (root / "nbgrader_config.py").write_text(STUDENT_NBGRADER_CONFIG.format(cache=str(cache)))
    with running_jupyterlab(root, tmp_path_factory.mktemp("validate-lab-state")) as server:
        print(f"\nJupyterLab answered after {server.startup_seconds:.1f} s")
        yield server


def validate_in_lab(browser, lab, path, screenshot):
    """Open the notebook at path, press Validate, close it again; return the Validation, after
    checking that no kernel Validate started is left running."""
    page = open_notebook(browser, lab, path)
    try:
        before = kernel_processes(lab)
        result = validate(page, VALIDATE_TIMEOUT, SCREENSHOTS / screenshot)
        left = kernels_left(lab, before)
    finally:
        close_notebook(page, lab, path)
    print(f"\n{path}: Validate answered after {result.seconds:.1f} s: {result.title}\n{result.text}\n"
          f"the button said: {result.labels}")
    assert not left, f"Validate on {path} left kernels running:\n" + "\n".join(left)
    return result


def said(result, lab) -> str:
    return f"the Validate dialog said:\n{result.title}\n{result.text}\n(server log: {lab.log_path})"


@pytest.mark.timeout(VALIDATE_TIMEOUT + 300)
def test_validate_says_success_for_the_reference_solution(browser, lab):
    result = validate_in_lab(browser, lab, f"correct/{ASSIGNMENT}.ipynb", "validate_correct.png")
    verdict = (result.title, result.outcome, result.error)
    assert verdict == ("Validation Results", "success", False), said(result, lab)
    assert result.text == "Success! Your notebook passes all the tests.", said(result, lab)
    # nbgrader ran the notebook in the student's folder: that is where the module was written.
    assert (lab.root_dir / "correct" / "ros2_ws" / "install" / "brightness").is_dir()
    assert not (lab.root_dir / "ros2_ws").exists()
    # While it ran (13-18 s), the button said which cell runs, not only "Validating...".
    assert_button_followed_the_cells(result, lab.root_dir / "correct" / f"{ASSIGNMENT}.ipynb")


def assert_button_followed_the_cells(result, notebook: Path) -> None:
    """The Validate button said "Validating: cell k of m" with m the notebook's code cells and k
    never going back, what the build cell and the graded check cells do ("Validating: building the
    workspace (colcon), cell k of m"), and "Validate" again at the end."""
    from course_lib.notebook.student_lab.validate_progress import code_cells

    cells = len(code_cells(json.loads(notebook.read_text())))
    shown = [re.fullmatch(r"Validating: (?:(.+), )?cell (\d+) of (\d+)(, then the results)?", label)
             for label in result.labels]
    counted = [(int(found[2]), int(found[3])) for found in shown if found]
    # Both take seconds (colcon's start alone; the node check ~20 s): the button, asked once a
    # second, shows each.
    doing = {found[1] for found in shown if found and found[1]}
    assert doing == {"building the workspace (colcon)", "running the graded checks"}, result.labels
    assert counted, f"the button never said which cell runs: {result.labels}"
    assert {of for _, of in counted} == {cells}, (cells, result.labels)
    assert [cell for cell, _ in counted] == sorted(cell for cell, _ in counted), result.labels
    assert result.labels[-1] == "Validate", result.labels


@pytest.mark.timeout(VALIDATE_TIMEOUT + 300)
def test_validate_fails_a_wrong_average_and_shows_the_failing_checks(browser, lab):
    result = validate_in_lab(browser, lab, f"incorrect/{ASSIGNMENT}.ipynb", "validate_incorrect.png")
    verdict = (result.title, result.outcome, result.error)
    assert verdict == ("Validation Results", "failed", True), said(result, lab)
    # Every failed cell is shown by its source; the node publishes average_brightness's 0 as well.
    failed = re.findall(r"The following cell failed:\s*#[^\n]*\nchecks\.selfcheck\('(\w+)'\)", result.text)
    assert failed == ["values", "node"], said(result, lab)
    # A wrong number fails the self-checks, without a crash or a timeout: each check ran, and
    # Validate lists its verdict (what failed, ✘, and what passed), not a bare "Partial credit".
    assert result.text.count("[self-check · seed") == 2 and "✘" in result.text, said(result, lab)
    assert "Partial credit" not in result.text, said(result, lab)
    assert "Traceback" not in result.text and "CellTimeoutError" not in result.text, said(result, lab)


@pytest.mark.timeout(300)
def test_validate_on_a_lesson_points_at_its_self_checks_at_once_and_leaves_no_kernel(browser, lab):
    """A lesson has no graded cells: Validate answers with the fix first, in a few short lines (no
    traceback), without running the lesson in a kernel that outlives it (each press used to leave
    one running), under a heading of its own in a dialog that is no error (nbgrader's heading was
    "There was an error running the validate command:")."""
    from course_lib.notebook.student_lab.validate import LESSON_ANSWER, LESSON_HEADING

    result = validate_in_lab(browser, lab, LESSON, "validate_lesson.png")
    assert (result.title, result.outcome, result.error) == ("Validation Results", "lesson", False), said(result, lab)
    header, _, answer = result.text.partition("\n")
    assert header == LESSON_HEADING and "error" not in result.text, said(result, lab)
    assert f"{header}\n{answer.strip()}" == LESSON_ANSWER and "Traceback" not in result.text, said(result, lab)
    assert answer.strip().startswith("Use this lesson's self-check cells"), said(result, lab)


def test_make_lab_releases_into_the_labs_exchange_once_per_source(course, lab_root):
    """An assignment released from its unchanged source is not released again (`make lab` starts at
    once the second time); the release is in the exchange the lab's nbgrader_config.py names."""
    from autograder.term import release
    from course_lib.contract import COURSE_ID
    from course_lib.notebook.student_lab.exchange import local_exchange

    assert release.release_for_lab(lab_root, [ASSIGNMENT]) == []
    assert (local_exchange(lab_root) / COURSE_ID / "outbound" / ASSIGNMENT / f"{ASSIGNMENT}.ipynb").is_file()


@pytest.mark.timeout(300)
def test_assignments_panel_lists_the_released_assignment_and_fetches_it(browser, lab, course):
    """Under `make lab` (one student, no hub) Nbgrader > Assignment List shows the course and what
    `make lab` released into the lab's exchange, without an error; Fetch copies it into the lab."""
    from course_lib.contract import COURSE_ID

    page = open_assignment_list(browser, lab)
    try:
        assert wait_for_assignment(page, "released", ASSIGNMENT, 60) == f"{ASSIGNMENT} | {COURSE_ID} | Fetch"
        shown = assignment_lists(page)
        assert not any(row.startswith("(error)") for rows in shown.values() for row in rows), shown
        assert chosen_course(page) == COURSE_ID
        page.locator("#released_assignments_list > .list_item", has_text=ASSIGNMENT).get_by_role(
            "button", name="Fetch").click()
        assert wait_for_assignment(page, "fetched", ASSIGNMENT, 60) == f"{ASSIGNMENT} | {COURSE_ID} | Submit"
        SCREENSHOTS.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(SCREENSHOTS / "assignment_list.png"))
    finally:
        page.close()
    fetched = lab.root_dir / ASSIGNMENT / f"{ASSIGNMENT}.ipynb"
    assert fetched.read_bytes() == (course / "release" / ASSIGNMENT / f"{ASSIGNMENT}.ipynb").read_bytes()
