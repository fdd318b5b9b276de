"""nbgrader configuration of the course, written once here.

``write_config(course_dir)`` puts an ``nbgrader_config.py`` in a course directory that loads
:func:`apply`, so that both the nbgrader CLI (run by hand in that directory) and the autograder
use the same settings. Layout: nbgrader's own (``source/ release/ submitted/ autograded/
feedback/``), gradebook ``gradebook.db`` (SQLite) in the course root.
"""

from __future__ import annotations

from pathlib import Path

COURSE_ID = "ros2-jazzy-opencv"

#: Seconds an ordinary (non-graded) cell may run under grading: importing the student's module
#: imports rclpy, which takes a second or two; anything longer is a loop that must not run at import.
CELL_TIMEOUT = 30

#: Seconds a graded test cell may run: the longest check plus its start-up. Each check also
#: bounds itself (harness.Check.timeout); this is the backstop when a kernel stops answering.
TEST_CELL_TIMEOUT = 150

#: The stub ClearSolutions puts in place of a solution, at the solution's indentation.
CODE_STUB = "# YOUR CODE HERE\nraise NotImplementedError(\"replace this line with your code\")"


def cell_timeout(cell) -> int:
    """nbclient's timeout_func: graded cells get TEST_CELL_TIMEOUT, all others CELL_TIMEOUT."""
    meta = cell.get("metadata", {}).get("nbgrader", {})
    return TEST_CELL_TIMEOUT if meta.get("grade") and not meta.get("solution") else CELL_TIMEOUT


def apply(c, root: str | Path | None = None) -> None:
    """Fill an nbgrader config object (``c = get_config()``) with the course's settings."""
    c.CourseDirectory.course_id = COURSE_ID
    if root is not None:
        c.CourseDirectory.root = str(root)
    c.CourseDirectory.db_url = f"sqlite:///{Path(root).resolve() / 'gradebook.db'}" if root else ""
    c.ClearSolutions.code_stub = {"python": CODE_STUB}
    apply_student(c)
    # A student who deleted a test cell gets it back (and its points are graded), not a crash.
    c.OverwriteCells.add_missing_cells = True
    # Students' notebooks may print a lot; the feedback keeps the start of each output.
    c.LimitOutput.max_lines = 400


def apply_student(c) -> None:
    """The settings a student's nbgrader needs (the Validate button runs the whole notebook): the
    course's cell timeouts. nbgrader's default, 30 s for every cell, would cut a node check that
    grading lets run (a CellTimeoutError the student never gets at grading)."""
    c.Execute.timeout = TEST_CELL_TIMEOUT
    c.Execute.timeout_func = cell_timeout
    c.Execute.interrupt_on_timeout = True


CONFIG_TEMPLATE = '''\
# nbgrader configuration of the course (written by `python -m autograder release`).
# The settings live in autograder/config.py; edit them there.
from pathlib import Path

from autograder.config import apply

c = get_config()  # noqa: F821 (provided by nbgrader)
apply(c, Path(__file__).resolve().parent)
'''


def write_config(course_dir: Path) -> Path:
    """Write course_dir/nbgrader_config.py (idempotent) and return its path."""
    path = Path(course_dir) / "nbgrader_config.py"
    if not path.exists() or path.read_text() != CONFIG_TEMPLATE:
        path.write_text(CONFIG_TEMPLATE)
    return path
