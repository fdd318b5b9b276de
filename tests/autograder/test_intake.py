"""A submission that cannot be graded as handed in says why (to the student) and how to fix it
(to the instructor), before anything runs."""

from __future__ import annotations

import shlex

import nbformat

from autograder.grading import intake

EMPTY_NOTEBOOK = nbformat.writes(nbformat.v4.new_notebook())


def _course(tmp_path, handed: list[str]):
    (tmp_path / "source" / "pubsub").mkdir(parents=True)
    (tmp_path / "source" / "pubsub" / "pubsub.ipynb").write_text(EMPTY_NOTEBOOK)
    folder = tmp_path / "submitted" / "carol" / "pubsub"
    folder.mkdir(parents=True)
    for name in handed:
        (folder / name).write_text(EMPTY_NOTEBOOK)
    return folder


def test_notebook_renamed_by_the_lms_gets_the_reason_and_the_rename(tmp_path):
    """'pubsub (1).ipynb': the reason names both names; the fix is a working mv and the re-grade."""
    folder = _course(tmp_path, ["pubsub (1).ipynb"])
    problem = intake.check(tmp_path, "carol", "pubsub", folder)
    assert "'pubsub (1).ipynb', not 'pubsub.ipynb'" in problem.reason
    move, regrade = problem.fix.removeprefix("Rename it and grade it again: ").split(" && ")
    assert shlex.split(move) == ["mv", str(folder / "pubsub (1).ipynb"), str(folder / "pubsub.ipynb")]
    assert regrade == f"python -m autograder grade {tmp_path} --student carol --assignment pubsub"


def test_no_notebook_of_the_assignment_among_several(tmp_path):
    """Two other notebooks and not the released one: the reason lists what was found."""
    folder = _course(tmp_path, ["a.ipynb", "b.ipynb"])
    problem = intake.check(tmp_path, "carol", "pubsub", folder)
    assert "no notebook named 'pubsub.ipynb' (found: 'a.ipynb', 'b.ipynb')" in problem.reason


def test_released_name_and_an_extra_notebook_are_fine(tmp_path):
    """The released notebook is there (an extra one is nbgrader's to skip): nothing to report."""
    assert intake.check(tmp_path, "carol", "pubsub", _course(tmp_path, ["pubsub.ipynb", "scratch.ipynb"])) is None


def test_unreadable_timestamp_is_a_problem_for_the_instructor(tmp_path):
    """A timestamp.txt without a date: the student is told it will be graded again, the
    instructor what to write in the file."""
    folder = _course(tmp_path, ["pubsub.ipynb"])
    (folder / "timestamp.txt").write_text("soon")
    problem = intake.check(tmp_path, "carol", "pubsub", folder)
    assert "timestamp.txt holds 'soon'" in problem.fix and "will grade it again" in problem.reason


def test_a_notebook_that_is_not_json_says_where_before_anything_runs(tmp_path):
    """Not JSON: the reason names the line and column, and how to save a notebook again."""
    folder = _course(tmp_path, ["pubsub.ipynb"])
    (folder / "pubsub.ipynb").write_text('{\n  "cells": [\n    oops\n')
    problem = intake.check(tmp_path, "carol", "pubsub", folder)
    assert "'pubsub.ipynb' is not a Jupyter notebook: it is not valid JSON (Expecting value at line 3, column 5)" \
        in problem.reason and "File > Save Notebook" in problem.reason


def test_json_that_is_no_notebook_is_named_so(tmp_path):
    folder = _course(tmp_path, ["pubsub.ipynb"])
    (folder / "pubsub.ipynb").write_text("[1, 2]")
    assert "'pubsub.ipynb' is not a Jupyter notebook: nbformat cannot read it" in \
        intake.check(tmp_path, "carol", "pubsub", folder).reason


def test_a_link_in_a_submitted_folder_is_a_problem_and_is_not_read(tmp_path):
    """A link (here to a file of the instructor's) is refused by name; its target is never read."""
    folder = _course(tmp_path, ["pubsub.ipynb"])
    (tmp_path / "answers.py").write_text("SOLUTION = 42")
    (folder / "notes.txt").symlink_to(tmp_path / "answers.py")
    problem = intake.check(tmp_path, "carol", "pubsub", folder)
    assert "'notes.txt' in your submission is a symbolic link" in problem.reason and "42" not in problem.reason
