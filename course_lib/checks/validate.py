"""What nbgrader's Validate button needs in a student's lab: the course's cell timeouts.

Validate runs the whole notebook, self-checks included. nbgrader's default of 30 s for every
cell would cut a node self-check that grading lets run (a CellTimeoutError the student never
gets at grading), so students' labs and the grader use the same two timeouts. A lab's
``nbgrader_config.py`` calls :func:`apply_student`; the grader's configuration
(autograder.config) builds on it.
"""

from __future__ import annotations

#: Seconds an ordinary (non-graded) cell may run: importing the student's module imports rclpy,
#: which takes a second or two; anything longer is a loop that must not run at import.
CELL_TIMEOUT = 30

#: Seconds a graded test cell may run: the longest check plus its start-up. Each check also
#: bounds itself (registry.Check.timeout); this is the backstop when a kernel stops answering.
TEST_CELL_TIMEOUT = 150


#: Seconds nbclient waits for the kernel to start (nbclient's own default).
STARTUP_TIMEOUT = 60

#: Seconds nbclient waits, once a cell's reply has come, for the rest of its output and the
#: kernel's idle status (nbclient's default is 4). nbgrader makes running out of it fail the whole
#: notebook; a cell interrupted at its timeout (a loop at import) leaves IPython a traceback to
#: format, which at a load of 40-60 on two cores took longer than 4 s: the submission failed.
IOPUB_TIMEOUT = 10


def scaled(seconds: float) -> int:
    """`seconds` on an idle machine, times the load factor (course_lib.checks.context.scaled: the
    grader's, or in a student's lab the machine's load now). The grader's wall time for the whole
    notebook grows with the load, and so must these: a cell that runs right, or a kernel that
    starts, must never be cut because the machine was busy."""
    from course_lib.checks.context import scaled as backstop

    return round(backstop(seconds))


def build_cell(cell) -> bool:
    """Whether a cell builds a workspace with colcon (``python -m course_lib build``)."""
    return "course_lib build" in cell.get("source", "")


def graded_cell(cell) -> bool:
    """Whether a cell is a graded test cell: it runs the assignment's checks."""
    meta = cell.get("metadata", {}).get("nbgrader", {})
    return bool(meta.get("grade") and not meta.get("solution"))


def long_cell(cell) -> bool:
    """Whether a cell may run long: a graded test cell (its checks), or a workspace's build cell (a
    message package takes tens of seconds to build). Every other cell is an ordinary one."""
    return build_cell(cell) or graded_cell(cell)


def cell_timeout(cell) -> int:
    """nbclient's timeout_func: long cells (long_cell) get TEST_CELL_TIMEOUT, all others
    CELL_TIMEOUT (both scaled)."""
    return scaled(TEST_CELL_TIMEOUT if long_cell(cell) else CELL_TIMEOUT)


#: What nbgrader leaves out when it submits, collects or autogrades a folder: its defaults, and
#: colcon's output folders (a workspace's build/, install/ and log/ are made again by its build).
IGNORE = [".ipynb_checkpoints", "*.pyc", "__pycache__", "feedback", "build", "install", "log"]


def apply_student(c) -> None:
    """Give an nbgrader config object (``c = get_config()``) the course's cell timeouts and the
    files it leaves out (IGNORE)."""
    c.CourseDirectory.ignore = IGNORE
    c.Execute.timeout = scaled(TEST_CELL_TIMEOUT)
    c.Execute.timeout_func = cell_timeout
    c.Execute.startup_timeout = scaled(STARTUP_TIMEOUT)
    c.Execute.iopub_timeout = scaled(IOPUB_TIMEOUT)
    c.Execute.interrupt_on_timeout = True
