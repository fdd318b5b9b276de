"""Tests for course_lib.progress outside a kernel (tests/browser/test_browser.py watches the line in
JupyterLab while a cell runs, and the lessons' build and self-check leave theirs)."""

import threading

import pytest

from course_lib import progress


def test_outside_a_kernel_progress_shows_nothing_and_starts_no_thread(capsys):
    threads = threading.active_count()
    with progress.Progress("colcon build in ws") as shown:
        shown.step("Starting >>> my_package\n")
        assert shown.current == "Starting >>> my_package"
        assert threading.active_count() == threads
    assert capsys.readouterr() == ("", "")


def test_while_running_keeps_the_function_its_result_and_its_errors():
    @progress.while_running("self-check: adding")
    def add(a, b):
        """Add two numbers."""
        if a is None:
            raise ValueError("no a")
        return a + b

    assert (add(2, 3), add.__name__, add.__doc__) == (5, "add", "Add two numbers.")
    with pytest.raises(ValueError, match="no a"):
        add(None, 1)
