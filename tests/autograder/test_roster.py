"""Students' names from a roster CSV in the gradebook (the formgrader showed "None, None"); a
roster without ids, or with a repeated or unusable id, is refused before anything is written."""

from __future__ import annotations

import pytest

from autograder import config
from autograder.results import gradebook
from autograder.term import roster

ROSTER = ("id,first_name,last_name,email,Section\n"
          "alice,Alice,Ang,alice@example.org,A\n"
          "bob,Bob,\"Baker, Jr.\",,B\n")


def test_roster_names_reach_the_formgrader(tmp_path):
    """After the import nbgrader's API (the formgrader's Students page) lists each student's names."""
    from nbgrader.apps.api import NbGraderAPI

    config.write_config(tmp_path)
    (tmp_path / "roster.csv").write_text("\ufeff" + ROSTER)  # a spreadsheet's byte-order mark
    assert roster.import_roster(tmp_path, tmp_path / "roster.csv") == (2, ["Section"])
    students = {s["id"]: s for s in NbGraderAPI(config=config.load(tmp_path)).get_students()}
    assert (students["alice"]["first_name"], students["alice"]["last_name"]) == ("Alice", "Ang")
    assert students["bob"]["last_name"] == "Baker, Jr." and students["alice"]["email"] == "alice@example.org"


def test_importing_again_updates_and_removes_nobody(tmp_path):
    """A second roster updates names and adds students; those not in it stay."""
    (tmp_path / "first.csv").write_text(ROSTER)
    (tmp_path / "second.csv").write_text("id,last_name\nbob,Baker\ncarol,Chen\n")
    roster.import_roster(tmp_path, tmp_path / "first.csv")
    roster.import_roster(tmp_path, tmp_path / "second.csv")
    with gradebook.open_gradebook(tmp_path) as gb:
        names = {s.id: (s.first_name, s.last_name) for s in gb.students}
    assert names == {"alice": ("Alice", "Ang"), "bob": ("Bob", "Baker"), "carol": (None, "Chen")}


@pytest.mark.parametrize("text, message", [
    ("Username,First name\nalice,Alice\n", "no 'id' column \\(its columns: Username, First name\\)"),
    ("id,last_name\nalice,Ang\nalice,Other\n", "lines 2 and 3: the id 'alice' appears twice"),
    ("id\nalice\n\n,Nobody\n", "line 3: the id '' cannot name a folder"),
    ("id\nsome/one\n", "the id 'some/one' cannot name a folder"),
])
def test_bad_roster_is_refused_with_the_row_to_fix(tmp_path, text, message):
    """Errors name the line and the fix; the gradebook is not even created."""
    (tmp_path / "roster.csv").write_text(text)
    with pytest.raises(ValueError, match=message):
        roster.import_roster(tmp_path, tmp_path / "roster.csv")
    assert not (tmp_path / "gradebook.db").exists()
