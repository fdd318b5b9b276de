"""What the hub's grading service does with one queued submission, and with the feedback of those
graded (root; coursehub.grading_service runs these in its threads).

- :func:`grade`: the submission copied from inbound/ to submitted/ (coursehub.inbound), then its
  result: the one recorded for these very files (the service was stopped after recording it),
  else that of a submission with the same content graded before (the same work handed in
  again, or by another student: graded once), else a grading in the grader's sandbox
  (autograder.grading.pipeline). The result goes into the gradebook and the grader's records as the
  instructor's grade run writes them, so that run later finds it and grades nothing again.
- :func:`release`: the feedback of graded submissions of one assignment (nbgrader's
  generate_feedback, in this process) released into the exchange as ``nbgrader release_feedback``
  does, so that Fetch Feedback in the student's Assignments panel shows it; then the grading
  report and grades.csv are written again.
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import shutil
from datetime import datetime, timezone
from pathlib import Path

from autograder import config
from autograder.results import report, store
from autograder.results.submissions import PER_SUBMISSION_FILES, Submission, submission_digest
from autograder.sandbox import untrusted
from autograder.term import export
from coursehub import inbound
from coursehub.accounts import chown_tree
from coursehub.submit_queue import Row, SubmitQueue


def grade(course, queue: SubmitQueue, row: Row, uid: int | None, one_at_a_time=None) -> None:
    """Collect, grade (or reuse a grading of the same content) and record one claimed row of the
    student whose uid is `uid` (None: no longer on the roster); a submission that is not taken
    (autograder.sandbox.untrusted) is refused with its reason.
    `one_at_a_time(content)`: a lock held from looking for a grading of the same content to
    recording this one (workers given the same files grade them once); None: no other worker."""
    course_dir = course.course_dir
    folder = inbound.inbound(course.exchange, course.course_id) / row.entry
    try:
        if uid is None:
            raise untrusted.Refused(f"{row.student} is no longer a student of this course, so the submission was not "
                                    "graded.")
        collected = inbound.collect(folder, row.student, row.assignment, uid, course_dir)
    except untrusted.Refused as refusal:
        queue.refuse(row.id, str(refusal))
        inbound.set_aside(folder, row.id, course_dir)
        return
    sub = Submission(row.student, row.assignment, collected)
    content = submission_digest(sub, course_dir, content_only=True)
    with one_at_a_time(content) if one_at_a_time else contextlib.nullcontext():
        _grade_collected(course, queue, row, sub, content)


def _grade_collected(course, queue: SubmitQueue, row: Row, sub: Submission, content: str) -> None:
    from autograder.grading.pipeline import grade_submission
    from course_lib.ros import rosenv

    course_dir = course.course_dir
    course_config = config.load(course_dir)
    result, reused_from = store.cached_result(course_dir, sub), None
    if result is not None:  # recorded before the service stopped: record it again, grade nothing
        store.record_in_gradebook(course_dir, result, course_config)
    else:
        result, reused_from = _same_content(course_dir, queue, sub, content)
        if result is None:
            with rosenv.reserve_domain_id() as reservation:
                result = grade_submission(sub, course_dir, reservation.domain_id)
        store.save_result(course_dir, result, course_config)
    chown_tree(course_dir, course.instructor)  # the instructor's formgrader and commands write here too
    if result.status == "failed":  # no graded notebook, so no feedback page: its reason is on the student's page
        queue.failed(row.id, result.reason.strip() or "it could not be graded; your instructor will grade it.",
                     content=content, score=result.score, max_score=result.max_score)
        return
    queue.graded(row.id, content, result.score, result.max_score, "", reused_from)


def _same_content(course_dir: Path, queue: SubmitQueue, sub: Submission, content: str):
    """The result of an earlier submission with the same content, as this submission's (its graded
    notebooks copied); (None, None) when there is none to reuse."""
    for earlier in queue.same_content(sub.assignment, content):
        folder = course_dir / "submitted" / earlier.student / sub.assignment
        other = Submission(earlier.student, sub.assignment, folder)
        recorded = store.recorded_results(course_dir, sub.assignment, earlier.student)
        # Only while the earlier student's recorded result is still of those files.
        if not recorded or not folder.is_dir() or submission_digest(other, course_dir, content_only=True) != content \
                or recorded[0].digest != submission_digest(other, course_dir):
            continue
        graded = course_dir / "autograded" / earlier.student / sub.assignment
        target = course_dir / "autograded" / sub.student / sub.assignment
        if graded != target:  # (the same student's earlier submission: its graded notebooks are there)
            if target.exists():
                shutil.rmtree(target)
            shutil.copytree(graded, target, symlinks=True)
        for name in PER_SUBMISSION_FILES:  # this submission's time and feedback name
            if (sub.path / name).is_file():
                shutil.copyfile(sub.path / name, target / name)
        note = f"The same files as {earlier.student}'s submission {earlier.id}: its grading was reused."
        result = dataclasses.replace(recorded[0], student=sub.student, digest=submission_digest(sub, course_dir),
                                     from_cache=False, detail=f"{recorded[0].detail}\n{note}".strip())
        return result, earlier.id
    return None, None


def scores_only(rules: config.SubmitRules, duedate: datetime | None) -> bool:
    """Whether feedback written now leaves out the checks' reasons (before the due date, when the
    assignment's rules say so). `duedate` is naive UTC; without one, it is always before it."""
    now = datetime.now(timezone.utc).replace(tzinfo=None)
    return not rules.reasons_before_due and (duedate is None or now <= duedate)


