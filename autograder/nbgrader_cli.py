"""nbgrader on a course directory: its command line, run with this repository importable, and its
converters run in this process (``generate_assignment``, ``generate_feedback``) as its formgrader
runs them, which spares a Python start and a second ``import nbgrader`` (1.5-3 s of processor time)
per call."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from autograder import gradebook

REPO = Path(__file__).resolve().parent.parent


def env_for_tools() -> dict:
    env = dict(os.environ)
    path = [str(REPO)] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p and p != str(REPO)]
    env["PYTHONPATH"] = os.pathsep.join(path)
    env["PATH"] = gradebook.with_this_python(env.get("PATH", ""))
    return env


def run_nbgrader(args: list[str], course: Path, timeout: float = 300) -> str:
    """Run the nbgrader CLI on a course directory; raise RuntimeError with its output on failure."""
    command = [sys.executable, "-m", "nbgrader", *args, f"--CourseDirectory.root={course}"]
    done = subprocess.run(command, cwd=course, env=env_for_tools(), capture_output=True, text=True,
                          timeout=timeout)
    if done.returncode != 0:
        raise RuntimeError(f"nbgrader {' '.join(args)} failed (exit code {done.returncode}):\n"
                           f"{(done.stdout + done.stderr)[-3000:]}")
    return done.stdout + done.stderr


def converter_for(converter_class, course: Path, assignment: str, student: str | None = None, settings=None):
    """An nbgrader converter (GenerateAssignment, GenerateFeedback, ...) for one assignment of the
    course (and one student's submission, if given), with the course's configuration or `settings`."""
    from nbgrader.coursedir import CourseDirectory

    from autograder import config

    settings = config.load(course) if settings is None else settings
    coursedir = CourseDirectory(config=settings, root=str(course))
    coursedir.assignment_id = assignment
    if student:
        coursedir.student_id = student
    return converter_class(coursedir=coursedir, config=settings)


def _run_converter(converter_class, course: Path, assignment: str, student: str | None = None) -> str:
    """Run a converter as its command does with --force; its log; RuntimeError with the log on failure."""
    from nbgrader.utils import capture_log

    converter = converter_for(converter_class, course, assignment, student)
    converter.force = True
    outcome = capture_log(converter)
    log = outcome.get("log", "")
    if not outcome["success"]:
        raise RuntimeError(f"nbgrader {converter_class.__name__} of {assignment} failed:\n"
                           f"{(log + outcome.get('error', ''))[-3000:]}")
    return log


def generate_assignment(course: Path, assignment: str) -> str:
    """``nbgrader generate_assignment ASSIGNMENT --force``: the student version in release/, and the
    assignment, its cells and hidden tests in the gradebook."""
    from nbgrader.converters import GenerateAssignment

    return _run_converter(GenerateAssignment, Path(course), assignment)


def generate_feedback(course: Path, assignment: str, student: str | None = None) -> str:
    """``nbgrader generate_feedback ASSIGNMENT --force [--student STUDENT]``: the feedback pages of
    the autograded submissions."""
    from nbgrader.converters import GenerateFeedback

    return _run_converter(GenerateFeedback, Path(course), assignment, student)
