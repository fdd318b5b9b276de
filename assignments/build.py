"""Writes the nbgrader source notebooks of the graded assignments: ``python assignments/build.py``.

The notebooks under assignments/source/ are what instructors edit in JupyterLab; this script is
how they are made, from each assignment's file (course_lib/checks/assignments/<name>.py: its spec with its
packages, the module of its plain functions, its questions, the words of its notebook; its checks) and its
reference packages, and how a test checks that their graded cells match the checks (points of each test
cell = points of its check). It also writes the table of contracts in assignments/README.md from the specs.

The solutions are the reference packages in assignments/reference_ws/src (the only copy): each
file of an assignment's packages becomes a ``%%writefile ros2_ws/src/<package>/<file>`` cell. A
file with ``### BEGIN SOLUTION`` / ``### END SOLUTION`` regions (inside function bodies, so that
nbgrader's stub ``raise NotImplementedError`` keeps the module importable) is a solution cell.
"""

from __future__ import annotations

import sys
from pathlib import Path, PurePosixPath

import nbformat

from course_lib.checks import assignments as specs
from course_lib.checks.spec import Assignment
from course_lib.contract import ASSIGNMENTS_SOURCE as SOURCE
from course_lib.contract import ROOT, WORKSPACE

README = SOURCE.parent / "README.md"
#: The lines around the generated table of assignments/README.md.
TABLE_START = "<!-- the contracts' table: written by python assignments/build.py from the specs -->"
TABLE_END = "<!-- end of the table -->"


def _meta(kind: str, grade_id: str, points: float = 0) -> dict:
    base = {"schema_version": 3, "grade_id": grade_id, "task": False}
    if kind == "solution":
        base.update(grade=False, solution=True, locked=False)
    elif kind == "test":
        base.update(grade=True, solution=False, locked=True, points=points)
    elif kind == "locked":
        base.update(grade=False, solution=False, locked=True)
    return {"nbgrader": base}


def md(text: str, grade_id: str | None = None):
    """A markdown cell; only the introduction (grade_id "intro") is locked.

    nbgrader 0.9's add_missing_cells puts a deleted test cell back after the source cell before
    it, and fails (KeyError) unless that cell is a solution or test cell. So no locked cell may
    sit directly before a test cell, counting only cells with nbgrader metadata.
    """
    cell = nbformat.v4.new_markdown_cell(text.strip())
    if grade_id == "intro":
        cell.metadata.update(_meta("locked", grade_id))
    return cell


def code(text: str, kind: str | None = None, grade_id: str | None = None, points: float = 0):
    cell = nbformat.v4.new_code_cell(text.strip())
    if kind:
        cell.metadata.update(_meta(kind, grade_id, points))
    return cell


def test_cell(assignment: str, name: str):
    """The graded cell of one check: the self-check, then the hidden graded run with a fresh seed."""
    from course_lib.checks import registry

    spec = registry.get_check(assignment, name)
    source = (f"# {spec.description} ({spec.points:g} points)\n"
              f"checks.selfcheck({name!r})\n"
              "### BEGIN HIDDEN TESTS\n"
              f"checks.grade({name!r})\n"
              "### END HIDDEN TESTS")
    return code(source, "test", f"check_{name}", spec.points)


def setup_cell(assignment: str, extra: str = "", packages: bool = True):
    """The first cell: this assignment's checks and, where it has packages, the course helpers its
    cells use (a quiz needs no more than its checks)."""
    if not packages:
        return code(f"""
# Run this cell first. It imports this assignment's checks.
from course_lib.checks import {assignment} as checks
{extra}""", "locked", "setup")
    return code(f"""
# Run this cell first. It imports the course helpers and this assignment's checks.
import importlib
import sys

import numpy as np

from course_lib import images, rosenv
from course_lib.checks import {assignment} as checks
{extra}""", "locked", "setup")


def import_cell(package: str, module: str, names: str):
    """Imports the student's module from its package's source (no build needed for plain functions)."""
    folder = f"{WORKSPACE}/src/{package}"
    return code(f"""
# Imports (or re-imports, after you edit and re-run the cells above) your module from its package.
if {folder!r} not in sys.path:
    sys.path.insert(0, {folder!r})
import {module}
importlib.reload({module})
from {module} import {names}
""")  # not locked: see md()


