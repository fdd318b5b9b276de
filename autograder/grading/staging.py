"""Private copies for a submission's grading: the grader itself and the submitted files."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import autograder


def stage_grader(work: Path) -> Path:
    """Copy the autograder package into `work`/grader, readable by root only, and return that
    folder (first on the sandbox's PYTHONPATH). The sandbox hides the repository's autograder/;
    the grader's own processes (nbgrader's config, the kernel launcher, the checks' answer keys)
    import this copy, while the student's uid cannot enter it."""
    folder = work / "grader"
    shutil.copytree(Path(autograder.__file__).resolve().parent, folder / "autograder",
                    ignore=shutil.ignore_patterns("__pycache__"))
    os.chmod(folder, 0o700)
    return folder


def private_copy(source: Path, target: Path) -> None:
    """Copy a submission's folder readable by root only (other workers' uids cannot read it),
    following no link out of it (autograder.sandbox.untrusted; intake.check refused such a folder before)."""
    from autograder.sandbox import untrusted
    from course_lib.checks.validate import IGNORE

    untrusted.copy_tree(source, target, ignore=IGNORE)
    for directory, _dirs, files in os.walk(target):
        os.chmod(directory, 0o711)
        for name in files:
            os.chmod(os.path.join(directory, name), 0o600)

