"""Checks of the quiz: multiple-choice questions on lessons 00-05, answered as variables of the
notebook (``q3 = "b"``; the questions: course_lib/checks/quiz_questions.py): its spec, its
notebook's words and its checks.

The notebook's check cell saves the answers into ANSWERS_FILE beside the notebook (:func:`save_answers`,
from the notebook's variables), in the self-check and at grading alike. The self-check says only
whether each answer is one of its question's letters (:func:`well_formed`, in the kernel: no
answer key is anywhere a student can read). At grading the check ``answers`` reads that file
outside the kernel and compares each answer with the grader's answer key
(``ctx.expected("explain", question, answer)``: autograder/answers/quiz.py), which also says why a
wrong answer is wrong. Each question earns its points alone.
"""

from __future__ import annotations

import json
import os
import stat
import sys
from pathlib import Path

from course_lib.checks import runner
from course_lib.checks.context import Context
from course_lib.checks.multiple_choice import answer_problem, normalized
from course_lib.checks.quiz_questions import QUIZ_QUESTIONS
from course_lib.checks.registry import check
from course_lib.checks.spec import Assignment, NotebookText

# --- the notebook's words (markdown) and the spec ----------------------------------------

QUIZ_INTRO = """
# Quiz: lessons 00-05

Sixteen multiple-choice questions on what the lessons taught: ROS 2's concepts, reading what the
`ros2` command prints, choosing a QoS, reading a launch file, images, markers, actions and bags. Each has one
right answer and earns one point.

**How to answer:** write the letter of your choice as a string into the cell under the question,
e.g. `q3 = "b"`, and run it. The check cell at the end saves your answers and says whether each is
one of the question's letters; whether it is right is graded after you hand the quiz in, and the
feedback explains each wrong answer. Run every cell (Run All) before you hand it in.
"""

#: The spec: what assignments/build.py, the grader and the checks below read about it.
SPEC = Assignment("quiz", "05", {}, NotebookText(intro=QUIZ_INTRO, checks={"answers": ("your answers",)}),
       questions=QUIZ_QUESTIONS, answers="secret")

#: Where the check cell saves the notebook's answers (beside the notebook), and the most it reads.
ANSWERS_FILE = "quiz_answers.json"
ANSWERS_MAX_BYTES = 64 * 1024


def _notebook_namespace() -> dict:
    """The variables of the notebook (IPython's user namespace), or of __main__ outside one."""
    try:
        from IPython import get_ipython

        shell = get_ipython()
    except ImportError:
        shell = None
    return shell.user_ns if shell is not None else vars(sys.modules["__main__"])


def save_answers(namespace: dict | None = None, folder=".") -> dict:
    """Write the quiz's variables (q1, q2, ...) of `namespace` (default: the notebook's) into
    folder/ANSWERS_FILE and return them; a variable not set is None, a value JSON cannot hold
    is written as its repr."""
    namespace = _notebook_namespace() if namespace is None else namespace
    answers = {name: namespace.get(name) for name in QUIZ_QUESTIONS}
    text = json.dumps(answers, default=repr, ensure_ascii=False)
    Path(folder, ANSWERS_FILE).write_text(text, encoding="utf-8")
    return json.loads(text)


def read_answers(folder) -> dict:
    """The answers saved in folder/ANSWERS_FILE ({} when there is none, or it is no regular file of
    at most ANSWERS_MAX_BYTES holding a JSON object): never follows a link, never says what else
    the file holds."""
    try:
        fd = os.open(Path(folder, ANSWERS_FILE), os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError:
        return {}
    with os.fdopen(fd, "rb") as handle:
        if not stat.S_ISREG(os.fstat(handle.fileno()).st_mode):
            return {}
        data = handle.read(ANSWERS_MAX_BYTES + 1)
    try:
        answers = json.loads(data.decode("utf-8")) if len(data) <= ANSWERS_MAX_BYTES else None
    except ValueError:
        answers = None
    return answers if isinstance(answers, dict) else {}


def well_formed(answers: dict) -> list[tuple[str, str | None]]:
    """(question, what is wrong with the form of its answer, or None) for every question."""
    return [(name, answer_problem(question, answers.get(name))) for name, question in QUIZ_QUESTIONS.items()]


def selfcheck(name: str) -> None:
    """Save the notebook's answers, then say whether each is well-formed (not whether it is right:
    that is graded after hand-in). The verdict goes to stderr while an answer is not well-formed,
    where nbgrader's Validate looks for problems. Under grading it only saves them."""
    from course_lib.ros import rosenv

    answers = save_answers()
    if rosenv.under_grading():
        return
    problems = well_formed(answers)
    missing = [f"  ✘ {question}: {problem}" for question, problem in problems if problem]
    done = [question for question, problem in problems if not problem]
    lines = [f"[self-check] {len(done)} of {len(problems)} answers are well-formed (whether they are right "
             "is graded after you hand the quiz in: Submit it; working alone in `make lab`, then run "
             "`python -m autograder grade-lab` in a terminal and press Fetch Feedback)", *missing]
    if done:
        answered = (f"{question} = {normalized(answers[question])!r}" for question in done)
        lines.append("  ✔ answered: " + ", ".join(answered))
    stream = sys.stderr if missing else sys.stdout
    stream.write("\n".join(lines) + "\n")
    stream.flush()


def grade(name: str):
    """Save the notebook's answers, then grade check `name` (the grader runs it outside the kernel)."""
    save_answers()
    return runner.grade(SPEC.name, name)


@check(points=sum(question.points for question in QUIZ_QUESTIONS.values()), timeout=30)
def answers(ctx: Context) -> None:
    """Each answer of the quiz compared with the answer key, a question's points for each right one."""
    given = read_answers(ctx.workdir)
    if not given:
        ctx.note(f"no answers were saved ({ANSWERS_FILE} is missing or unreadable): run the quiz's check cell")
    for name, problem in well_formed(given):
        weight = QUIZ_QUESTIONS[name].points
        if problem is not None:
            ctx.item(False, f"{name}: {problem}", weight)
            continue
        answer = normalized(given[name])
        why = ctx.expected("explain", name, answer)
        ctx.item(why is None, f"{name}: {answer} is right" if why is None else f"{name}: not {answer}. {why}", weight)
