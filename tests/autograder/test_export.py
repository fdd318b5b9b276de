"""grades.csv for an LMS: every student and assignment of the gradebook, final scores with the late
penalty, in nbgrader's columns but quoted as CSV; a filtered export never replaces it."""

from __future__ import annotations

import csv
import datetime

import pytest
from support.imports import module_fixture

from autograder import config
from autograder.results import gradebook

export = module_fixture("autograder.term.export")  # it imports nbgrader


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    """Assignments a (5 points) and b (3), students ann, "Baker, Jr." and cy; ann handed in a a day
    late (20 % a day), nobody handed in b."""
    root = tmp_path_factory.mktemp("course")
    config.write_config(root)
    with open(root / "nbgrader_config.py", "a") as handle:
        handle.write("c.LatePenalty.per_day = {'a': 0.2}\n")
    with gradebook.open_gradebook(root) as gb:
        for name, points in (("a", 5), ("b", 3)):
            gb.update_or_create_assignment(name, duedate="2025-01-10 12:00:00")
            gb.add_notebook(name, name)
            gb.add_grade_cell("check", name, name, max_score=points, cell_type="code")
        gb.update_or_create_student("ann", first_name="Ann", last_name="Ang")
        gb.update_or_create_student("bob", first_name="Bob", last_name="Baker, Jr.")
        gb.update_or_create_student("cy")
    gradebook.record(root, "ann", "a", {("a", "check"): 5.0}, datetime.datetime(2025, 1, 11, 8, 0),
                     config.load(root))
    return root


def _rows(path):
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def test_every_student_and_assignment_with_the_final_score(export, course):
    """Six rows (3 students x 2 assignments); ann's late a: raw 5, penalty 1, score 4."""
    rows = _rows(export.export(course))
    assert [(r["assignment"], r["student_id"]) for r in rows] == \
        [("a", "ann"), ("a", "bob"), ("a", "cy"), ("b", "ann"), ("b", "bob"), ("b", "cy")]
    ann = rows[0]
    assert (ann["raw_score"], ann["late_submission_penalty"], ann["score"], ann["max_score"]) == \
        ("5.0", "1.0", "4.0", "5.0")
    assert ann["timestamp"] == "2025-01-11 08:00:00" and ann["duedate"] == "2025-01-10 12:00:00"
    assert all(r["score"] == "0.0" and r["timestamp"] == "" for r in rows[1:])


def test_names_with_commas_stay_one_field(export, course):
    """nbgrader's own export joins fields with commas unquoted; this one is read back intact."""
    rows = _rows(export.export(course))
    assert {r["last_name"] for r in rows if r["student_id"] == "bob"} == {"Baker, Jr."}
    assert list(rows[0]) == export.COLUMNS


def test_filtered_export_does_not_replace_grades_csv(export, course):
    """An export of one assignment to grades.csv is refused with the --to to use; grades.csv stays."""
    path = export.export(course)
    before = path.read_text()
    plugin = export.CourseCsvExport(config=config.load(course), assignment=["a"])
    with gradebook.open_gradebook(course) as gb, pytest.raises(ValueError, match="fewer rows.*--to"):
        plugin.export(gb)
    assert path.read_text() == before
    plugin.to = str(course / "a-only.csv")
    with gradebook.open_gradebook(course) as gb:
        plugin.export(gb)
    assert {r["assignment"] for r in _rows(course / "a-only.csv")} == {"a"}


def test_nbgrader_export_of_one_assignment_is_refused_with_its_error_line(export, course):
    """`nbgrader export --assignment a` in the course directory: an error line, exit status 1."""
    import subprocess
    import sys

    before = export.export(course).read_text()
    done = subprocess.run([sys.executable, "-m", "nbgrader", "export", "--assignment", "a"], cwd=course,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 1 and "[ExportApp | ERROR] An export of a only" in done.stderr + done.stdout
    assert "Traceback" not in done.stderr and (course / "grades.csv").read_text() == before