def release(course, assignment: str, rows: list[Row], hide_reasons: bool) -> dict[int, str]:
    """Write the feedback of these graded rows of one assignment and release it to their students;
    return the rows whose feedback could not be written or released, with the error (the others
    are released: one row's failure holds up no other)."""
    import traceback

    from autograder.term import feedback

    course_dir = course.course_dir
    failures = {}  # student -> error
    students = sorted({row.student for row in rows})
    try:
        feedback.write_in_process(course_dir, assignment, students, scores_only=hide_reasons)
        written = students
    except Exception:  # noqa: BLE001 - one page broke the batch: each student's alone, to find whose
        written = []
        for student in students:
            try:
                feedback.write_in_process(course_dir, assignment, [student], scores_only=hide_reasons)
                written.append(student)
            except Exception:  # noqa: BLE001 - that student's failure, reported to the service
                failures[student] = traceback.format_exc()
    for student in written:
        try:
            _release_one(course, assignment, student)
        except Exception:  # noqa: BLE001 - that student's failure, reported to the service
            failures[student] = traceback.format_exc()
    report.write_report(course_dir)  # the instructor's files, once for the batch
    export.export(course_dir)
    chown_tree(course_dir, course.instructor)
    return {row.id: failures[row.student] for row in rows if row.student in failures}


def _release_one(course, assignment: str, student: str) -> None:
    """What nbgrader's release_feedback does for one student: each feedback page to
    ``<exchange>/<course>/feedback/<hash of the submission's secret and the notebook>.html`` (the
    name the student's Fetch Feedback looks for), readable by all, the instructor's like the folder
    (whose later release_feedback replaces them)."""
    import pwd

    from nbgrader.utils import notebook_hash

    owner = pwd.getpwnam(course.instructor)
    source = course.course_dir / "feedback" / student / assignment
    target = inbound.inbound(course.exchange, course.course_id).parent / "feedback"
    if not target.is_dir():
        target.mkdir(mode=0o711)  # nbgrader's mode: students reach a page by its name only
        os.chown(target, owner.pw_uid, owner.pw_gid)
    secret = (source / "submission_secret.txt").read_text()
    for page in sorted(source.glob("*.html")):
        name = f"{notebook_hash(secret=secret, notebook_id=page.stem)}.html"
        temporary = target / f".{name}.tmp"
        shutil.copyfile(page, temporary)
        os.chmod(temporary, 0o644)
        os.chown(temporary, owner.pw_uid, owner.pw_gid)
        os.replace(temporary, target / name)


def duedate(course_dir: Path, assignment: str) -> datetime | None:
    """The assignment's due date in the gradebook (naive UTC), or None."""
    from nbgrader.api import MissingEntry

    from autograder.results import gradebook

    with gradebook.open_gradebook(course_dir) as gb:
        try:
            return gb.find_assignment(assignment).duedate
        except MissingEntry:
            return None
