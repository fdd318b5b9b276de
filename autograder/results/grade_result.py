"""The result of grading one submission, as recorded (autograder.json) and reported."""

from __future__ import annotations

import dataclasses


@dataclasses.dataclass
class GradeResult:
    student: str
    assignment: str
    digest: str
    score: float = 0.0
    max_score: float = 0.0
    cells: list[dict] = dataclasses.field(default_factory=list)
    status: str = "graded"       # graded | failed (the notebook could not be run to the end)
    reason: str = ""             # for the student (the feedback shows it)
    detail: str = ""             # for the instructor only (the fix, nbgrader's log): the grading report
    seconds: float = 0.0
    isolation: str = ""
    from_cache: bool = False     # True: an earlier run's result (the submission did not change)
    kernel_uid: int | None = None  # the uid the student's code ran as (root isolation only)
    steps: dict = dataclasses.field(default_factory=dict)  # seconds of each pipeline step, by name
    # The build and checks run while the notebook ran (autograder.grading.early_checks): True when they
    # counted, False when the notebook wrote other files and they ran again, None when not tried.
    checked_early: bool | None = None
    # The workspace build of an identical workspace was copied (autograder.builds.caches.WorkspaceBuilds).
    build_reused: bool = False

    @classmethod
    def from_dict(cls, data: dict) -> GradeResult:
        """A result as recorded (autograder.json), also one written by an older grader."""
        names = {field.name for field in dataclasses.fields(cls)}
        return cls(**{key: value for key, value in data.items() if key in names})
