"""The answers a check compares a student's results with: the grader's, or recorded from the grader's.

A check asks ``ctx.expected("average_brightness", image)``. Where the answer comes from depends on
how the check runs (contract.ANSWERS_ENV, set by runner.execute):

- ``graded`` (the grader, fresh seeds): the grader's answer key, the function of that name in
  ``<assignment>.py`` of the folder the grader hands the checks (contract.ANSWER_KEYS_ENV: its
  own private copy of ``autograder/answers/``). The key lives only on the instructor's side:
  students' environments never hold it, the student's processes never get the variable, and the
  grader's sandbox hides the folder from them. course_lib never imports the grader.
- ``selfcheck`` (the student's notebook, the fixed self-check seed): the answers the key gave for
  exactly those inputs, recorded as data in ``course_lib/checks/recorded/<assignment>.json``.
  A self-check and a graded run of the same input therefore compare with the same number.
- ``record`` (``python -m autograder record-answers``): graded, and every answer is also written
  to the file named by contract.RECORD_ANSWERS_ENV, from which the recorded answers are made.

Inputs are keyed by their content (dtype, shape and bytes of each argument), so the order in
which a check asks does not matter.
"""

from __future__ import annotations

import hashlib
import json
import os
import runpy
from pathlib import Path

from course_lib import contract

MODES = ("selfcheck", "graded", "record")
RECORDED = Path(__file__).resolve().parent / "recorded"


class MissingAnswer(LookupError):
    """A self-check asked for an answer that was not recorded (its inputs changed since)."""


def input_key(*args) -> str:
    """A digest of the arguments' content: dtype, shape and bytes of each (numpy arrays or scalars)."""
    import numpy as np

    digest = hashlib.sha256()
    for arg in args:
        array = np.ascontiguousarray(np.asarray(arg))
        digest.update(f"{array.dtype.str}{array.shape}".encode())
        digest.update(array.tobytes())
    return digest.hexdigest()[:32]


def recorded_path(assignment: str) -> Path:
    return RECORDED / f"{assignment}.json"


class AnswerKey:
    """Where one check process gets its expected answers (see the module docstring)."""

    def __init__(self, assignment: str, mode: str | None = None):
        self.assignment = assignment
        self.mode = mode or os.environ.get(contract.ANSWERS_ENV, "selfcheck")
        if self.mode not in MODES:
            raise ValueError(f"{contract.ANSWERS_ENV}={self.mode!r}: expected one of {', '.join(MODES)}")
        self._key: dict | None = None
        self._recorded: dict | None = None

    def expected(self, question: str, *args):
        """The right answer of `question` (a function name of the contract) for these arguments."""
        if self.mode == "selfcheck":
            return self._lookup(question, input_key(*args))
        answer = self._answer_key()[question](*args)
        if self.mode == "record":
            with open(os.environ[contract.RECORD_ANSWERS_ENV], "a") as handle:
                handle.write(json.dumps({"assignment": self.assignment, "question": question,
                                         "key": input_key(*args), "answer": answer}) + "\n")
        return answer

    def _answer_key(self) -> dict:
        """The functions of the assignment's answer key, from the folder the grader handed over."""
        if self._key is None:
            folder = os.environ.get(contract.ANSWER_KEYS_ENV)
            path = Path(folder or ".") / f"{self.assignment}.py"
            if not folder or not path.is_file():
                raise RuntimeError(f"The grader's answer key of {self.assignment} is not here "
                                   f"({contract.ANSWER_KEYS_ENV}={folder or ''}): graded checks run on the "
                                   "instructor's side, where the grader hands them its autograder/answers/")
            self._key = runpy.run_path(str(path))
        return self._key

    def _lookup(self, question: str, key: str):
        if self._recorded is None:
            path = recorded_path(self.assignment)
            self._recorded = json.loads(path.read_text())["answers"] if path.is_file() else {}
        try:
            return self._recorded[question][key]
        except KeyError:
            raise MissingAnswer(f"no recorded answer of {question} for this input: the self-check's inputs changed "
                                f"since its answers were recorded. Instructor: run `python -m autograder "
                                f"record-answers {self.assignment}` in the course repository") from None


def merge_recording(lines_file: Path) -> list[Path]:
    """Write the answers recorded in `lines_file` (one JSON object a line) into the recorded files,
    replacing each assignment's earlier answers; return the files written."""
    by_assignment: dict[str, dict] = {}
    for line in Path(lines_file).read_text().splitlines():
        entry = json.loads(line)
        answers = by_assignment.setdefault(entry["assignment"], {})
        answers.setdefault(entry["question"], {})[entry["key"]] = entry["answer"]
    written = []
    for assignment, answers in sorted(by_assignment.items()):
        path = recorded_path(assignment)
        path.parent.mkdir(exist_ok=True)
        ordered = {question: dict(sorted(keys.items())) for question, keys in sorted(answers.items())}
        path.write_text(json.dumps({"assignment": assignment, "answers": ordered}, indent=1) + "\n")
        written.append(path)
    return written
