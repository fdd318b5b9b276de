"""The short quizzes at the end of the lessons (course_lib.selfcheck.lesson_quiz): instant feedback
for each answer, the form of an answer judged as the graded quiz judges it."""

from __future__ import annotations

import pytest

from course_lib import selfcheck
from course_lib.selfcheck.lesson_quiz import quiz_markdown, quiz_of
from course_lib.selfcheck.lesson_quiz_questions import LESSON_QUIZZES


@pytest.mark.parametrize("lesson", sorted(LESSON_QUIZZES))
def test_each_quiz_has_three_or_four_questions_with_their_answer_among_the_choices(lesson):
    questions = quiz_of(lesson)
    assert 3 <= len(questions) <= 4
    for item in questions:
        assert item.answer in item.question.choices and item.why


def test_all_right_is_true_and_says_why_each_is_right():
    answers = {number: item.answer.upper() for number, item in enumerate(quiz_of("05"), 1)}
    verdict = selfcheck.check_quiz("05", answers)
    assert verdict and str(verdict).startswith("✔ 3 of 3 right.")
    assert quiz_of("05")[1].why in str(verdict)


def test_a_wrong_and_a_missing_answer_are_named_with_why_and_what_to_write():
    first, second, _ = quiz_of("02")
    wrong = next(letter for letter in first.question.choices if letter != first.answer)
    verdict = selfcheck.check_quiz("02", {"1": wrong, 2: second.answer})
    assert not verdict
    text = str(verdict)
    assert text.startswith("✘ 1 of 3 right") and f"✘ 1: not {wrong}. {first.why}" in text
    assert '✘ 3: not answered yet: write one of "a", "b", "c" or "d"' in text


def test_answers_that_are_no_dict_or_no_lesson_say_what_to_pass():
    assert "Pass a dict" in str(selfcheck.check_quiz("01", ["a", "b", "c"]))
    with pytest.raises(KeyError, match="the lessons with one are"):
        quiz_of("99")


def test_the_questions_show_every_choice_and_how_to_answer():
    text = quiz_markdown("00")
    assert text.count("- **a**:") == len(quiz_of("00"))
    assert 'quiz = {1: "", 2: "", 3: ""}' in text