def package_cells(packages: list[str], plain_ros: str) -> list:
    """The cells that write the packages: the folders, then one %%writefile cell per file (a
    solution cell when the file has solution regions), then the build."""
    from autograder.builds.reference import package_files  # build() puts the repository on the path

    files = [item for package in packages for item in package_files(package)]
    folders = sorted({str(PurePosixPath(path).parent) for path, _ in files})
    empty = [path for path, text in files if not text]  # %%writefile refuses an empty cell
    cells = [md(f"""
## Your packages

Each cell below writes one file of your workspace `{WORKSPACE}/src/`: run them all after every change
(or edit the files in JupyterLab's file browser and copy your changes back here: the notebook is what
you hand in, and grading runs it). {plain_ros}
"""),
             code("# The package folders and empty files (in a terminal: the same commands).\n"
                  f"!mkdir -p {' '.join(folders)}\n!touch {' '.join(empty)}")]
    for path, text in files:
        if not text:
            continue
        source = f"%%writefile {path}\n{text}"
        if "### BEGIN SOLUTION" in text:
            cells.append(code(source, "solution", PurePosixPath(path).stem))
        else:
            cells.append(code(source))
    cells.append(md("""
### Build

The next cell builds the workspace, as `cd ros2_ws && colcon build --symlink-install` does in a
terminal (on the course's pip install `python -m course_lib build` also sets what the wheels need
for message packages). Build again after changing `setup.py`, `package.xml` or a `.msg` file; with
`--symlink-install` a change of a Python file needs no new build. At grading the grader builds your
workspace itself, in its sandbox, and this cell does nothing.
"""))
    cells.append(code(f"""
if not rosenv.under_grading():
    !python -m course_lib build {WORKSPACE} --symlink-install
"""))
    return cells


def question_cells(assignment: str, questions: dict) -> list:
    """A markdown cell per multiple-choice question and a solution cell the student answers it in:
    its right letter from the grader's answer key (autograder/answers/<assignment>.py, KEY) between
    the solution markers, which the release replaces by nbgrader's stub."""
    import importlib

    if not questions:
        return []
    key = importlib.import_module(f"autograder.answers.{assignment}").KEY  # build() puts the repository on the path
    cells = []
    for name, question in questions.items():
        cells += [md(question.markdown(name)),
                  code(f"# {name}: one of {question.letters()}\n### BEGIN SOLUTION\n{name} = \"{key[name][0]}\"\n"
                       "### END SOLUTION", "solution", name)]
    return cells


def notebook(cells) -> nbformat.NotebookNode:
    nb = nbformat.v4.new_notebook()
    for index, cell in enumerate(cells):  # stable ids: rebuilding gives the same file
        cell.id = cell.metadata.get("nbgrader", {}).get("grade_id") or f"cell-{index}"
    nb.cells = cells
    nb.metadata["kernelspec"] = {"display_name": "Python 3 (ipykernel)", "language": "python", "name": "python3"}
    nb.metadata["language_info"] = {"name": "python"}
    return nb


def assignment_notebook(spec: Assignment) -> nbformat.NotebookNode:
    """An assignment's source notebook: its own words (spec.notebook) around what its spec and its
    checks say: the setup, its packages' files, the import of its plain functions, its questions,
    a test cell per check."""
    from course_lib.checks import registry

    text = spec.notebook
    cells = [md(text.intro, "intro"), setup_cell(spec.name, text.imports, bool(spec.packages))]
    if spec.packages:
        cells += package_cells(list(spec.packages), text.plain_ros)
    cells += question_cells(spec.name, spec.questions)
    if spec.functions is not None:
        cells += [import_cell(*spec.functions, text.names), md(text.try_text), code(text.try_code)]
    for number, name in enumerate(registry.checks_of(spec.name), 1):
        heading, *more = text.checks[name]
        cells += [md("\n\n".join([f"## Check {number}: {heading}", *more]), f"check_{name}_md"),
                  test_cell(spec.name, name)]
    return notebook(cells)


def contract_table(assignments: dict[str, Assignment]) -> str:
    """The table of assignments/README.md: each assignment's lesson, points, packages and checks, from its spec."""
    from course_lib.checks import registry

    rows = ["| assignment | after lesson | points | packages (executables) | checks (points) |",
            "|---|---|---|---|---|"]
    for spec in assignments.values():
        checks = registry.checks_of(spec.name).values()
        packages = ", ".join(f"`{package}`" + (" (" + ", ".join(f"`{e}`" for e in executables) + ")" if executables
                                               else "") for package, executables in spec.packages.items())
        rows.append(f"| `{spec.name}` | {spec.lesson} | {sum(check.points for check in checks):g} | "
                    f"{packages or 'none'} | {', '.join(f'`{check.name}` {check.points:g}' for check in checks)} |")
    return "\n".join([TABLE_START, *rows, TABLE_END])


def readme_with_table(text: str, assignments: dict[str, Assignment]) -> str:
    """assignments/README.md's text with its table of contracts written from the specs."""
    before, rest = text.split(TABLE_START, 1)
    return before + contract_table(assignments) + rest.split(TABLE_END, 1)[1]


def build(names=None) -> list[Path]:
    """Write the source notebooks (all, or the given assignments) and return their paths."""
    sys.path.insert(0, str(ROOT))
    written = []
    for name in names or specs.ASSIGNMENTS:
        path = SOURCE / name / f"{name}.ipynb"
        path.parent.mkdir(parents=True, exist_ok=True)
        nbformat.write(assignment_notebook(specs.spec(name)), path)
        written.append(path)
    return written


def write_readme() -> Path:
    """Write the table of contracts in assignments/README.md from the specs (a test compares them)."""
    README.write_text(readme_with_table(README.read_text(), specs.ASSIGNMENTS))
    return README


if __name__ == "__main__":
    for path in build(sys.argv[1:] or None):
        print(path)
    if len(sys.argv) == 1:
        print(write_readme())
