"""The short quizzes at the end of the lessons (course_lib.selfcheck.lesson_quiz): instant feedback
for each answer, the form of an answer judged as the graded quiz judges it; the right letters spread
over a, b, c and d, and a wrong answer told why that choice is wrong, not which is right."""

from __future__ import annotations

import pytest
from support.quiz import gives_away, rendered

from course_lib import selfcheck
from course_lib.selfcheck.lesson_quiz import quiz_markdown, quiz_of
from course_lib.selfcheck.lesson_quiz_questions import LESSON_QUIZZES


@pytest.mark.parametrize("lesson", sorted(LESSON_QUIZZES))
def test_each_quiz_has_three_or_four_questions_with_their_answer_among_the_choices(lesson):
    questions = quiz_of(lesson)
    assert 3 <= len(questions) <= 4
    for item in questions:
        assert item.answer in item.question.choices and item.why
        assert set(item.wrong) == set(item.question.choices) - {item.answer} and all(item.wrong.values())


def test_the_right_letters_are_spread_over_the_lessons_and_within_each():
    """No letter is right in more than 40 % of the questions, and no lesson has one letter for all."""
    letters = [item.answer for items in LESSON_QUIZZES.values() for item in items]
    counts = {letter: letters.count(letter) for letter in "abcd"}
    assert max(counts.values()) <= 0.4 * len(letters), counts
    same = [lesson for lesson, items in LESSON_QUIZZES.items() if len({item.answer for item in items}) == 1]
    assert same == [], f"every answer of lesson {same} is the same letter"


@pytest.mark.parametrize("lesson", sorted(LESSON_QUIZZES))
def test_a_wrong_answers_feedback_never_names_the_right_one(lesson):
    for number, item in enumerate(quiz_of(lesson), 1):
        right = item.question.choices[item.answer]
        for letter, feedback in item.wrong.items():
            assert gives_away(feedback, item.answer, right) is None, (lesson, number, letter, feedback)


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
    assert text.startswith("✘ 1 of 3 right") and f"✘ 1: not {wrong}. {first.wrong[wrong]}" in text
    assert first.why not in text and f"✔ 2: {second.answer}. {second.why}" in text
    assert '✘ 3: not answered yet: write one of "a", "b", "c" or "d"' in text


def test_answers_that_are_no_dict_or_no_lesson_say_what_to_pass():
    assert "Pass a dict" in str(selfcheck.check_quiz("01", ["a", "b", "c"]))
    with pytest.raises(KeyError, match="the lessons with one are"):
        quiz_of("99")


def test_the_questions_show_every_choice_and_how_to_answer():
    text = quiz_markdown("00")
    assert text.count("- **a**:") == len(quiz_of("00"))
    assert 'quiz = {1: "", 2: "", 3: ""}' in text


@pytest.mark.parametrize("lesson", sorted(LESSON_QUIZZES))
def test_the_shown_quiz_renders_each_question_then_its_own_list_of_choices(lesson):
    """What show_quiz displays, rendered (tests/course_lib/checks/test_multiple_choice.py renders each question
    alone)."""
    elements = rendered(quiz_markdown(lesson))
    questions = quiz_of(lesson)
    lists = [element for element in elements if element.name == "ul"]
    assert [len(found.find_all("li")) for found in lists] == [len(item.question.choices) for item in questions]
    labels = [element.strong.get_text() for element in elements if element.name == "p" and element.strong]
    assert labels == [f"{number}." for number in range(1, len(questions) + 1)]
