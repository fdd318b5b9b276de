"""The instructor's steps on the hub, one command each (``python -m coursehub STEP ASSIGNMENT``,
run by root on the server; the formgrader's buttons do release and collect too):

- release: ``python -m autograder release`` (nbgrader generate_assignment) and ``nbgrader
  release_assignment``, as the instructor: the assignment appears in the students' Assignments panel;
- collect: ``nbgrader collect``, as the instructor: the exchange's submissions into submitted/;
- grade: ``python -m autograder grade``, as root (its sandbox needs root: per-submission uids,
  namespaces), then the course directory is given back to the instructor;
- feedback: ``python -m autograder feedback`` and ``nbgrader release_feedback``, as the instructor:
  students press "Fetch Feedback".
"""

from __future__ import annotations

import os
import subprocess
import sys

from coursehub import sandbox
from coursehub.accounts import chown_tree


def _as_instructor(course, *commands: list[str]) -> str:
    output = []
    env = sandbox.user_environment(course, course.instructor, os.environ)
    for command in commands:
        done = subprocess.run(sandbox.as_user(course, course.instructor, command), cwd=course.course_dir, env=env,
                              capture_output=True, text=True)
        output.append(done.stdout + done.stderr)
        if done.returncode != 0:
            raise RuntimeError(f"{' '.join(command)} failed as {course.instructor} (exit code {done.returncode}):\n"
                               + "".join(output)[-3000:])
    return "".join(output)


def _autograder(*args: str) -> list[str]:
    return [sys.executable, "-m", "autograder", *args]


def _nbgrader(*args: str) -> list[str]:
    return [sys.executable, "-m", "nbgrader", *args]


def release(course, assignment: str, duedate: str | None = None) -> str:
    extra = ["--duedate", duedate] if duedate else []
    return _as_instructor(course, _autograder("release", str(course.course_dir), "--assignment", assignment, *extra),
                          _nbgrader("release_assignment", assignment, "--force"))


def collect(course, assignment: str) -> str:
    return _as_instructor(course, _nbgrader("collect", assignment, "--update"))


def grade(course, assignment: str, workers: int = 2, student: str | None = None, force: bool = False) -> str:
    command = _autograder("grade", str(course.course_dir), "--assignment", assignment, "--workers", str(workers))
    if student:
        command += ["--student", student]
    if force:
        command += ["--force"]
    done = subprocess.run(command, cwd=sandbox.REPO, capture_output=True, text=True,
                          env=dict(os.environ, PYTHONPATH=str(sandbox.REPO)))
    chown_tree(course.course_dir, course.instructor)  # the formgrader (the instructor's) writes the gradebook
    if done.returncode != 0:
        raise RuntimeError(f"python -m autograder grade failed (exit code {done.returncode}):\n"
                           f"{(done.stdout + done.stderr)[-3000:]}")
    return done.stdout + done.stderr


def feedback(course, assignment: str) -> str:
    return _as_instructor(course, _autograder("feedback", str(course.course_dir), "--assignment", assignment),
                          _nbgrader("release_feedback", assignment))
