"""Parallel sandboxed autograding of the class (``python -m autograder grade``), then the grading
report and grades.csv.

A submission whose notebook is not named as released, or whose timestamp.txt holds no date, is
not run at all: it gets 0 and a reason that says so (autograder.grading.intake). After a run, the grading
report (autograder.results.report) and the LMS export grades.csv (autograder.term.export) are written again
from everything graded so far, so a partial run (one student, one assignment) drops no row.
One submission is graded by autograder.grading.pipeline; its result is recorded by autograder.results.store.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor

from autograder import config
from autograder.grading import fork_server
from autograder.grading.pipeline import grade_submission
from autograder.results import gradebook, store
from autograder.results.grade_result import GradeResult
from autograder.results.submissions import Submission, find_submissions
from autograder.term.release import assignments_in, prepare_course, release


class _Progress:
    def __init__(self, total: int, stream=sys.stderr):
        self.total, self.done, self.stream, self.lock = total, 0, stream, threading.Lock()
        self.started = time.monotonic()

    def update(self, result: GradeResult) -> None:
        with self.lock:
            self.done += 1
            width = 30
            filled = int(width * self.done / max(1, self.total))
            bar = "#" * filled + "." * (width - filled)
            self.stream.write(f"[{bar}] {self.done}/{self.total} {result.student}/{result.assignment}: "
                              f"{result.score:g}/{result.max_score:g} {result.status} ({result.seconds:g} s, "
                              f"{time.monotonic() - self.started:.0f} s elapsed)\n")
            self.stream.flush()


def grade(course_dir, assignment: str | None = None, workers: int = 1, force: bool = False,
          progress: bool = True, student: str | None = None) -> list[GradeResult]:
    """Autograde every submission (or one assignment's, one student's), then write the grading
    report and grades.csv again from everything graded so far.

    Unchanged submissions that were graded before are not graded again unless force=True; their
    recorded scores go into the gradebook again with the late penalty of today's due dates.
    Returns the results of the submissions found, in (student, assignment) order.
    """
    from autograder.results import report
    from autograder.term import export, late
    from course_lib.ros import rosenv

    course = prepare_course(course_dir)
    course_config = config.load(course)
    late.check_settings(course_config, assignments_in(course))
    subs = find_submissions(course, assignment, student)
    if not subs and (assignment or student):
        raise ValueError(f"No submission in {course / 'submitted'} matches --student {student or '(any)'} "
                         f"--assignment {assignment or '(any)'}; the submissions there: "
                         f"{', '.join(s.key for s in find_submissions(course)) or 'none'}")
    known = set()
    if (course / "gradebook.db").exists():
        with gradebook.open_gradebook(course) as gb:
            known = {a.name for a in gb.assignments}
    missing = sorted({s.assignment for s in subs} - known)
    if missing:
        release(course, missing)  # records the assignments (and their hidden tests) in the gradebook
    results: dict[str, GradeResult] = {}
    todo = []
    for sub in subs:
        cached = None if force else store.cached_result(course, sub)
        if cached is not None:
            store.record_in_gradebook(course, cached, course_config)
            results[sub.key] = cached
        else:
            todo.append(sub)
    bar = _Progress(len(todo)) if progress and todo else None
    store_lock = threading.Lock()

    def work(sub: Submission) -> GradeResult:
        with rosenv.reserve_domain_id() as reservation:
            result = grade_submission(sub, course, reservation.domain_id)
        with store_lock:
            store.save_result(course, result, course_config)
        if bar:
            bar.update(result)
        return result

    with fork_server.serving() if todo else contextlib.nullcontext(), \
            ThreadPoolExecutor(max_workers=max(1, workers)) as pool:
        for sub, result in zip(todo, pool.map(work, todo), strict=True):
            results[sub.key] = result
    ordered = [results[s.key] for s in subs]
    report.write_report(course, ordered)
    export.export(course)
    return ordered
