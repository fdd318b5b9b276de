"""Does the autograder grade a zoo of submissions right, in parallel, and survive them all?

One module-scoped grading run (2 workers) is shared by the tests: release the brightness,
pubsub and services_actions assignments into a fresh course directory, hand in the zoo
(tests/support/zoo/brightness.py: the reference solution with a hostile cell, and hostile submissions;
tests/support/zoo/pubsub.py: mistakes in the packages; tests/support/zoo/services_actions.py: the reference, the
untouched release and the typical mistakes of a service and an action server; tests/support/zoo/pillar.py:
the reference of the drive to the pillar and its typical mistakes), grade, and check
each grade, its reason (for the package mistakes on the feedback page), the submitted files,
leftover processes, and a second (cached) run.
"""

from __future__ import annotations

import hashlib
import os
import time
from pathlib import Path

import psutil
import pytest
from support import course as course_support
from support import zoo
from support.zoo import brightness as brightness_zoo
from support.zoo import pillar as pillar_zoo
from support.zoo import pubsub as pubsub_zoo
from support.zoo import services_actions as services_actions_zoo

# The shared grading run (sixteen submissions, 2 workers) happens in the first test's set-up.
pytestmark = [pytest.mark.slow, pytest.mark.timeout(1500)]


def _total(assignment: str) -> float:
    """The most an assignment earns: the points of its checks (its spec's file in course_lib/checks/assignments/)."""
    from course_lib.checks import registry

    return sum(check.points for check in registry.checks_of(assignment).values())


