"""What the quiz tests share: a question's markdown rendered as a reader sees it, every question of
every quiz, and whether a wrong choice's feedback gives the right answer away."""

from __future__ import annotations

import re

from autograder.answers import quiz as key
from course_lib.checks.multiple_choice import Question
from course_lib.checks.quiz_questions import QUIZ_QUESTIONS
from course_lib.selfcheck.lesson_quiz_questions import LESSON_QUIZZES

#: Every question of every quiz: (id, label as shown, question, right letter, wrong letter -> feedback).
ALL_QUESTIONS = [
    *((f"quiz-{name}", name, question, key.KEY[name].answer, key.KEY[name].wrong)
      for name, question in QUIZ_QUESTIONS.items()),
    *((f"lesson{lesson}-{number}", str(number), item.question, item.answer, item.wrong)
      for lesson, items in LESSON_QUIZZES.items() for number, item in enumerate(items, 1)),
]

_FENCED = re.compile(r"^```[^\n]*\n(.*?)^```$", re.DOTALL | re.MULTILINE)


def rendered(markdown: str):
    """The markdown as HTML (nbconvert's renderer, mistune, as in a feedback page), parsed: the
    top-level elements."""
    from bs4 import BeautifulSoup
    from nbconvert.filters.markdown_mistune import markdown2html_mistune

    return [element for element in BeautifulSoup(markdown2html_mistune(markdown), "html.parser").children
            if element.name]


def code_blocks(text: str) -> list[str]:
    """The contents of the fenced code blocks of a markdown text, each ending in a newline."""
    return _FENCED.findall(text)


def structure_problems(question: Question, label: str, elements) -> list[str]:
    """What is wrong with a question as rendered (`elements`: its top-level HTML elements): the
    label in bold opens a paragraph of prompt text, each code block of the text is a <pre> with its
    lines intact, the choices are the one list, last, an item per choice in order, and no markdown
    is left as raw text."""
    problems = []
    first = elements[0]
    opening = first.find("strong") if first.name == "p" else None
    if opening is None or opening.get_text() != f"{label}." or first.contents[0] is not opening:
        problems.append(f"does not open with the bold label {label}.: {first}")
    elif not first.get_text()[len(label) + 1:].strip():
        problems.append(f"the label's paragraph has no prompt: {first}")
    blocks = [element.get_text() for element in elements if element.name == "pre" or element.find("pre")]
    if blocks != code_blocks(question.text.strip() + "\n"):
        problems.append(f"code blocks {blocks!r} are not the text's {code_blocks(question.text)!r}")
    lists = [element for element in elements if element.name in ("ul", "ol")]
    if lists != [elements[-1]] or elements[-1].name != "ul":
        problems.append(f"the choices are not the one list, last: {[e.name for e in elements]}")
    else:
        items = elements[-1].find_all("li", recursive=False)
        shown = [(item.strong.get_text() if item.strong else None) for item in items]
        if shown != list(question.choices):
            problems.append(f"the list shows letters {shown}, not {list(question.choices)}")
        for item, choice in zip(items, question.choices.values(), strict=False):
            if item.get_text().split(": ", 1)[-1] != plain(choice, lower=False):
                problems.append(f"choice {item.get_text()!r} is not {choice!r}")
    prose = " ".join(element.get_text() for element in elements if element.name != "pre" and not element.find("pre"))
    if "```" in prose or "**" in prose or re.search(r"(^|\n)- ", prose):
        problems.append(f"raw markdown shows as text: {prose!r}")
    return problems


def plain(markdown: str, lower: bool = True) -> str:
    """A short markdown text as read: without code marks and bold, blanks collapsed."""
    text = " ".join(re.sub(r"[`*]", "", markdown).split())
    return text.lower() if lower else text


def gives_away(feedback: str, letter: str, choice: str) -> str | None:
    """How a wrong choice's feedback names the right answer (its letter as an answer, or the right
    choice's text), or None."""
    if re.search(rf"(?<![\w/~]){re.escape(plain(choice))}(?![\w/])", plain(feedback)):
        return f"it holds the right choice's text {choice!r}"
    named = re.search(rf"\({letter}\)|[\"']{letter}[\"']|\*\*{letter}\*\*|^{letter}[:.)]|"
                      rf"\b(?:answer|choice|option|letter)\s+(?:is\s+)?{letter}\b|\bthe answer is\b",
                      feedback, re.IGNORECASE | re.MULTILINE)
    return f"it names the right letter ({named.group()!r})" if named else None
