"""Graded feedback for a student alone (autograder/term/lab_grading.py, ``python -m autograder grade-lab``):
the quiz is released into a lab's own exchange as `make lab` releases it, fetched, answered (one
answer wrong) and submitted with the real nbgrader CLI under the lab's nbgrader_config.py; grade-lab
grades the submission with the course's grader and releases its feedback, and nbgrader's
fetch_feedback (what the panel's Fetch Feedback button runs) brings the graded page with the score
and the wrong answer's reason. (The quiz: no ROS, no build, the cheapest assignment to grade.)"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import nbformat
import pytest
from support.zoo.quiz import answered

from autograder import __main__ as cli
from autograder import nbgrader_cli
from autograder.answers import quiz as key
from autograder.term import lab_grading, release
from course_lib import contract

ROOT = contract.ROOT
WRONG = ("q3", "b")


def nbgrader(lab_root: Path, *args: str) -> str:
    """The real nbgrader CLI as the student runs it in the lab (its nbgrader_config.py)."""
    done = subprocess.run([sys.executable, "-m", "nbgrader", *args], cwd=lab_root, env=nbgrader_cli.env_for_tools(),
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout + done.stderr


@pytest.fixture
def lab_root(tmp_path):
    """A lab as `make lab` serves it: the repository's nbgrader_config.py (the lab's exchange under
    the root) and a cache of its own for nbgrader's records of the student's submissions."""
    (tmp_path / "nbgrader_config.py").write_text((ROOT / "nbgrader_config.py").read_text()
                                                 + f"\nc.Exchange.cache = {str(tmp_path / 'cache')!r}\n")
    return tmp_path


def test_nothing_submitted_says_to_submit_first(lab_root, capsys):
    assert lab_grading.grade_lab(lab_root) == []
    assert cli.main(["grade-lab", str(lab_root)]) == 0
    assert "Nothing submitted yet" in capsys.readouterr().out


@pytest.mark.slow
def test_a_submitted_quiz_is_graded_and_its_feedback_fetched(lab_root, capsys):
    assert release.release_for_lab(lab_root, ["quiz"]) == ["quiz"]
    nbgrader(lab_root, "fetch_assignment", "quiz")
    path = lab_root / "quiz" / "quiz.ipynb"
    nb = nbformat.read(path, as_version=4)
    answered({**{name: entry.answer for name, entry in key.KEY.items()}, WRONG[0]: WRONG[1]})(nb)
    nbformat.write(nb, path)
    nbgrader(lab_root, "submit", "quiz")

    assert cli.main(["grade-lab", str(lab_root), "--assignment", "quiz"]) == 0
    said = capsys.readouterr().out
    assert "quiz: 15 / 16; press Fetch Feedback" in said, said

    nbgrader(lab_root, "fetch_feedback", "quiz")
    (page,) = (lab_root / "quiz" / "feedback").glob("*/quiz.html")
    text = page.read_text()
    assert f"{WRONG[0]}: not {WRONG[1]}. {key.explain(*WRONG)}" in text
    assert "q1: c is right" in text and "Score: 15.0 / 16.0" in text
