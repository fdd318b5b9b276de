"""What an assignment's spec is: what the notebook builder (assignments/build.py), the checks, the
grader and the tests read about an assignment. Each assignment's file in
``course_lib/checks/assignments/`` holds one (``SPEC``), its notebook's words and its checks.

An assignment is a colcon workspace beside its notebook (``ros2_ws/src/<package>/``), multiple-choice
questions answered in the notebook (``q3 = "b"``), or both. Its spec says which packages the student
writes and the executables each installs (what ``ros2 run`` offers), which module holds the plain
functions the checks call without a build, its questions, where the expected answers of its checks
come from, and the words of its notebook that are its own (assignments/build.py writes the rest: the
packages' cells, the imports, a markdown and an answer cell per question, a test cell per check).
Its reference packages are in ``assignments/reference_ws/src/``.
"""

from __future__ import annotations

import dataclasses

from course_lib.checks.multiple_choice import Question


@dataclasses.dataclass(frozen=True)
class NotebookText:
    """The words of an assignment's notebook that are its own.

    Attributes:
        intro: the first cell (markdown): the assignment and its contract, what is graded.
        plain_ros: how its packages come about in plain ROS 2 (ends the packages' introduction; "" without packages).
        checks: each check -> its heading (after "Check N: ") and, optionally, markdown under it.
        imports: more lines of the setup cell.
        names: what the notebook imports from the module of the plain functions (Assignment.functions).
        try_text, try_code: the cell the student tries the functions in, and the line before it.
    """

    intro: str
    checks: dict[str, tuple[str, ...]]
    plain_ros: str = ""
    imports: str = ""
    names: str = ""
    try_text: str = ""
    try_code: str = ""


@dataclasses.dataclass(frozen=True, repr=False)
class Assignment:
    """One graded assignment.

    Attributes:
        name: the assignment's name: its notebook, its file in checks/assignments/, its nbgrader assignment.
        lesson: the lesson it follows ("01b"); the course teaches the assignments in this order.
        packages: each package the student writes -> the executables it installs (none for a
            message package), in build order; {} for an assignment without a workspace (nothing
            is built).
        functions: (package, dotted module) of the plain functions the checks call, or None.
        questions: its multiple-choice questions, the notebook's variable -> the question ({} for none).
        answers: where the checks' expected answers come from: "key" (the grader's answer key,
            autograder/answers/<name>.py, recorded for self-checks in checks/recorded/<name>.json),
            "secret" (the grader's answer key, asked only when graded and never recorded: a quiz's
            key would be its answers) or "scene" (the ground truth of the scenes the checks draw).
        notebook: the words of its notebook that are its own.
    """

    name: str
    lesson: str
    packages: dict[str, tuple[str, ...]]
    notebook: NotebookText
    functions: tuple[str, str] | None = None
    questions: dict[str, Question] = dataclasses.field(default_factory=dict)
    answers: str = "scene"

    def __repr__(self) -> str:  # short: a notebook shows it for checks.selfcheck
        return f"Assignment({self.name!r})"

    def executables(self, package: str) -> tuple[str, ...]:
        return self.packages[package]

    def executable(self, package: str) -> str:
        """The one executable of `package` (ValueError when it installs none or several)."""
        executables = self.packages[package]
        if len(executables) != 1:
            raise ValueError(f"package {package!r} of {self.name} installs {len(executables)} executables, not one")
        return executables[0]

    # What the notebook calls (``checks.selfcheck("values")``): each assignment's module binds them,
    # ``selfcheck, grade = SPEC.selfcheck, SPEC.grade``.
    def selfcheck(self, name: str) -> None:
        """Run check `name` with the self-check seed and print what is right and wrong."""
        from course_lib.checks import runner

        return runner.selfcheck(self.name, name)

    def grade(self, name: str) -> float:
        """Run check `name` with a fresh seed (grading)."""
        from course_lib.checks import runner

        return runner.grade(self.name, name)
