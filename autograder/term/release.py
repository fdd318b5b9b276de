"""The course root (config, source/), the student versions in release/ (nbgrader generate_assignment),
and their release into an exchange (nbgrader release_assignment), also a student's lab's own."""

from __future__ import annotations

import shutil
from pathlib import Path

from autograder import config, nbgrader_cli
from course_lib.contract import ASSIGNMENTS_SOURCE as REPO_SOURCE
from course_lib.contract import ROOT as REPO

#: What of an assignment's source folder a course does not take.
SOURCE_IGNORE = shutil.ignore_patterns(".ipynb_checkpoints", "__pycache__", "*.py")


def assignments_in(course: Path) -> list[str]:
    source = course / "source"
    return sorted(p.name for p in source.iterdir() if p.is_dir() and any(p.glob("*.ipynb"))) if source.is_dir() else []


def prepare_course(course_dir) -> Path:
    """Create the course root: config, and source/ from the repository when it has none."""
    course = Path(course_dir).resolve()
    course.mkdir(parents=True, exist_ok=True)
    config.write_config(course)
    if not (course / "source").is_dir():
        shutil.copytree(REPO_SOURCE, course / "source", ignore=SOURCE_IGNORE)
    return course


def release(course_dir, assignments: list[str] | None = None, duedate: str | None = None) -> list[Path]:
    """Write the student versions to COURSE_DIR/release/<assignment>/ (nbgrader generate_assignment).

    This also records each assignment, its cells and its hidden tests in the gradebook, and the
    due date when one is given (autograder.term.late.set_duedate; kept when released again without one).
    """
    from autograder.term import late

    course = prepare_course(course_dir)
    written = []
    for name in assignments or assignments_in(course):
        nbgrader_cli.generate_assignment(course, name)
        unanswered_questions(course / "release" / name, name)
        if duedate:
            late.set_duedate(course, name, duedate)
        written.append(course / "release" / name)
    return written



def unanswered_questions(folder: Path, assignment: str) -> None:
    """Give each multiple-choice answer cell of a release the stub ``q3 = None`` instead of
    nbgrader's ``raise NotImplementedError``: a question unanswered is not an error, so Run All on
    the untouched release reaches the last cell, whose self-check names what is still unanswered.
    The cells are the solution cells named after the assignment's questions (assignments/build.py
    writes them), which are neither locked nor graded: no checksum of nbgrader's covers them."""
    import nbformat

    from course_lib.checks import assignments as specs

    spec = specs.ASSIGNMENTS.get(assignment)
    if spec is None or not spec.questions:
        return
    for path in sorted(Path(folder).glob("*.ipynb")):
        nb = nbformat.read(path, as_version=4)
        for cell in nb.cells:
            name = cell.metadata.get("nbgrader", {}).get("grade_id")
            if name in spec.questions and config.CODE_STUB in cell.source:
                cell.source = cell.source.replace(config.CODE_STUB, f"{name} = None")
        nbformat.write(nb, path)


def release_to_exchange(course_dir, exchange, assignments: list[str]) -> None:
    """Put the course's student versions (release/) into an nbgrader exchange, which is made when
    missing: students see them in Nbgrader > Assignment List (nbgrader release_assignment)."""
    Path(exchange).mkdir(parents=True, exist_ok=True)
    for name in assignments:
        nbgrader_cli.release_assignment(Path(course_dir), name, Path(exchange))


def release_for_lab(lab_root=REPO, assignments: list[str] | None = None) -> list[str]:
    """Release the repository's assignments into the exchange of the lab served from lab_root (what
    ``make lab`` does for a student who works alone; course_lib.notebook.student_lab.exchange). An assignment
    whose source is as at its last release, and which is in the exchange, is left as it is.

    Returns:
        the assignments released now.
    """
    from course_lib.notebook.student_lab.exchange import local_course, local_exchange

    course, exchange = local_course(lab_root), local_exchange(lab_root)
    names = assignments or [p.name for p in sorted(REPO_SOURCE.iterdir()) if any(p.glob("*.ipynb"))]
    stale = [name for name in names if not released_as_is(course, exchange, name)]
    for name in stale:
        shutil.rmtree(course / "source" / name, ignore_errors=True)
        shutil.copytree(REPO_SOURCE / name, course / "source" / name, ignore=SOURCE_IGNORE)
    if stale:
        release(course, stale)
        release_to_exchange(course, exchange, stale)
    return stale


def released_as_is(course: Path, exchange: Path, name: str) -> bool:
    """The course holds the repository's source notebooks of the assignment unchanged, and the
    exchange its release."""
    notebooks = sorted(p.name for p in (REPO_SOURCE / name).glob("*.ipynb"))
    copies = sorted(p.name for p in (course / "source" / name).glob("*.ipynb"))
    return (notebooks == copies
            and all((REPO_SOURCE / name / n).read_bytes() == (course / "source" / name / n).read_bytes()
                    for n in notebooks)
            and all((exchange / config.COURSE_ID / "outbound" / name / n).is_file() for n in notebooks))
