"""The exchange's inbound/ as the grading service reads it (coursehub.inbound): a folder nbgrader's
submit is still writing is not taken, a finished one is, oldest first, and counts for the student
whose account owns it; every other entry is refused with a reason for the student who made it, and
is never followed; a collected submission holds what nbgrader's collect would copy."""

from __future__ import annotations

import os

import pytest

from coursehub import inbound

ME = os.geteuid()
#: The roster as the service passes it: user names and their uids.
STUDENTS = {"ann": ME, "bob": ME, "cy": ME}


def _submission(folder, name, done=True):
    path = folder / name
    path.mkdir(parents=True)
    (path / "brightness.ipynb").write_text("{}")
    (path / ".ipynb_checkpoints").mkdir()
    if done:
        (path / "timestamp.txt").write_text("2026-03-01 12:00:00.000000 UTC")
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
    found = inbound.new_entries(folder, set(), STUDENTS)
    assert [(e.student, e.submitted.minute, e.refused) for e in found] == [("ann", 1, None), ("bob", 5, None)]
    assert inbound.new_entries(folder, {e.name for e in found}, STUDENTS) == []
    assert inbound.new_entries(tmp_path / "not-released-yet", set(), STUDENTS) == []


@pytest.mark.parametrize("name, reason", [
    ("not-a-submission", "is not named as nbgrader's Submit names a submission"),
    ("ann+brightness", "is not named as nbgrader's Submit names a submission"),
    ("ann+brightness+not a time+abc", "is not named as nbgrader's Submit names a submission"),
    ("..+brightness+2026-03-01 12:00:00.000000 UTC+abc", "names '..', who is not a student of this course"),
    ("nobody+brightness+2026-03-01 12:00:00.000000 UTC+abc", "names 'nobody', who is not a student"),
    ("ann\n+brightness+2026-03-01 12:00:00.000000 UTC+abc", "names 'ann\\n', who is not a student"),
])
def test_an_entry_not_named_for_a_roster_student_is_refused_with_its_reason(tmp_path, name, reason):
    _submission(tmp_path / "inbound", name)
    [entry] = inbound.new_entries(tmp_path / "inbound", set(), STUDENTS)
    assert reason in entry.refused


def test_a_link_in_inbound_is_refused_not_followed(tmp_path):
    elsewhere = _submission(tmp_path, "ann+brightness+2026-03-01 12:00:00.000000 UTC+abc")
    (tmp_path / "inbound").mkdir()
    (tmp_path / "inbound" / elsewhere.name).symlink_to(elsewhere)
    [entry] = inbound.new_entries(tmp_path / "inbound", set(), STUDENTS)
    assert "is not a folder (a link or a file)" in entry.refused


def test_a_folder_in_another_students_name_counts_for_its_owner_and_is_refused(tmp_path):
    _submission(tmp_path / "inbound", "ann+brightness+2026-03-01 12:00:00.000000 UTC+abc")
    [entry] = inbound.new_entries(tmp_path / "inbound", set(), {"ann": ME + 1, "bob": ME})
    assert (entry.student, entry.assignment) == ("bob", "brightness")
    assert "names 'ann' but was made by another account" in entry.refused


def test_a_collected_submission_replaces_the_students_earlier_one(tmp_path):
    entry = _submission(tmp_path / "inbound", "bob+brightness+2026-03-01 12:05:00.000000 UTC+abc")
    course = tmp_path / "course"
    (course / "submitted" / "bob" / "brightness").mkdir(parents=True)
    (course / "submitted" / "bob" / "brightness" / "old.py").write_text("")
    target = inbound.collect(entry, "bob", "brightness", ME, course)
    assert sorted(p.name for p in target.iterdir()) == ["brightness.ipynb", "submission_secret.txt", "timestamp.txt"]
    assert sorted(p.name for p in target.parent.iterdir()) == ["brightness"]


def test_a_refused_entry_is_set_aside_under_the_queues_name_for_it(tmp_path):
    entry = _submission(tmp_path / "inbound", "..+brightness+2026-03-01 12:05:00.000000 UTC+abc")
    moved = inbound.set_aside(entry, 7, tmp_path / "course")
    assert moved == tmp_path / "course" / "autograder" / "refused" / "7" and moved.is_dir()
    assert not entry.exists() and sorted(p.name for p in (tmp_path / "course").iterdir()) == ["autograder"]


def test_the_collect_class_loads_on_a_students_server_where_autograder_is_hidden():
    """Every server loads nbgrader's exchange classes from the hub's settings; a student's hides
    autograder/ (autograder.sandbox.namespaces.HIDDEN_FROM_STUDENTS), so coursehub.checked_collect must import
    without it."""
    import subprocess
    import sys

    code = ("import sys\n"
            "class Hidden:\n"
            "    def find_spec(self, name, path=None, target=None):\n"
            "        if name.split('.')[0] == 'autograder':\n"
            "            raise ModuleNotFoundError(name)\n"
            "sys.meta_path.insert(0, Hidden())\n"
            "from coursehub.checked_collect import CheckedCollect\n"
            "print(CheckedCollect.__name__)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and done.stdout.strip() == "CheckedCollect", done.stderr