def _hashes(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def graded(tmp_path_factory):
    from autograder.term import grade

    course = course_support.released_course(tmp_path_factory, tmp_path_factory.mktemp("zoo_course"),
                                            ["brightness", "pubsub", "services_actions", "pillar"])
    course_support.seed_interface_cache(tmp_path_factory, course, ["pubsub", "services_actions"])
    entries = {k: v for k, v in brightness_zoo.entries(str(course)).items() if v.get("level") != "check"}
    for student, entry in entries.items():
        zoo.submit(course, student, "brightness", entry["edits"])
    for student, entry in pubsub_zoo.entries().items():
        zoo.submit(course, student, "pubsub", entry["edits"])
    for student, entry in services_actions_zoo.entries(str(course)).items():
        zoo.submit(course, student, "services_actions", entry["edits"])
    for student, entry in pillar_zoo.entries(str(course)).items():
        zoo.submit(course, student, "pillar", entry["edits"])
    before = _hashes(course / "submitted")
    started = time.monotonic()
    results = grade.grade(course, workers=2, progress=False)
    seconds = time.monotonic() - started
    yield {"course": course, "entries": entries, "results": {r.student: r for r in results},
           "before": before, "seconds": seconds}


def _outputs(course: Path, student: str) -> str:
    return zoo.graded_outputs(course, student, "brightness")


def _check_scores(result) -> dict[str, float]:
    return {cell["cell"].removeprefix("check_"): cell["auto_score"] for cell in result.cells}


def _matches(expected, actual) -> bool:
    if expected is None:
        return True
    if isinstance(expected, tuple):
        return expected[0] - 1e-6 <= actual <= expected[1] + 1e-6
    return abs(actual - expected) < 1e-6


@pytest.mark.parametrize("student", [k for k, v in brightness_zoo.entries("").items() if v.get("level") != "check"])
def test_zoo_entry_gets_its_expected_score_and_reason(graded, student):
    """Each zoo submission gets its expected points per check, and its notebook says why."""
    result = graded["results"][student]
    entry = graded["entries"][student]
    if entry.get("failed"):
        assert result.status == "failed" and result.score == 0
        assert entry["reason"] in result.reason.lower()
        return
    assert result.status == "graded", result.reason
    scores = _check_scores(result)
    for check in ("values", "node"):
        outputs = _outputs(graded["course"], student)
        assert _matches(entry[check], scores[check]), f"{check}: {scores}\n{outputs[-3000:]}"
    reasons = entry["reason"] if isinstance(entry["reason"], tuple) else (entry["reason"],)
    text = _outputs(graded["course"], student)
    assert any(reason in text for reason in reasons), (reasons, text[-3000:])


#: (assignment, zoo module) of the submissions graded per check with the reasons on the feedback page.
PACKAGE_ZOOS = [("pubsub", pubsub_zoo), ("services_actions", services_actions_zoo), ("pillar", pillar_zoo)]


@pytest.mark.parametrize("assignment, student", [(a, s) for a, z in PACKAGE_ZOOS for s in sorted(z.entries(""))])
def test_package_submission_gets_its_scores_with_its_reasons_on_the_feedback_page(graded, assignment, student):
    """A mistake in a package (a message field, a missing <depend>, a wrong entry point, a build
    error, a service or action server that does not keep the contract) costs the points of the
    checks it breaks, and the student's feedback page names it; the reference gets every point."""
    from autograder.term import feedback

    entry = dict(PACKAGE_ZOOS)[assignment].entries(str(graded["course"]))[student]
    result = graded["results"][student]
    assert result.status == "graded", result.reason
    scores = _check_scores(result)
    outputs = zoo.graded_outputs(graded["course"], student, assignment)
    for check, expected in entry["scores"].items():
        assert _matches(expected, scores[check]), f"{check}: {scores}\n{outputs[-3000:]}"
    feedback.write_feedback(graded["course"], student=student, assignment=assignment)
    page = (graded["course"] / "feedback" / student / assignment / f"{assignment}.html").read_text()
    page = page.replace("&#39;", "'").replace("&quot;", '"')
    for reason in entry["reasons"]:
        assert reason in page, (reason, outputs[-3000:])
    for phrase in entry.get("absent", []):
        assert phrase not in page, (phrase, outputs[-3000:])


def test_reference_solution_gets_full_marks_beside_its_own_hostile_cell(graded):
    """The reference solution with a hostile cell, graded next to hostile submissions, gets every
    point: what the cell tries changes nothing."""
    result = graded["results"]["hostile"]
    assert (result.score, result.max_score) == (_total("brightness"), _total("brightness"))


def test_hostile_submission_is_contained(graded):
    """No network, no course directory, no gradebook, and its leftovers do not survive grading."""
    text = _outputs(graded["course"], "hostile")
    assert "NETWORK: blocked" in text
    assert "COURSE: hidden" in text
    assert "GRADEBOOK: denied" in text or "GRADEBOOK: not found" in text
    assert "BACKGROUND: started" in text
    if os.geteuid() == 0:  # the kernel's uid owns only its working folder, not the notebook's
        assert "SYMLINK: denied" in text
    leftovers = [p.info for p in psutil.process_iter(["pid", "cmdline", "uids"])
                 if p.info["cmdline"] and ("sleep" in p.info["cmdline"][0] and "1234" in p.info["cmdline"])]
    assert leftovers == []


def test_no_process_of_a_grading_uid_survives(graded):
    """Every process that ran as one of this run's worker uids is gone once grading returns.

    A worker uid is KERNEL_UID_BASE plus the ROS domain id the submission had reserved; once the
    domain is free, a grading run of a parallel test may reserve it and run its kernel under the
    same uid (which failed this test in a suite run). So each domain is reserved, once its other
    user is done with it, while its uids are looked at."""
    from autograder.grading.pipeline import EARLY_UID_OFFSET, KERNEL_UID_BASE

    uids = {r.kernel_uid for r in graded["results"].values() if r.kernel_uid is not None}
    if os.geteuid() == 0:
        assert uids, "as root every submission runs as a worker uid of its own"
    alive = []
    for uid in sorted(uids):
        domain = uid - KERNEL_UID_BASE
        with _when_free(domain):
            alive += [p.info for p in psutil.process_iter(["pid", "cmdline", "uids", "status"])
                      if p.info["uids"] and p.info["uids"].real in (uid, uid + EARLY_UID_OFFSET)
                      and p.info["status"] != psutil.STATUS_ZOMBIE]
    assert alive == []


def _when_free(domain: int, backstop: float = 600.0):
    """The reservation of `domain` once it is free: another test's grading holds it for one submission."""
    from course_lib.ros import rosenv

    end = time.monotonic() + backstop
    while True:
        try:
            return rosenv.reserve_domain_id(range(domain, domain + 1))
        except RuntimeError:
            if time.monotonic() > end:
                raise
            time.sleep(0.2)


def test_submitted_files_are_byte_identical(graded):
    """Grading reads the submissions and never writes them."""
    assert _hashes(graded["course"] / "submitted") == graded["before"]


def test_grading_report_lists_every_submission(graded):
    """grading_report.csv has one row per submission with student_id, assignment, score and max_score."""
    import csv

    with open(graded["course"] / "grading_report.csv") as handle:
        rows = list(csv.DictReader(handle))
    assert {r["student_id"] for r in rows} == (set(graded["entries"]) | set(pubsub_zoo.entries())
                                               | set(services_actions_zoo.entries("")) | set(pillar_zoo.entries("")))
    max_scores = {name: f"{_total(name):g}" for name in ("brightness", "pubsub", "services_actions", "pillar")}
    assert all(r["max_score"] == max_scores[r["assignment"]] for r in rows)
    assert {r["student_id"]: float(r["score"]) for r in rows} == {s: r.score for s, r in graded["results"].items()}


def test_second_run_reuses_unchanged_grades(graded):
    """A second grade run grades nothing again and reports the same scores."""
    from autograder.term import grade

    again = grade.grade(graded["course"], workers=2, progress=False)
    assert all(r.from_cache for r in again)
    assert {r.student: r.status for r in again} == {s: r.status for s, r in graded["results"].items()}
    assert {r.student: r.score for r in again} == {s: r.score for s, r in graded["results"].items()}


def test_gradebook_holds_the_scores(graded):
    """The course's SQLite gradebook (nbgrader's API) has each submission's score."""
    from nbgrader.api import Gradebook

    with Gradebook(f"sqlite:///{graded['course'] / 'gradebook.db'}") as gb:
        for student, result in graded["results"].items():
            assert gb.find_submission(result.assignment, student).score == pytest.approx(result.score)
