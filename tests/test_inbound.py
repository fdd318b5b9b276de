"""The exchange's inbound/ as the grading service reads it (coursehub.inbound): a folder nbgrader's
submit is still writing is not taken, a finished one is, oldest first, and its copy in submitted/
holds what nbgrader's collect would copy."""

from __future__ import annotations

import os

from coursehub import inbound


def _submission(folder, name, done=True):
    path = folder / name
    path.mkdir(parents=True)
    (path / "brightness.ipynb").write_text("{}")
    (path / ".ipynb_checkpoints").mkdir()
    if done:
        (path / "timestamp.txt").write_text(name.split("+")[2])
        (path / "submission_secret.txt").write_text("secret")
        os.chmod(path, 0o777)  # nbgrader's last step
    else:
        os.chmod(path, 0o755)
    return path


def test_only_finished_submissions_are_taken_oldest_first(tmp_path):
    folder = tmp_path / "inbound"
    _submission(folder, "bob+brightness+2026-03-01 12:05:00.000000 UTC+abc")
    _submission(folder, "ann+brightness+2026-03-01 12:01:00.000000 UTC+def")
    _submission(folder, "cy+brightness+2026-03-01 12:00:00.000000 UTC+ghi", done=False)
    (folder / "not-a-submission").mkdir()
    found = inbound.new_entries(folder, known=set())
    assert [(e.student, e.submitted.minute) for e in found] == [("ann", 1), ("bob", 5)]
    assert inbound.new_entries(folder, known={e.name for e in found}) == []
    assert inbound.new_entries(tmp_path / "not-released-yet", set()) == []


def test_a_collected_submission_replaces_the_students_earlier_one(tmp_path):
    entry = inbound.parse(_submission(tmp_path / "inbound", "bob+brightness+2026-03-01 12:05:00.000000 UTC+abc"))
    course = tmp_path / "course"
    (course / "submitted" / "bob" / "brightness").mkdir(parents=True)
    (course / "submitted" / "bob" / "brightness" / "old.py").write_text("")
    target = inbound.collect(entry, course)
    assert sorted(p.name for p in target.iterdir()) == ["brightness.ipynb", "submission_secret.txt", "timestamp.txt"]
