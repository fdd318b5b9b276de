"""The autograder end to end, with the real nbgrader CLI and gradebook: release -> reference
solution -> grade -> full marks (catdog_warp here; see FULL_RUN_REFERENCES), typical mistakes
graded down with their reason on the feedback page, a quiz with one wrong answer. (The checks on
single mistakes, without nbgrader: tests/assignments/test_autograder.py and
tests/course_lib/checks/test_quiz.py; they run on another test worker.)"""

from __future__ import annotations

from pathlib import Path

import pytest
from support import course as course_support
from support import zoo
from support.zoo.quiz import answered
from test_autograder import ASSIGNMENTS, CATDOG_CHECK, CATDOG_MISTAKES, FULL_RUN

from autograder.answers import quiz as quiz_key
from autograder.term import grade

#: Typical mistakes that go through the whole pipeline (nbgrader, grader, feedback page), as
#: (edits, the check it costs, a phrase of the verdict); the other typical mistakes are run through
#: the checks only (tests/assignments/test_autograder.py), which is cheaper.
FULL_RUN_MISTAKES = {
    "catdog_warp": (CATDOG_MISTAKES[FULL_RUN["catdog_warp"]][0], CATDOG_CHECK,
                    CATDOG_MISTAKES[FULL_RUN["catdog_warp"]][1]),
}

#: The quiz handed in with every answer right but QUIZ_WRONG's (no ROS, no build: a cheap grading).
QUIZ_WRONG = ("q8", "a")


#: References graded through the whole pipeline here. Each assignment's reference goes through it
#: once in the suite: brightness's in the zoo (tests/assignments/test_autograder_zoo.py, "hostile": with a
#: hostile cell), pubsub's in the term (tests/autograder/test_term.py, alice), catdog_warp's here.
FULL_RUN_REFERENCES = ["catdog_warp"]

#: A last cell that rewrites the node module with Python instead of %%writefile: the grader
#: cannot predict it (autograder.builds.notebook_writes), so the early build and checks must not count.
REWRITING_CELL = """from pathlib import Path
node = Path("ros2_ws/src/brightness/brightness/brightness_node.py")
node.write_text(node.read_text() + "\\n\\ndef average_brightness(image):\\n    return 0\\n")
"""


def submit_rewriting(course: Path, student: str) -> None:
    """The brightness reference, with REWRITING_CELL at the end of its notebook."""
    import nbformat

    path = zoo.submit(course, student, "brightness")
    nb = nbformat.read(path, as_version=4)
    nb.cells.append(nbformat.v4.new_code_cell(REWRITING_CELL))
    nbformat.write(nb, path)


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    course = course_support.released_course(tmp_path_factory, tmp_path_factory.mktemp("course"), ASSIGNMENTS)
    course_support.seed_interface_cache(tmp_path_factory, course, ASSIGNMENTS)
    for assignment in FULL_RUN_REFERENCES:
        zoo.submit(course, "reference", assignment)
    for assignment, (edits, _check, _reason) in FULL_RUN_MISTAKES.items():
        zoo.submit(course, "mistaken", assignment, edits)
    submit_rewriting(course, "rewriting")
    zoo.submit(course, "mistaken", "quiz", [answered(dict([QUIZ_WRONG]))])
    results = grade.grade(course, workers=2, progress=False)
    return course, {(r.student, r.assignment): r for r in results}


@pytest.fixture(scope="module")
def feedback_pages(course):
    from autograder.term import feedback

    root, _ = course
    return root, feedback.write_feedback(root)


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_release_has_stubs_and_no_solutions_or_hidden_tests(course):
    """release/ holds the notebooks with stubs: no solution code, no hidden tests; a question's
    answer cell holds `q3 = None`, the others nbgrader's raise (autograder.term.release)."""
    from course_lib.checks.assignments import ASSIGNMENTS as SPECS

    root, _ = course
    for assignment in ASSIGNMENTS:
        text = (root / "release" / assignment / f"{assignment}.ipynb").read_text()
        assert "BEGIN SOLUTION" not in text and "HIDDEN TESTS" not in text and "checks.grade(" not in text
        questions = SPECS[assignment].questions
        assert all(f"{name} = None" in text for name in questions), assignment
        assert questions or "NotImplementedError" in text, assignment


