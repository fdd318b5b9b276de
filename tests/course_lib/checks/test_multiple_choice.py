"""Multiple-choice questions (course_lib/checks/multiple_choice.py) as a reader sees them: every
question of the graded quiz and of the lessons' quizzes, rendered by nbconvert's markdown renderer
(the one of the feedback pages; JupyterLab's follows the same CommonMark rules), shows its number,
its prompt, its code blocks intact and its choices as a list."""

from __future__ import annotations

import pytest
from support.quiz import ALL_QUESTIONS, code_blocks, rendered, structure_problems

from course_lib.checks.multiple_choice import Question, answer_problem


@pytest.mark.parametrize(("label", "question"), [(label, question) for _id, label, question, *_ in ALL_QUESTIONS],
                         ids=[entry[0] for entry in ALL_QUESTIONS])
def test_every_question_renders_with_its_number_prompt_code_and_choices(label, question):
    assert structure_problems(question, label, rendered(question.markdown(label))) == []


def test_a_question_that_opens_with_a_code_block_keeps_the_block_and_its_choices_apart():
    """Written on the label's line, a fence is no fence: its lines run together with the label and
    the choices become text of a code block (q5 of the quiz once did so). Such a text gets its
    label on a line of its own."""
    question = Question("```\n$ ros2 node list\n/a\n/a\n```\n\nWhat does this say?", {"a": "x", "b": "y"})
    elements = rendered(question.markdown("q5"))
    assert [element.name for element in elements] == ["p", "pre", "p", "ul"]
    assert elements[1].get_text() == code_blocks(question.text)[0] == "$ ros2 node list\n/a\n/a\n"
    assert len(elements[3].find_all("li")) == 2


def test_the_structure_check_finds_a_block_on_the_label_line():
    """What test_every_question_renders_... would say of the markdown before the fix."""
    question = Question("```\n$ ros2 node list\n/a\n```\n\nWhat does this say?", {"a": "x", "b": "y"})
    before_the_fix = f"**q5.** {question.text}\n\n- **a**: x\n- **b**: y"
    problems = structure_problems(question, "q5", rendered(before_the_fix))
    assert any("code blocks" in problem for problem in problems), problems
    assert any("the choices are not the one list" in problem for problem in problems), problems


@pytest.mark.parametrize(("answer", "problem"), [
    (None, "not answered yet"), ("", "not answered yet"), (3, "write the letter as a string"),
    ("e", "is not one of the choices"), (" B", None)])
def test_an_answer_is_one_of_the_letters(answer, problem):
    said = answer_problem(Question("?", {"a": "x", "b": "y"}), answer)
    assert said is None if problem is None else problem in said
