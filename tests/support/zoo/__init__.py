"""The zoo: submissions made from the reference solution by replacing pieces of it.

``submit(course, student, assignment, edits)`` takes the released notebook, puts the reference
solution (from the source notebook, solution markers removed) into its solution cells, applies
``edits`` (old text -> new text in the student's module cell, or whole-notebook functions) and
writes it to COURSE_DIR/submitted/<student>/<assignment>/<assignment>.ipynb, as nbgrader's
collect step would.
"""

from __future__ import annotations

from pathlib import Path

import nbformat

from autograder.builds.reference import solution_source, writefile_cells


def filled_notebook(course: Path, assignment: str) -> nbformat.NotebookNode:
    """The released notebook with the reference solution in its solution cells."""
    release = nbformat.read(course / "release" / assignment / f"{assignment}.ipynb", as_version=4)
    source = nbformat.read(course / "source" / assignment / f"{assignment}.ipynb", as_version=4)
    solutions = {c.metadata["nbgrader"]["grade_id"]: c.source for c in source.cells
                 if c.metadata.get("nbgrader", {}).get("solution")}
    for cell in release.cells:
        meta = cell.metadata.get("nbgrader", {})
        if meta.get("solution"):
            cell.source = solution_source(solutions[meta["grade_id"]])
    return release


def edited_notebook(course: Path, assignment: str, edits=(), student: str = "") -> nbformat.NotebookNode:
    """The filled notebook with `edits`: each (old, new) applied to the first %%writefile cell (a
    file of the student's packages) that holds `old`, or a function nb -> None."""
    nb = filled_notebook(course, assignment)
    for edit in edits:
        if callable(edit):
            edit(nb)
            continue
        old, new = edit
        cell = next((c for c in writefile_cells(nb) if old in c.source), None)
        if cell is None:
            raise ValueError(f"zoo edit for {student}: {old!r} is in no file of the reference packages")
        cell.source = cell.source.replace(old, new, 1)
    return nb


def submit(course: Path, student: str, assignment: str, edits=()) -> Path:
    """Write a zoo submission (see edited_notebook) where nbgrader's collect step puts it: the
    notebook, and the workspace its %%writefile cells wrote, as a student who ran them hands it in."""
    from autograder.builds.reference import write_files

    nb = edited_notebook(course, assignment, edits, student)
    target = Path(course) / "submitted" / student / assignment / f"{assignment}.ipynb"
    target.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(nb, target)
    write_files(nb, target.parent)
    return target


def graded_outputs(course: Path, student: str, assignment: str) -> str:
    """The text the autograded notebook shows: every cell's output, tracebacks and the grader's verdicts."""
    nb = nbformat.read(Path(course) / "autograded" / student / assignment / f"{assignment}.ipynb", as_version=4)
    texts = []
    for cell in nb.cells:
        for output in cell.get("outputs", []):
            texts.append(output.get("text", "") or str(output.get("data", {}).get("text/plain", "")))
            texts.extend(output.get("traceback", []))
    return "\n".join(texts)