@pytest.mark.slow
@pytest.mark.parametrize("assignment", FULL_RUN_REFERENCES)
def test_reference_solutions_get_full_marks(course, assignment):
    """release -> reference solution in the student notebook -> grade: every point."""
    root, results = course
    result = results["reference", assignment]
    assert result.status == "graded", result.reason
    assert result.score == result.max_score > 0, zoo.graded_outputs(root, "reference", assignment)
    assert result.checked_early, "the files the notebook wrote were predicted: built and checked while it ran"


@pytest.mark.slow
def test_a_file_the_notebook_writes_otherwise_is_built_and_checked_as_written(course):
    """A cell that rewrites the module with Python (not %%writefile) makes the prediction wrong:
    the early build and checks are dropped, and the module as the notebook left it is graded."""
    root, results = course
    result = results["rewriting", "brightness"]
    assert result.status == "graded", result.reason
    assert result.checked_early is False
    scores = {c["cell"]: c["auto_score"] for c in result.cells}
    assert (scores["check_values"] == 0
            and result.score < result.max_score), zoo.graded_outputs(root, "rewriting", "brightness")


@pytest.mark.slow
@pytest.mark.parametrize("assignment", sorted(FULL_RUN_MISTAKES))
def test_typical_mistake_is_graded_down_with_its_reason_in_the_feedback(feedback_pages, course, assignment):
    """A typical mistake, handed in as a notebook, loses points in the check it breaks, and its
    feedback page says why."""
    _, results = course
    root, _pages = feedback_pages
    result = results["mistaken", assignment]
    assert (result.status == "graded"
            and 0 < result.score < result.max_score), zoo.graded_outputs(root, "mistaken", assignment)
    _edits, check, reason = FULL_RUN_MISTAKES[assignment]
    cell = next(c for c in result.cells if c["cell"] == f"check_{check}")
    assert cell["auto_score"] < cell["max_score"], (cell, zoo.graded_outputs(root, "mistaken", assignment))
    page = (root / "feedback" / "mistaken" / assignment / f"{assignment}.html").read_text()
    assert reason in page.replace("&#39;", "'").replace("&quot;", '"')


@pytest.mark.slow
def test_feedback_shows_crops_beside_expected(feedback_pages):
    """Feedback: an index per student, and the warp notebook's page shows both crops."""
    root, pages = feedback_pages
    assert root / "feedback" / "reference" / "index.html" in pages
    page = (root / "feedback" / "reference" / "catdog_warp" / "catdog_warp.html").read_text()
    assert "yours" in page and "expected" in page and "data:image/png;base64" in page
    assert "reproduce with AUTOGRADER_SEED=" in page
    assert not (root / "feedback" / "reference" / "catdog_warp" / "autograder.log").exists()


@pytest.mark.slow
def test_a_quiz_with_one_wrong_answer_loses_exactly_its_point_and_the_feedback_says_why(feedback_pages, course):
    """The quiz's answers go from the notebook's variables through the grader's check to the feedback
    page: every point but the wrong answer's, and why it is wrong."""
    _, results = course
    root, _pages = feedback_pages
    result = results["mistaken", "quiz"]
    assert result.status == "graded", result.reason
    question, letter = QUIZ_WRONG
    assert result.score == result.max_score - 1 == 15, zoo.graded_outputs(root, "mistaken", "quiz")
    page = (root / "feedback" / "mistaken" / "quiz" / "quiz.html").read_text()
    page = page.replace("&quot;", '"').replace("&#39;", "'")
    assert f"{question}: not {letter}. {quiz_key.explain(question, letter)}" in page
