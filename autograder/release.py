"""The course root (config, source/) and the student versions in release/ (nbgrader generate_assignment)."""

from __future__ import annotations

import shutil
from pathlib import Path

from autograder import config
from autograder.nbgrader_cli import run_nbgrader

REPO = Path(__file__).resolve().parent.parent
REPO_SOURCE = REPO / "assignments" / "source"


def assignments_in(course: Path) -> list[str]:
    source = course / "source"
    return sorted(p.name for p in source.iterdir() if p.is_dir() and any(p.glob("*.ipynb"))) if source.is_dir() else []


def prepare_course(course_dir) -> Path:
    """Create the course root: config, and source/ from the repository when it has none."""
    course = Path(course_dir).resolve()
    course.mkdir(parents=True, exist_ok=True)
    config.write_config(course)
    if not (course / "source").is_dir():
        shutil.copytree(REPO_SOURCE, course / "source",
                        ignore=shutil.ignore_patterns(".ipynb_checkpoints", "__pycache__", "*.py"))
    return course


def release(course_dir, assignments: list[str] | None = None, duedate: str | None = None) -> list[Path]:
    """Write the student versions to COURSE_DIR/release/<assignment>/ (nbgrader generate_assignment).

    This also records each assignment, its cells and its hidden tests in the gradebook, and the
    due date when one is given (autograder.late.set_duedate; kept when released again without one).
    """
    from autograder import late

    course = prepare_course(course_dir)
    written = []
    for name in assignments or assignments_in(course):
        run_nbgrader(["generate_assignment", name, "--force"], course)
        if duedate:
            late.set_duedate(course, name, duedate)
        written.append(course / "release" / name)
    return written

