"""The reference solutions of the assignments (instructor side).

They are the packages in assignments/reference_ws/src, with the solution between ``### BEGIN
SOLUTION`` / ``### END SOLUTION`` markers; the source notebooks hold them as ``%%writefile
ros2_ws/src/<package>/<file>`` cells (assignments/build.py).
"""

from __future__ import annotations

from pathlib import Path

import nbformat

from course_lib.contract import ASSIGNMENTS_SOURCE as SOURCE
from course_lib.contract import WORKSPACE


def solution_source(text: str) -> str:
    """A solution cell as a student who solved it would hand it in: the markers removed."""
    return "\n".join(line for line in text.split("\n")
                     if "### BEGIN SOLUTION" not in line and "### END SOLUTION" not in line)


def writefile_cells(nb: nbformat.NotebookNode) -> list:
    """The code cells that write the student's package files (%%writefile <path>), in order."""
    return [cell for cell in nb.cells if cell.cell_type == "code" and cell.source.startswith("%%writefile")]


def source_notebook(assignment: str, source: Path = SOURCE) -> nbformat.NotebookNode:
    return nbformat.read(Path(source) / assignment / f"{assignment}.ipynb", as_version=4)


def write_files(nb: nbformat.NotebookNode, folder: Path, edits=()) -> Path:
    """Write the files of a notebook's %%writefile cells (and its !touch lines' empty files) into
    `folder`, as running the cells would (autograder.builds.notebook_writes), with the solution markers
    removed and each (old, new) edit applied to the first file that holds `old`; return folder/ros2_ws."""
    from autograder.builds.notebook_writes import writes_of

    writes = writes_of(solution_source(cell.source) for cell in nb.cells if cell.cell_type == "code")
    files = {name: (data or b"").decode() for name, data in writes.files.items()}
    return _write(files, folder, edits, "the notebook's %%writefile cells")


#: The reference packages (assignments/reference_ws/src/<package>): the only copy of each solution.
REFERENCE_SRC = SOURCE.parent / "reference_ws" / "src"


def package_files(package: str) -> list[tuple[str, str]]:
    """(path beside the notebook, ros2_ws/src/<package>/..., text with its solution markers) of
    each file of a reference package, its tests and caches left out: what its source notebook's
    cells write (assignments/build.py)."""
    folder = REFERENCE_SRC / package
    files = []
    for path in sorted(p for p in folder.rglob("*") if p.is_file()):
        relative = path.relative_to(folder)
        if relative.parts[0] == "test" or "__pycache__" in relative.parts or path.suffix == ".pyc":
            continue
        files.append((f"{WORKSPACE}/src/{package}/{relative.as_posix()}", path.read_text()))
    return files


def reference_files(assignment: str) -> dict[str, str]:
    """{path relative to the notebook's folder (ros2_ws/src/...): text} of an assignment's
    reference packages, solution markers removed, their tests and caches left out."""
    from course_lib.checks.assignments import spec

    return {path: solution_source(text) for package in spec(assignment).packages
            for path, text in package_files(package)}


def write_reference_workspace(assignment: str, folder: Path, edits=()) -> Path:
    """Write the reference packages of an assignment into folder/ros2_ws/src, with each (old, new)
    edit applied to the first file that holds `old`; return folder/ros2_ws."""
    return _write(reference_files(assignment), folder, edits, f"the {assignment} reference packages")


def _write(files: dict[str, str], folder: Path, edits, where: str) -> Path:
    for old, new in edits:
        target = next((name for name, text in files.items() if old in text), None)
        if target is None:
            raise ValueError(f"edit {old!r} is in no file of {where}")
        files[target] = files[target].replace(old, new, 1)
    for name, text in files.items():
        path = Path(folder) / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return Path(folder) / WORKSPACE
