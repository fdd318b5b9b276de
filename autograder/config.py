"""nbgrader configuration of the course, written once here.

``write_config(course_dir)`` puts an ``nbgrader_config.py`` in a course directory that loads
:func:`apply`, so that both the nbgrader CLI (run by hand in that directory) and the autograder
use the same settings. Layout: nbgrader's own (``source/ release/ submitted/ autograded/
feedback/``), gradebook ``gradebook.db`` (SQLite) in the course root.
"""

from __future__ import annotations

from pathlib import Path

from course_lib.checks.validate import apply_student

COURSE_ID = "ros2-jazzy-opencv"

#: The stub ClearSolutions puts in place of a solution, at the solution's indentation.
CODE_STUB = "# YOUR CODE HERE\nraise NotImplementedError(\"replace this line with your code\")"


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
