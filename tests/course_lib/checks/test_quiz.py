"""The graded quiz (course_lib/checks/assignments/quiz.py): the answer key gets full marks, a blank quiz 0, a
wrong answer loses exactly its points with its explanation; the self-check only judges the form;
the key stays with the grader; the right letters are spread and a wrong answer's feedback says why
that choice is wrong without naming the right one. The check runs in this process, as the grader's check process runs
it (no ROS, no nbgrader: the whole pipeline grades a quiz in tests/assignments/test_autograder_pipeline.py)."""

from __future__ import annotations

import json
import os

import pytest
from support.quiz import gives_away

from autograder.answers import quiz as key
from autograder.term import record_answers
from course_lib import contract
from course_lib.checks import answers, assignments, check_process, registry
from course_lib.checks import quiz as checks
from course_lib.checks.quiz_questions import QUIZ_QUESTIONS
from course_lib.checks.result import verdict_text

RIGHT = {name: entry.answer for name, entry in key.KEY.items()}


def graded(tmp_path, monkeypatch, given: dict | None):
    """The quiz's check, graded against the answers `given` (None: no answers file)."""
    monkeypatch.setenv(contract.ANSWERS_ENV, "graded")
    if given is not None:
        checks.save_answers(given, tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    return check_process.run_in_this_process("quiz", "answers", 1, tmp_path, out)


def test_the_key_answers_every_question_and_only_those():
    assert set(key.KEY) == set(QUIZ_QUESTIONS)
    for name, entry in key.KEY.items():
        choices = QUIZ_QUESTIONS[name].choices
        assert entry.answer in choices and entry.why, name
        assert set(entry.wrong) == set(choices) - {entry.answer} and all(entry.wrong.values()), name


def test_the_right_letters_are_spread():
    """No letter is right in more than 40 % of the questions, so that none is a good guess."""
    counts = {letter: list(RIGHT.values()).count(letter) for letter in "abcd"}
    assert max(counts.values()) <= 0.4 * len(RIGHT), counts


@pytest.mark.parametrize("name", sorted(QUIZ_QUESTIONS, key=lambda name: int(name[1:])))
def test_a_wrong_answers_feedback_never_names_the_right_one(name):
    entry = key.KEY[name]
    right = QUIZ_QUESTIONS[name].choices[entry.answer]
    for letter, feedback in entry.wrong.items():
        assert gives_away(feedback, entry.answer, right) is None, (name, letter, feedback)
        assert key.explain(name, letter) == feedback
    assert key.explain(name, entry.answer) is None


def test_the_give_away_check_finds_a_named_answer():
    assert gives_away("The answer is d.", "d", "x") and gives_away("Not this: pick (d).", "d", "x")
    assert gives_away("It is `/robot1/dark`, as the namespace says.", "d", "`/robot1/dark`")
    assert gives_away("That is about 30 Hz", "d", "about 30 Hz")
    assert gives_away("A homography needs 4 pairs.", "c", "4")
    assert gives_away("dark_fraction is the executable's name", "d", "`/robot1/dark`") is None


def test_the_answer_key_gets_full_marks(tmp_path, monkeypatch):
    result = graded(tmp_path, monkeypatch, RIGHT)
    assert result.points == result.max_points == len(QUIZ_QUESTIONS), result.verdict_lines()
    assert result.error is None


def test_the_verdict_shows_no_seed_the_quiz_never_drew_from(tmp_path, monkeypatch):
    """A quiz draws nothing at random: its feedback has no seed line and no AUTOGRADER_SEED to
    reproduce it with (a check that draws scenes keeps both: tests/course_lib/checks/test_result.py)."""
    text = verdict_text(graded(tmp_path, monkeypatch, RIGHT), graded=True)
    assert text.startswith("[graded] ") and "seed" not in text.lower(), text


@pytest.mark.parametrize("given", [{}, None], ids=["blank", "no-answers-file"])
def test_a_blank_quiz_gets_nothing_and_says_what_to_write(tmp_path, monkeypatch, given):
    result = graded(tmp_path, monkeypatch, given)
    assert result.points == 0 and result.error is None
    assert all(not item["ok"] and "not answered yet" in item["message"] for item in result.items)


def test_one_wrong_answer_loses_exactly_its_points_and_says_why(tmp_path, monkeypatch):
    wrong = next(letter for letter in QUIZ_QUESTIONS["q6"].choices if letter != RIGHT["q6"])
    result = graded(tmp_path, monkeypatch, {**RIGHT, "q6": wrong.upper()})  # " B" and "B" count as "b"
    assert result.points == result.max_points - QUIZ_QUESTIONS["q6"].points
    failed = [item["message"] for item in result.items if not item["ok"]]
    assert failed == [f"q6: not {wrong}. {key.explain('q6', wrong)}"]  # as the lesson quizzes say it
    assert key.explain("q6", wrong) == key.KEY["q6"].wrong[wrong] and "robot1/dark" not in failed[0]


def test_an_answer_that_is_no_letter_loses_its_points_with_what_to_write(tmp_path, monkeypatch):
    result = graded(tmp_path, monkeypatch, {**RIGHT, "q2": 2, "q3": "e"})
    failed = {item["message"].split(":")[0]: item["message"] for item in result.items if not item["ok"]}
    assert set(failed) == {"q2", "q3"} and result.points == result.max_points - 2
    assert "write the letter as a string" in failed["q2"] and "is not one of the choices" in failed["q3"]


def test_the_check_reads_no_link_and_no_huge_file(tmp_path):
    secret = tmp_path / "secret.json"
    secret.write_text(json.dumps(RIGHT))
    os.symlink(secret, tmp_path / checks.ANSWERS_FILE)
    assert checks.read_answers(tmp_path) == {}
    os.remove(tmp_path / checks.ANSWERS_FILE)
    (tmp_path / checks.ANSWERS_FILE).write_text(" " * checks.ANSWERS_MAX_BYTES + json.dumps(RIGHT))
    assert checks.read_answers(tmp_path) == {}


def test_the_self_check_saves_the_answers_and_judges_only_their_form(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(checks, "_notebook_namespace", lambda: {"q1": "b", "q2": "z", "q3": 3, "unrelated": 1})
    checks.selfcheck("answers")
    said = capsys.readouterr()
    assert "1 of 16 answers are well-formed" in said.err and "q1 = 'b'" in said.err
    assert "q2: 'z' is not one of the choices" in said.err and "q4: not answered yet" in said.err
    assert " right" not in said.err.replace("whether they are right", "")  # it never says right or wrong
    assert checks.read_answers(tmp_path) == {**dict.fromkeys(QUIZ_QUESTIONS), "q1": "b", "q2": "z", "q3": 3}


def test_the_key_is_never_recorded_for_students():
    """A quiz's recorded answers would be its key: its spec says "secret", record-answers skips it,
    and a self-check that asked for an answer would find none."""
    assert assignments.spec("quiz").answers == "secret"
    assert "quiz" not in record_answers.assignments_with_keys()
    assert not answers.recorded_path("quiz").exists()
    with pytest.raises(answers.MissingAnswer):
        answers.AnswerKey("quiz", "selfcheck").expected("explain", "q1", "b")


def test_no_explanation_of_the_key_is_in_what_students_install():
    from pathlib import Path

    import course_lib

    folder = Path(course_lib.__file__).parent
    texts = [path.read_text() for path in folder.rglob("*") if path.suffix in (".py", ".json")]
    for name, entry in key.KEY.items():
        for why in (entry.why, *entry.wrong.values()):
            assert not any(why[:40] in text for text in texts), name


def test_the_check_is_worth_the_points_of_its_questions():
    (only,) = registry.checks_of("quiz").values()
    assert only.points == sum(question.points for question in QUIZ_QUESTIONS.values())
