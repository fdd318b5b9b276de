"""Students from a roster CSV into the gradebook: ``python -m autograder roster COURSE_DIR roster.csv``.

The columns are nbgrader's (``nbgrader db student import`` reads the same file): ``id``
(required: the name of the student's folder in submitted/, the student id in the LMS's file
names), and optionally ``first_name``, ``last_name``, ``email``, ``lms_user_id``. Other columns
are ignored and listed. Importing again updates the students; nobody is removed and no grade is
touched. Unlike nbgrader's import, the whole file is checked before anything is written: a
missing ``id`` column, an empty, duplicated or unusable id stops the import with the row to fix.
"""

from __future__ import annotations

import csv
from pathlib import Path

COLUMNS = ("id", "first_name", "last_name", "email", "lms_user_id")


def read_roster(path) -> tuple[list[dict], list[str]]:
    """The students of a roster CSV and the names of the columns it ignores.

    Raises:
        ValueError: no id column, or a row whose id is empty, repeated or not usable as a folder name.
    """
    path = Path(path)
    with open(path, newline="", encoding="utf-8-sig") as handle:  # utf-8-sig: spreadsheets write a BOM
        reader = csv.DictReader(handle)
        header = [name.strip() for name in reader.fieldnames or []]
        if "id" not in header:
            raise ValueError(f"{path} has no 'id' column (its columns: {', '.join(header) or 'none'}). Name the column "
                             f"that holds the student ids 'id'; the others nbgrader knows: {', '.join(COLUMNS[1:])}.")
        students, seen = [], {}
        for line, row in enumerate(reader, start=2):
            row = {(key or "").strip(): (value or "").strip() for key, value in row.items() if key}
            student = row.get("id", "")
            if not student or student in (".", "..") or "/" in student or "\\" in student:
                raise ValueError(f"{path}, line {line}: the id {student!r} cannot name a folder in submitted/; "
                                 "give every student an id without slashes (e.g. the LMS user name)")
            if student in seen:
                raise ValueError(f"{path}, lines {seen[student]} and {line}: the id {student!r} appears twice; "
                                 "each student needs an id of their own")
            seen[student] = line
            students.append({key: row[key] for key in COLUMNS if row.get(key)})
    return students, [name for name in header if name not in COLUMNS]


def import_roster(course_dir, path) -> tuple[int, list[str]]:
    """Create or update the roster's students in the course gradebook.

    Returns:
        The number of students imported and the ignored columns.
    """
    from autograder.results import gradebook

    students, ignored = read_roster(path)
    with gradebook.open_gradebook(course_dir) as gb:
        for student in students:
            fields = dict(student)
            gb.update_or_create_student(fields.pop("id"), **fields)
    return len(students), ignored
