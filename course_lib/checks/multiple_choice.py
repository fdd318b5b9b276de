"""Multiple-choice questions: how one reads in a notebook and what counts as a well-formed answer.

The graded quiz (course_lib/checks/assignments/quiz.py, its questions in course_lib/checks/quiz_questions.py)
and the short quizzes at the end of the lessons (course_lib.selfcheck.lesson_quiz) share them. A question holds
no answer: the graded quiz's answers stay with the grader (autograder/answers/quiz.py).
"""

from __future__ import annotations

import dataclasses
import re

#: What a student leaves where an answer is not given yet (the self-checks say "not answered yet").
PLACEHOLDERS = (None, ..., "...", "")

#: How a markdown text that opens with a block (no sentence) begins: a code fence, a list, a
#: quote, a heading, a table.
_OPENS_WITH_BLOCK = re.compile(r"(```|~~~|[-*+] |\d+[.)] |>|#|\|)")


@dataclasses.dataclass(frozen=True)
class Question:
    """One multiple-choice question.

    Attributes:
        text: the question (markdown; may hold a code block of `ros2` output or a launch file).
        choices: letter -> the choice's text (markdown), in the order shown.
        points: what a right answer earns in a graded quiz.
    """

    text: str
    choices: dict[str, str]
    points: float = 1.0

    def markdown(self, label: str) -> str:
        """The question as a notebook shows it: its label in bold before the text's first sentence,
        then one list item per choice. A text that opens with a block (a fenced code block, a list)
        gets the label on a line of its own: on the block's first line markdown would read the
        block as text of the label's paragraph."""
        text = self.text.strip()
        lines = [f"**{label}.**" + ("\n\n" if _OPENS_WITH_BLOCK.match(text) else " ") + text, ""]
        lines += [f"- **{letter}**: {choice}" for letter, choice in self.choices.items()]
        return "\n".join(lines)

    def letters(self) -> str:
        """The letters one may answer, as a sentence writes them: '"a", "b", "c" or "d"'."""
        quoted = [f'"{letter}"' for letter in self.choices]
        return ", ".join(quoted[:-1]) + f" or {quoted[-1]}" if len(quoted) > 1 else quoted[0]


def answer_problem(question: Question, answer) -> str | None:
    """What is wrong with the form of an answer (None when it is one of the question's letters):
    not answered yet, not a string, or a letter the question does not offer."""
    if answer is None or answer is ... or (isinstance(answer, str) and answer.strip() in PLACEHOLDERS):
        return f"not answered yet: write one of {question.letters()}"
    if not isinstance(answer, str):
        return f"{answer!r} is a {type(answer).__name__}; write the letter as a string, one of {question.letters()}"
    if answer.strip().lower() not in question.choices:
        return f"{answer!r} is not one of the choices: write one of {question.letters()}"
    return None


def normalized(answer: str) -> str:
    """A well-formed answer as it is compared: ' B' is "b"."""
    return answer.strip().lower()
