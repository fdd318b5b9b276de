"""The graded assignments, one file each: ``course_lib/checks/assignments/<name>.py`` holds its spec
(``SPEC``, a course_lib.checks.spec.Assignment), the words of its notebook and its checks.

Adding an assignment is adding its file (and its reference packages in assignments/reference_ws/src,
and an answer key in autograder/answers/ where its checks take answers from one): every file of this
folder is an assignment, found by :func:`discover`. A notebook imports its file as
``from course_lib.checks import <name> as checks`` (course_lib.checks resolves the name here).
"""

from __future__ import annotations

import importlib
import pkgutil
from types import ModuleType

from course_lib.checks.spec import Assignment


def module(name: str) -> ModuleType:
    """The module of an assignment (its spec, its notebook's words, its checks)."""
    return importlib.import_module(f"{__name__}.{name}")


def discover() -> dict[str, Assignment]:
    """Every assignment of this package's folders (``__path__``), in the order the course teaches them."""
    specs = []
    for info in pkgutil.iter_modules(__path__):
        found = module(info.name).SPEC
        if found.name != info.name:
            raise ValueError(f"checks/assignments/{info.name}.py holds the spec of {found.name!r}: name them alike")
        specs.append(found)
    return {found.name: found for found in sorted(specs, key=lambda found: (found.lesson, found.name))}


#: Every graded assignment, in the order the course teaches them.
ASSIGNMENTS: dict[str, Assignment] = discover()


def spec(name: str) -> Assignment:
    """The spec of an assignment; KeyError naming the assignments there are."""
    if name not in ASSIGNMENTS:
        raise KeyError(f"no graded assignment {name!r}; the assignments are {sorted(ASSIGNMENTS)}")
    return ASSIGNMENTS[name]
