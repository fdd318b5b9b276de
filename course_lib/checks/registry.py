"""The registry of graded checks: what a check is (points, time, what it checks).

A check is a function in ``course_lib/checks/assignments/<assignment>.py`` decorated with :func:`check`,
which gives it its points and its time limit; its docstring's first line says what it checks::

    @check(points=4, timeout=40)
    def values(ctx):
        \"\"\"average_brightness returns the floor of the mean byte for colour and grey images.\"\"\"
        for outcome, expected in ...:
            ctx.item(outcome.value == expected, "...")


How a check runs: course_lib.checks.runner.
"""

from __future__ import annotations

import dataclasses
import importlib


@dataclasses.dataclass(frozen=True)
class Check:
    """One graded check of an assignment.

    Attributes:
        assignment: the assignment's name (its module's name in course_lib/checks/assignments/).
        name: the check's name, unique in the assignment (what selfcheck()/grade() take).
        points: the most it earns.
        timeout: seconds the check may take, student processes included.
        description: the docstring's first line: what the check checks.
        function: the check itself, called with a Context.
    """

    assignment: str
    name: str
    points: float
    timeout: float
    description: str
    function: object


_REGISTRY: dict[str, dict[str, Check]] = {}


def check(points: float, timeout: float):
    """Register a check function of a ``course_lib.checks`` module (see the module docstring)."""
    def register(function):
        assignment = function.__module__.rsplit(".", 1)[-1]
        doc = (function.__doc__ or "").strip().splitlines()
        if not doc:
            raise ValueError(f"Check {function.__name__} has no docstring: its first line says what it checks")
        spec = Check(assignment, function.__name__, float(points), float(timeout), doc[0], function)
        _REGISTRY.setdefault(assignment, {})[spec.name] = spec
        return function
    return register


def checks_of(assignment: str) -> dict[str, Check]:
    """The checks of an assignment, in the order they are defined (imports the checks module)."""
    importlib.import_module(f"course_lib.checks.assignments.{assignment}")
    return dict(_REGISTRY.get(assignment, {}))


def get_check(assignment: str, name: str) -> Check:
    checks = checks_of(assignment)
    if name not in checks:
        raise KeyError(f"{assignment} has no check {name!r}; its checks are {sorted(checks)}")
    return checks[name]
