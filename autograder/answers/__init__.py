"""The grader's answer keys: one module per assignment, a function per question of its contract.

A check asks ``ctx.expected("<function>", *inputs)`` (course_lib.checks.answers); when graded,
the answer is the function of that name in ``<assignment>.py`` here, called with the generated
inputs. The grader hands the checks this folder (:func:`environment`, contract.ANSWER_KEYS_ENV);
course_lib never imports it. These are reference computations, so they live only on the
instructor's side: the student package (course_lib) never holds them, the grader's sandbox hides
this folder from students' processes, and self-checks use the answers recorded from them
(``python -m autograder record-answers``). Assignments whose checks need no computed answer (the
expected crops of catdog_warp come from the scene's ground truth; their spec says
``answers="scene"``) have no module here.
"""

from __future__ import annotations

from pathlib import Path

from course_lib import contract

#: This folder. In a grading it is the grader's private copy (autograder.grading.staging), which the
#: student's uid cannot enter.
FOLDER = Path(__file__).resolve().parent


def environment() -> dict[str, str]:
    """The variable that hands these answer keys to the checks of a process and of its children."""
    return {contract.ANSWER_KEYS_ENV: str(FOLDER)}
