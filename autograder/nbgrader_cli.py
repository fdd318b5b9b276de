"""The nbgrader command line, run on a course directory with this repository importable."""

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

