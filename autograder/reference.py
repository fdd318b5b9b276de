"""The reference solutions of the assignments, as the source notebooks hold them (instructor side).

A source notebook's solution cells hold the reference between ``### BEGIN SOLUTION`` / ``### END
SOLUTION`` markers; the cell that starts with ``%%writefile <module>.py`` is the student's module.
"""

from __future__ import annotations

from pathlib import Path

import nbformat

SOURCE = Path(__file__).resolve().parent.parent / "assignments" / "source"


def solution_source(text: str) -> str:
    """A solution cell as a student who solved it would hand it in: the markers removed."""
    return "\n".join(line for line in text.split("\n")
                     if "### BEGIN SOLUTION" not in line and "### END SOLUTION" not in line)


def module_cell(nb: nbformat.NotebookNode) -> nbformat.NotebookNode:
    """The solution cell that writes the student's module (%%writefile)."""
    for cell in nb.cells:
        if cell.cell_type == "code" and cell.source.startswith("%%writefile"):
            return cell
    raise LookupError("no %%writefile cell in the notebook")


def source_notebook(assignment: str, source: Path = SOURCE) -> nbformat.NotebookNode:
    return nbformat.read(Path(source) / assignment / f"{assignment}.ipynb", as_version=4)


def write_module(nb: nbformat.NotebookNode, folder: Path, edits=()) -> Path:
    """Write the module of a notebook's %%writefile cell into `folder`, as running the cell would,
    with the solution markers removed and each (old, new) edit applied; return its path."""
    first, body = solution_source(module_cell(nb).source).split("\n", 1)
    for old, new in edits:
        if old not in body:
            raise ValueError(f"edit {old!r} is not in the module")
        body = body.replace(old, new, 1)
    path = Path(folder) / first.split()[1]
    path.write_text(body)
    return path


def write_reference_module(assignment: str, folder: Path, edits=()) -> Path:
    """Write the reference solution's module of an assignment into `folder`; return its path."""
    return write_module(source_notebook(assignment), folder, edits)


#: The reference packages (assignments/reference_ws/src/<package>): the only copy of each solution.
REFERENCE_SRC = SOURCE.parent / "reference_ws" / "src"


def reference_files(assignment: str) -> dict[str, str]:
    """{path relative to the notebook's folder (ros2_ws/src/...): text} of an assignment's
    reference packages, solution markers removed, their tests and caches left out."""
    from course_lib.checks import packages

    files = {}
    for package in packages.PACKAGES[assignment]:
        folder = REFERENCE_SRC / package
        for path in sorted(p for p in folder.rglob("*") if p.is_file()):
            relative = path.relative_to(folder)
            if relative.parts[0] in ("test", "__pycache__") or path.suffix == ".pyc" or "__pycache__" in relative.parts:
                continue
            files[f"{packages.WORKSPACE}/src/{package}/{relative.as_posix()}"] = solution_source(path.read_text())
    return files


def write_reference_workspace(assignment: str, folder: Path, edits=()) -> Path:
    """Write the reference packages of an assignment into folder/ros2_ws/src, with each (old, new)
    edit applied to the first file that holds `old`; return folder/ros2_ws."""
    files = reference_files(assignment)
    for old, new in edits:
        target = next((name for name, text in files.items() if old in text), None)
        if target is None:
            raise ValueError(f"edit {old!r} is in no file of the {assignment} reference packages")
        files[target] = files[target].replace(old, new, 1)
    for name, text in files.items():
        path = Path(folder) / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return Path(folder) / "ros2_ws"
