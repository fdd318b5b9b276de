"""The graded assignments, one spec each: what the notebook builder (assignments/build.py), the checks,
the grader and the tests read about an assignment.

An assignment is a colcon workspace beside its notebook (``ros2_ws/src/<package>/``). Its spec says
which packages the student writes and the executables each installs (what ``ros2 run`` offers),
which module holds the plain functions the checks call without a build, and where the expected
answers of its checks come from. Its checks and their points are in
``course_lib/checks/<name>.py``; its reference packages in ``assignments/reference_ws/src/``.
"""

from __future__ import annotations

import dataclasses

#: The workspace folder beside an assignment's notebook.
WORKSPACE = "ros2_ws"


@dataclasses.dataclass(frozen=True)
class Assignment:
    """One graded assignment.

    Attributes:
        name: the assignment's name: its notebook, its checks module, its nbgrader assignment.
        packages: each package the student writes -> the executables it installs (none for a
            message package), in build order.
        functions: (package, dotted module) of the plain functions the checks call, or None.
        answers: where the checks' expected answers come from: "key" (the grader's answer key,
            autograder/answers/<name>.py, recorded for self-checks in checks/recorded/<name>.json)
            or "scene" (the ground truth of the scenes the checks draw).
    """

    name: str
    packages: dict[str, tuple[str, ...]]
    functions: tuple[str, str] | None = None
    answers: str = "scene"

    def executables(self, package: str) -> tuple[str, ...]:
        return self.packages[package]


#: Every graded assignment, in the order the course teaches them.
ASSIGNMENTS: dict[str, Assignment] = {spec.name: spec for spec in (
    Assignment("pubsub", {"tutorial_interfaces": (), "pubsub": ("topic_publisher", "topic_subscriber")}),
    Assignment("brightness", {"brightness": ("brightness_node",)},
               functions=("brightness", "brightness.brightness_node"), answers="key"),
    Assignment("catdog_warp", {"catdog_interfaces": (), "webcam": ("image_publisher",),
                               "readmarker": ("marker_reader",)},
               functions=("readmarker", "readmarker.crop")),
)}


def spec(name: str) -> Assignment:
    """The spec of an assignment; KeyError naming the assignments there are."""
    if name not in ASSIGNMENTS:
        raise KeyError(f"no graded assignment {name!r}; the assignments are {sorted(ASSIGNMENTS)}")
    return ASSIGNMENTS[name]
