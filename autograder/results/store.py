"""The recorded results (COURSE_DIR/autograder/<student>/<assignment>/autograder.json), the course
gradebook's copy of their scores, and the cache of unchanged submissions."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

from autograder.results import gradebook
from autograder.results.grade_result import GradeResult
from autograder.results.submissions import Submission, submission_digest

STATE_FILE = "autograder.json"


def state_dir(course: Path, student: str, assignment: str) -> Path:
    """Where the grader keeps a submission's result and log: COURSE_DIR/autograder/<student>/<assignment>/
    (not in autograded/, whose files nbgrader copies into the student's feedback)."""
    return Path(course) / "autograder" / student / assignment


def save_result(course: Path, result: GradeResult, course_config) -> None:
    """Record a result in the course gradebook (autograder.results.gradebook) and beside the notebook."""
    record_in_gradebook(course, result, course_config)
    target = state_dir(course, result.student, result.assignment)
    target.mkdir(parents=True, exist_ok=True)
    (target / STATE_FILE).write_text(json.dumps(dataclasses.asdict(result), indent=1))


def record_in_gradebook(course: Path, result: GradeResult, course_config) -> None:
    """The result's scores, the submission time and the late penalty, in the course gradebook (a
    result from an earlier run: the time and penalty only, when the gradebook has its scores)."""
    scores = {} if result.status == "failed" else {(c["notebook"], c["cell"]): c["auto_score"] for c in result.cells}
    try:
        timestamp = gradebook.submitted_timestamp(course / "submitted" / result.student / result.assignment)
    except ValueError:  # intake.check failed the submission for it, with the fix
        timestamp = None
    result.max_score = gradebook.record(course, result.student, result.assignment, scores, timestamp, course_config,
                                        earlier=result.from_cache)


def cached_result(course: Path, sub: Submission) -> GradeResult | None:
    path = state_dir(course, sub.student, sub.assignment) / STATE_FILE
    try:
        result = GradeResult.from_dict(json.loads(path.read_text()))
        if result.digest == submission_digest(sub, course):
            result.from_cache = True
            return result
    except (OSError, ValueError, KeyError, TypeError):
        pass
    return None


def recorded_results(course, assignment: str | None = None, student: str | None = None) -> list[GradeResult]:
    """Every result recorded so far (COURSE_DIR/autograder/<student>/<assignment>/autograder.json),
    or one assignment's, one student's; sorted by student and assignment."""
    import glob

    student_part = glob.escape(student) if student else "*"
    assignment_part = glob.escape(assignment) if assignment else "*"
    pattern = f"{student_part}/{assignment_part}/{STATE_FILE}"
    results = []
    for path in sorted((Path(course) / "autograder").glob(pattern)):
        try:
            results.append(GradeResult.from_dict(json.loads(path.read_text())))
        except (OSError, ValueError, TypeError) as error:
            raise ValueError(f"{path} cannot be read ({error}): delete it and grade that submission again "
                             f"(python -m autograder grade COURSE_DIR --student {path.parent.parent.name} "
                             f"--assignment {path.parent.name} --force)") from None
    return results
