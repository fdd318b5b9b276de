"""The submissions in COURSE_DIR/submitted/ and the digest that says when one must be graded again."""

from __future__ import annotations

import dataclasses
import hashlib
from pathlib import Path

import autograder
from course_lib.checks import registry


@dataclasses.dataclass
class Submission:
    student: str
    assignment: str
    path: Path

    @property
    def key(self) -> str:
        return f"{self.student}/{self.assignment}"


def find_submissions(course: Path, assignment: str | None = None, student: str | None = None) -> list[Submission]:
    """COURSE_DIR/submitted/<student>/<assignment>/ holding at least one notebook, sorted (only one
    assignment's, one student's, when given)."""
    found = []
    submitted = course / "submitted"
    if not submitted.is_dir():
        return found
    for folder_of_student in sorted(p for p in submitted.iterdir() if p.is_dir()):
        if student is not None and folder_of_student.name != student:
            continue
        for folder in sorted(p for p in folder_of_student.iterdir() if p.is_dir()):
            if (assignment is None or folder.name == assignment) and any(folder.glob("*.ipynb")):
                found.append(Submission(folder_of_student.name, folder.name, folder))
    return found


#: The files nbgrader's submit adds to every submission (its time, the secret its feedback's name
#: derives from): two submissions that differ only in them have the same content.
PER_SUBMISSION_FILES = ("timestamp.txt", "submission_secret.txt")


def _tree_digest(paths: list[Path], digest, skip: tuple = ()) -> None:
    for base in paths:
        # A link is not read (root must not follow a student's link; intake.check refuses it).
        files = [base] if base.is_file() else sorted(p for p in base.rglob("*") if p.is_file() and not p.is_symlink())
        for path in files:
            if path.parent == base and path.name in skip:
                continue
            digest.update(str(path.relative_to(base.parent)).encode() + b"\0" + path.read_bytes() + b"\0")


#: The modules of course_lib.checks that run every assignment's checks (a change regrades).
CHECK_MODULES = ["spec", "registry", "result", "runner", "check_process", "context", "student_calls",
                 "student_processes", "student_server", "probe", "student", "answers", "packages"]


def submission_digest(sub: Submission, course: Path, content_only: bool = False) -> str:
    """Changes when the submission, the assignment's source or the grading code changes.

    `content_only`: the same for two submissions that differ only in nbgrader's per-submission
    files (PER_SUBMISSION_FILES): the same work, handed in again or by another student."""
    digest = hashlib.sha256()
    _tree_digest([sub.path], digest, PER_SUBMISSION_FILES if content_only else ())
    _tree_digest([course / "source" / sub.assignment], digest)
    grader, checks = Path(autograder.__file__).resolve().parent, Path(registry.__file__).resolve().parent
    code = [grader / "sandbox" / "kernel.py", grader / "config.py", grader / "grading" / "hidden_checks_process.py",
            grader / "sandbox" / "student_uid.py", grader / "sandbox" / "run_as.py",
            grader / "builds" / "workspace_build.py",
            grader / "answers" / f"{sub.assignment}.py",
            *(checks / f"{name}.py" for name in CHECK_MODULES), checks / "assignments" / f"{sub.assignment}.py"]
    _tree_digest([path for path in code if path.exists()], digest)
    return digest.hexdigest()

