"""Is a handed-in submission gradable as it is? Checked before it is graded, with reasons that say
what is wrong and how to fix it (not "nbgrader could not grade the notebook (exit code 1)").

- Notebook names: nbgrader grades a notebook only under the name it was released with. LMS
  downloads rename files that were uploaded twice (``pubsub (1).ipynb``, ``pubsub-1.ipynb``).
- The submission time: ``timestamp.txt`` (written by ``nbgrader zip_collect``) must hold a date.
- The files: plain files and folders only, within the size and count limits (autograder.sandbox.untrusted),
  and each released notebook a Jupyter notebook (JSON), so that a broken one is told in seconds,
  before any build or kernel.
"""

from __future__ import annotations

import dataclasses
import shlex
from pathlib import Path


@dataclasses.dataclass
class Problem:
    """Why a submission cannot be graded: `reason` for the student, `fix` for the instructor."""

    reason: str
    fix: str


def released_notebooks(course: Path, assignment: str) -> list[str]:
    """The notebook file names of an assignment, as released (COURSE_DIR/source/<assignment>/)."""
    return sorted(p.name for p in (Path(course) / "source" / assignment).glob("*.ipynb"))


def notebook_names(course: Path, student: str, assignment: str, folder: Path) -> Problem | None:
    """A Problem when a released notebook is missing from `folder` (e.g. handed in under another name)."""
    expected = released_notebooks(course, assignment)
    handed = sorted(p.name for p in Path(folder).glob("*.ipynb"))
    missing = [name for name in expected if name not in handed]
    if not expected or not missing:
        return None
    others = [name for name in handed if name not in expected]
    regrade = f"python -m autograder grade {course} --student {student} --assignment {assignment}"
    if len(missing) == 1 and len(others) == 1:
        old, new = Path(folder) / others[0], Path(folder) / missing[0]
        return Problem(
            reason=(f"The notebook you handed in is named '{others[0]}', not '{missing[0]}' as it was released, "
                    "so it could not be graded. Keep the released name when you hand in (an LMS adds "
                    "' (1)' or '-1' to a file uploaded twice)."),
            fix=f"Rename it and grade it again: mv {shlex.quote(str(old))} {shlex.quote(str(new))} && {regrade}")
    found = ", ".join(f"'{name}'" for name in others) or "no other notebook"
    return Problem(
        reason=(f"The submission has no notebook named {', '.join(repr(m) for m in missing)} (found: {found}), "
                "so it could not be graded. Hand in the released notebook under its released name."),
        fix=f"Put the student's notebook in {folder} as {', '.join(missing)}, then: {regrade}")


def timestamp(folder: Path) -> Problem | None:
    """A Problem when folder/timestamp.txt exists but holds no date."""
    from autograder.results import gradebook

    try:
        gradebook.submitted_timestamp(folder)
    except ValueError as error:
        return Problem(reason="The submission time of this submission could not be read; your instructor will "
                              "grade it again.", fix=str(error))
    return None


def files(folder: Path) -> Problem | None:
    """A Problem when the folder holds anything but plain files and folders, or too much
    (autograder.sandbox.untrusted: nothing is followed out of it)."""
    from autograder.sandbox import untrusted
    from course_lib.checks.validate import IGNORE

    try:
        untrusted.copy_tree(folder, None, ignore=IGNORE)
    except untrusted.Refused as refusal:
        return Problem(reason=str(refusal), fix=f"Look at {folder}: {refusal}")
    return None


def notebooks(course: Path, assignment: str, folder: Path) -> Problem | None:
    """A Problem when a released notebook in `folder` is not a Jupyter notebook (JSON nbformat 4)."""
    import json

    import nbformat

    for name in released_notebooks(course, assignment):
        path = Path(folder) / name
        try:
            text = path.read_text(encoding="utf-8")
            json.loads(text)  # nbformat's own error hides where the JSON breaks
            nbformat.reads(text, as_version=4)
        except UnicodeDecodeError as error:
            problem = f"it is not text (byte {error.start} is not UTF-8)"
        except json.JSONDecodeError as error:
            problem = f"it is not valid JSON ({error.msg} at line {error.lineno}, column {error.colno})"
        except Exception as error:  # noqa: BLE001 - nbformat's own complaints, whatever their class
            said = str(error).strip().splitlines()
            problem = f"nbformat cannot read it ({said[0][:200] if said else type(error).__name__})"
        else:
            continue
        return Problem(reason=(f"'{name}' is not a Jupyter notebook: {problem}, so it could not be graded. Open "
                               "the released notebook in JupyterLab, save it there (File > Save Notebook) and "
                               "submit again."), fix=f"Look at {path}")
    return None


def check(course: Path, student: str, assignment: str, folder: Path) -> Problem | None:
    """The first problem that keeps a submission from being graded, or None."""
    return (files(folder) or notebook_names(course, student, assignment, folder)
            or notebooks(course, assignment, folder) or timestamp(folder))
