"""What counts as a submission (autograder.results.submissions) and when its digest changes: the digest
decides whether an earlier grade is reused, so it must move with everything grading reads."""

from __future__ import annotations

from pathlib import Path

from autograder.results.submissions import Submission, find_submissions, submission_digest


def _hand_in(course: Path, student: str, assignment: str, text: str = "{}") -> Path:
    folder = course / "submitted" / student / assignment
    folder.mkdir(parents=True)
    (folder / f"{assignment}.ipynb").write_text(text)
    return folder


def test_submissions_are_folders_with_a_notebook_sorted_and_filtered(tmp_path):
    """Only submitted/<student>/<assignment>/ folders holding a notebook count, in (student,
    assignment) order; --assignment and --student narrow them."""
    _hand_in(tmp_path, "bob", "pubsub")
    _hand_in(tmp_path, "alice", "pubsub")
    _hand_in(tmp_path, "alice", "brightness")
    (tmp_path / "submitted" / "carol" / "pubsub").mkdir(parents=True)  # a folder without a notebook
    (tmp_path / "submitted" / "carol" / "pubsub" / "notes.txt").write_text("no notebook")
    (tmp_path / "submitted" / "stray.txt").write_text("not a student")
    keys = [s.key for s in find_submissions(tmp_path)]
    assert keys == ["alice/brightness", "alice/pubsub", "bob/pubsub"]
    assert [s.key for s in find_submissions(tmp_path, assignment="pubsub")] == ["alice/pubsub", "bob/pubsub"]
    assert [s.key for s in find_submissions(tmp_path, student="alice", assignment="pubsub")] == ["alice/pubsub"]
    assert find_submissions(tmp_path / "nowhere") == []


def test_digest_is_stable_and_moves_with_the_submission_and_the_source(tmp_path):
    """The same files give the same digest; an edited or added submitted file, or an edited source
    notebook, gives another; another student's submission does not touch it."""
    folder = _hand_in(tmp_path, "alice", "pubsub", '{"cells": []}')
    source = tmp_path / "source" / "pubsub"
    source.mkdir(parents=True)
    (source / "pubsub.ipynb").write_text("source")
    sub = Submission("alice", "pubsub", folder)
    first = submission_digest(sub, tmp_path)
    assert submission_digest(sub, tmp_path) == first and len(first) == 64
    _hand_in(tmp_path, "bob", "pubsub", "bob's work")
    assert submission_digest(sub, tmp_path) == first
    seen = {first}
    for change in (lambda: (folder / "pubsub.ipynb").write_text('{"cells": [1]}'),
                   lambda: (folder / "timestamp.txt").write_text("2025-03-14 12:00:00 UTC"),
                   lambda: (source / "pubsub.ipynb").write_text("source, edited")):
        change()
        digest = submission_digest(sub, tmp_path)
        assert digest not in seen
        seen.add(digest)


def test_digest_tells_a_renamed_file_from_the_same_bytes(tmp_path):
    """Moving bytes from one file name to another changes the digest (names are part of it)."""
    folder = _hand_in(tmp_path, "alice", "pubsub")
    (folder / "a.py").write_text("x = 1")
    sub = Submission("alice", "pubsub", folder)
    before = submission_digest(sub, tmp_path)
    (folder / "a.py").rename(folder / "b.py")
    assert submission_digest(sub, tmp_path) != before
