"""The lessons that build packages run clean in JupyterLab, as a student runs them: Run > Run All Cells.

The same test as tests/browser/test_browser.py runs for the other lessons, in a JupyterLab and a
Chromium of this module's own, so that under `--dist loadfile` the two halves of the lessons
run on two workers at once (browser_notebook.SECOND_LAB_LESSONS says which lessons are here).
"""

import pytest
from support.browser import running_jupyterlab
from support.browser_notebook import LESSON_RUN_TIMEOUT, assert_lesson_runs_clean, copy_lessons, course_lessons

pytestmark = pytest.mark.browser


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """JupyterLab on a scratch root holding a copy of notebooks/."""
    root = tmp_path_factory.mktemp("lessons-lab-root")
    copy_lessons(root)
    with running_jupyterlab(root, tmp_path_factory.mktemp("lessons-lab-state")) as server:
        print(f"\nJupyterLab answered after {server.startup_seconds:.1f} s")
        yield server


@pytest.mark.timeout(LESSON_RUN_TIMEOUT + 180)
@pytest.mark.parametrize("notebook", course_lessons(second_lab=True) or [
    pytest.param(None, marks=pytest.mark.skip(reason="none of browser_notebook.SECOND_LAB_LESSONS is in notebooks/"))])
def test_course_notebook_runs_clean_in_jupyterlab(notebook, browser, lab):
    """After Run All Cells every code cell has run, none shows an error, every image renders."""
    assert_lesson_runs_clean(browser, lab, notebook)
