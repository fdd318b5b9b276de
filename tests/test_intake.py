"""A submission that cannot be graded as handed in says why (to the student) and how to fix it
(to the instructor), before anything runs."""

from __future__ import annotations

import shlex

from autograder import intake


def _course(tmp_path, handed: list[str]):
    (tmp_path / "source" / "pubsub").mkdir(parents=True)
    (tmp_path / "source" / "pubsub" / "pubsub.ipynb").write_text("{}")
    folder = tmp_path / "submitted" / "carol" / "pubsub"
    folder.mkdir(parents=True)
    for name in handed:
        (folder / name).write_text("{}")
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
