"""The short ungraded quiz at the end of a lesson: its questions shown, and instant feedback.

A lesson ends with two cells::

    selfcheck.show_quiz("05")                      # the questions, as markdown
    quiz = {1: "", 2: "", 3: ""}                   # your letters
    selfcheck.check_quiz("05", quiz)

The questions of every lesson, with their answers, why each is right and why each wrong choice
is wrong, are in :mod:`.lesson_quiz_questions`
(ungraded: a student may read them; the graded quiz keeps its answers with the grader).
"""

from __future__ import annotations

from course_lib.checks.multiple_choice import answer_problem, normalized
from course_lib.selfcheck.lesson_quiz_questions import LESSON_QUIZZES, Answered
from course_lib.selfcheck.verdicts import Verdict


def quiz_of(lesson: str) -> tuple[Answered, ...]:
    """The questions of a lesson's quiz; KeyError naming the lessons that have one."""
    if lesson not in LESSON_QUIZZES:
        raise KeyError(f"no quiz for lesson {lesson!r}; the lessons with one are {sorted(LESSON_QUIZZES)}")
    return LESSON_QUIZZES[lesson]


def quiz_markdown(lesson: str) -> str:
    """The lesson's questions as markdown, numbered from 1, and how to answer them."""
    questions = quiz_of(lesson)
    blank = ", ".join(f'{number}: ""' for number in range(1, len(questions) + 1))
    parts = [item.question.markdown(str(number)) for number, item in enumerate(questions, 1)]
    parts.append(f"Answer in the next cell, one letter a question: `quiz = {{{blank}}}`.")
    return "\n\n".join(parts)


def show_quiz(lesson: str) -> None:
    """Show the lesson's questions under the cell (as text outside a notebook)."""
    text = quiz_markdown(lesson)
    try:
        from IPython import get_ipython
        from IPython.display import Markdown, display
    except ImportError:
        get_ipython = None
    if get_ipython is not None and get_ipython() is not None:
        display(Markdown(text))
    else:
        print(text)


def check_quiz(lesson: str, answers: dict) -> Verdict:
    """Each answer right or wrong: a right one with why it is right, a wrong one with why that
    choice is wrong (never which is right); true when all are right.

    `answers` maps the question's number (1, 2, ...) to a letter. A question without a
    well-formed answer says what to write, and the verdict is not done yet.
    """
    questions = quiz_of(lesson)
    if not isinstance(answers, dict):
        return Verdict(False, f"Pass a dict of question number -> letter, e.g. {{1: \"b\"}}, not a "
                              f"{type(answers).__name__}.")
    lines, right = [], 0
    for number, item in enumerate(questions, 1):
        answer = answers.get(number, answers.get(str(number)))
        problem = answer_problem(item.question, answer)
        if problem is not None:
            lines.append(f"  ✘ {number}: {problem}")
        elif normalized(answer) == item.answer:
            right += 1
            lines.append(f"  ✔ {number}: {item.answer}. {item.why}")
        else:
            lines.append(f"  ✘ {number}: not {normalized(answer)}. {item.wrong[normalized(answer)]}")
    head = f"{right} of {len(questions)} right" + ("." if right == len(questions) else "; try the others again.")
    return Verdict(right == len(questions), "\n".join([head, *lines]))
