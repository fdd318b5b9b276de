"""What a submission's grading leaves in the course: the autograded notebooks and the grader's log."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

from autograder.results.store import state_dir
from autograder.results.submissions import Submission
from autograder.sandbox import kernel

REPO = Path(__file__).resolve().parents[2]


def keep_autograded(course: Path, sub: Submission, autograded: Path | None) -> None:
    """Replace COURSE_DIR/autograded/<student>/<assignment>/ by the graded copy (None: an empty
    folder, so that the formgrader lists the submission as autograded, with its score 0)."""
    target = course / "autograded" / sub.student / sub.assignment
    if target.exists():
        shutil.rmtree(target)
    if autograded is not None and autograded.is_dir():
        shutil.copytree(autograded, target, symlinks=True,
                        ignore=shutil.ignore_patterns("__pycache__", ".autograder-*"))
    else:
        target.mkdir(parents=True, exist_ok=True)


def keep_log(course: Path, sub: Submission, log: str) -> None:
    folder = state_dir(course, sub.student, sub.assignment)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "autograder.log").write_text(log[-200000:])


def scrub_paths(folder: Path, work: Path) -> None:
    """Remove the grader's folders from the notebooks in `folder`: a traceback of the student's
    module names it as pubsub_nodes.py, not /tmp/autograder-work-.../.autograder-cwd/pubsub_nodes.py,
    and the grader's own files by their place in the repository (autograder/student.py)."""
    prefixes = [f"{folder / kernel.WORK_SUBDIR}{os.sep}", f"{folder}{os.sep}", f"{REPO}{os.sep}"]
    for path in sorted(folder.glob("*.ipynb")):
        text = original = path.read_text()
        for prefix in prefixes:
            text = text.replace(prefix, "")
        text = text.replace(str(work), "<grader's work folder>")
        if text != original:
            path.write_text(text)

