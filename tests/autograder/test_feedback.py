"""The students' index pages: every assignment graded so far, also after a run of one assignment
or one student; reasons for the student, never the instructor's notes or the grader's paths."""

from __future__ import annotations

import dataclasses
import json

from autograder.results import store
from autograder.results.grade_result import GradeResult
from autograder.term import feedback


def _recorded(course, student, assignment, **fields):
    result = GradeResult(student, assignment, "digest", score=0, max_score=10, status="failed", **fields)
    folder = store.state_dir(course, student, assignment)
    folder.mkdir(parents=True)
    (folder / store.STATE_FILE).write_text(json.dumps(dataclasses.asdict(result)))


def _course(tmp_path):
    _recorded(tmp_path, "alice", "pubsub", reason="Your notebook is named wrong.",
              detail="Rename it: mv /tmp/autograder-work-x/a b\n[AutogradeApp | ERROR] log line")
    _recorded(tmp_path, "alice", "brightness", reason="The kernel died.")
    _recorded(tmp_path, "bob", "pubsub", reason="Named wrong too.")
    return tmp_path


def test_feedback_of_one_assignment_keeps_the_others_in_the_index(tmp_path):
    """`feedback --assignment pubsub`: alice's index still lists brightness."""
    course = _course(tmp_path)
    pages = feedback.write_feedback(course, "pubsub")
    assert sorted(p.parent.name for p in pages) == ["alice", "bob"]
    page = (course / "feedback" / "alice" / "index.html").read_text()
    assert "<td>brightness</td>" in page and "<td>pubsub</td>" in page and "The kernel died." in page


def test_feedback_of_one_student_writes_only_that_index(tmp_path):
    """`feedback --student bob` writes bob's index and leaves alice's alone."""
    course = _course(tmp_path)
    assert feedback.write_feedback(course, student="bob") == [course / "feedback" / "bob" / "index.html"]
    assert not (course / "feedback" / "alice").exists()


def test_index_shows_the_reason_but_no_instructor_note(tmp_path):
    """The student reads why; the fix, nbgrader's log and the grader's folders stay out."""
    course = _course(tmp_path)
    feedback.write_feedback(course)
    page = (course / "feedback" / "alice" / "index.html").read_text()
    assert "Your notebook is named wrong." in page
    assert "mv " not in page and "AutogradeApp" not in page and "autograder-work" not in page


def test_notebook_pages_get_wrapping_output_lines(tmp_path):
    """nbgrader's feedback page gets a style that wraps output lines, once."""
    page = tmp_path / "pubsub.html"
    page.write_text("<html><head><style>pre{}</style></head><body><pre>a long verdict line</pre></body></html>")
    feedback._wrap_lines(page)
    feedback._wrap_lines(page)
    text = page.read_text()
    assert text.count("white-space: pre-wrap") == 1 and text.index("pre-wrap") < text.index("</head>")
