"""The hub's grading service (root) against what a hostile student can put in the exchange's
inbound/, which every student may write: links (to the instructor's solution, to /etc/shadow, to
another student's submission, to the service's own environment), a linked folder, a FIFO, a hard
link, a folder named to escape (``..``) or for someone who is not a student, a folder in another
student's name, a name with a newline, a notebook that is not JSON, a 300 MB file, 2000 tiny files.
Each is refused or fails within seconds, with its reason on the page of the student who made it
(and on nobody else's); nothing is followed, nothing of the course or the server reaches a student,
and the next good submission is graded and its feedback released.

Real Linux accounts made by ``python -m coursehub create-course``, entries made as the student's
uid, the service's own look, grading and release (coursehub.grading_service.Service), driven one
step at a time. Root only."""

from __future__ import annotations

import os
import secrets
from datetime import datetime, timedelta, timezone
from pathlib import Path

import nbformat
import pytest
from support import zoo
from support.hub import coursehub, why_no_hub
from support.zoo.brightness import SUM

pytestmark = [pytest.mark.hub, pytest.mark.slow, pytest.mark.timeout(600),
              pytest.mark.skipif(why_no_hub() is not None, reason=str(why_no_hub()))]

ASSIGNMENT = "brightness"
SHADOW = Path("/etc/shadow")


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    from coursehub import course as course_settings

    prefix = "hi" + "".join(secrets.choice("abcdefghijkmnpqrstuvwxyz") for _ in range(4))
    hub_dir = Path("/srv") / f"{prefix}-hub"
    roster = tmp_path_factory.mktemp("roster") / "roster.csv"
    roster.write_text(f"id,first_name,last_name\n{prefix}ann,Ann,Test\n{prefix}bob,Bob,Test\n")
    try:
        coursehub(hub_dir, "create-course", str(roster), "--instructor", f"{prefix}i", "--group", f"{prefix}g",
                  "--exchange", str(hub_dir / "exchange"))
        settings = course_settings.load(hub_dir)
        with open(settings.course_dir / "nbgrader_config.py", "a") as handle:
            handle.write(f"c.GradeOnSubmit.assignments = {{{ASSIGNMENT!r}: {{}}}}\n")
        coursehub(hub_dir, "release", ASSIGNMENT)
        yield settings
    finally:
        if (hub_dir / "course.json").exists():
            coursehub(hub_dir, "remove-course")


class Inbound:
    """Entries of inbound/ made as a student's uid, each a second after the one before."""

    def __init__(self, course):
        from autograder.config import COURSE_ID

        self.folder = course.exchange / COURSE_ID / "inbound"
        self.when = datetime.now(timezone.utc) - timedelta(hours=1)

    def hand_in(self, student: str, make, named: str | None = None, name: str | None = None) -> str:
        """An entry of `student`'s (the folder named for `named`, or `name` itself): `make(folder)`
        fills it, then nbgrader's last steps (timestamp, secret, mode 0777)."""
        from coursehub.accounts import as_user

        self.when += timedelta(seconds=1)
        stamp = self.when.strftime("%Y-%m-%d %H:%M:%S.%f %Z")
        name = name or f"{named or student}+{ASSIGNMENT}+{stamp}+{secrets.token_urlsafe(9)}"
        folder = self.folder / name

        def work():
            folder.mkdir()
            (folder / "timestamp.txt").write_text(stamp)
            (folder / "submission_secret.txt").write_text(secrets.token_hex(32))
            make(folder)
            os.chmod(folder, 0o777)

        as_user(student, work)
        return name


def _grade_all(service) -> None:
    """What the service's threads do, one step at a time: look, grade each queued row, release."""
    from coursehub import grading_job

    service.look_once()
    while (row := service.queue.claim()) is not None:
        grading_job.grade(service.course, service.queue, row, service.students().get(row.student))
    service.release_once()


def test_hostile_entries_are_refused_with_reasons_and_the_next_good_one_is_graded(course, tmp_path):
    from coursehub import grading_status
    from coursehub.accounts import as_user
    from coursehub.grading_service import Service
    from coursehub.submit_queue import SubmitQueue

    ann, bob = course.students
    solution = course.course_dir / "source" / ASSIGNMENT / f"{ASSIGNMENT}.ipynb"
    good = nbformat.writes(zoo.edited_notebook(course.course_dir, ASSIGNMENT, [(SUM, f"{SUM}  # bob's own")]))
    notebook = course.course_dir.parent / "notebook.ipynb"  # ann's ordinary notebook, for the entries that hide more
    elsewhere = Path(f"/tmp/{ann}-elsewhere")  # a folder of ann's outside the exchange
    before = sorted(p.name for p in course.course_dir.iterdir())

    def with_notebook(extra):
        def make(folder):
            (folder / f"{ASSIGNMENT}.ipynb").write_text(good)
            extra(folder)
        return make

    def link_as_notebook(target):
        return lambda folder: (folder / f"{ASSIGNMENT}.ipynb").symlink_to(target)

    def workspace_links(folder):
        (folder / "ros2_ws" / "src" / ASSIGNMENT).mkdir(parents=True)
        (folder / "ros2_ws" / "src" / ASSIGNMENT / "setup.py").symlink_to(SHADOW)

    def many_files(folder):
        for n in range(2000):
            (folder / f"f{n:04d}.txt").write_text("x")

    def big_file(folder):
        with open(folder / "recording.bag", "wb") as handle:
            handle.truncate(300 * 1000 * 1000)

    def hard_link(folder):
        (elsewhere / "mine.txt").write_text("ann's")
        os.link(elsewhere / "mine.txt", folder / "notes.txt")

    inbound = Inbound(course)
    service = Service(course, workers=1)
    nbformat.write(nbformat.v4.new_notebook(), notebook)
    as_user(ann, lambda: elsewhere.mkdir(exist_ok=True))
    hostile = {}  # entry -> what ann's page says of it

    def attempt(reason: str, make, **naming) -> None:
        """One hostile entry, handed in and taken by the service on its own (a newer one would
        supersede it while queued)."""
        hostile[inbound.hand_in(ann, make, **naming)] = reason
        _grade_all(service)

    notebook_link = f"'{ASSIGNMENT}.ipynb' in your submission is a symbolic link"
    attempt(notebook_link, link_as_notebook(solution))
    attempt(notebook_link, link_as_notebook(SHADOW))
    attempt(notebook_link, link_as_notebook("/proc/self/environ"))
    attempt(f"'ros2_ws/src/{ASSIGNMENT}/setup.py' in your submission is a symbolic link",
            with_notebook(workspace_links))
    attempt("'other' in your submission is a symbolic link", with_notebook(lambda f: (f / "other").symlink_to(
        inbound.folder)))
    attempt("'node.py' in your submission is a FIFO", with_notebook(lambda f: os.mkfifo(f / "node.py")))
    attempt("'notes.txt' in your submission is a hard link", with_notebook(hard_link))
    attempt("has a control character", with_notebook(lambda f: (f / "a\x1bb.py").write_text("")))
    attempt("more than 100 MB (at 'recording.bag')", with_notebook(big_file))
    attempt("more than 1000 files and folders", with_notebook(many_files))
    attempt("names '..', who is not a student", with_notebook(lambda f: None), named="..")
    attempt("names 'nobody', who is not a student", with_notebook(lambda f: None), named="nobody")
    attempt(f"names '{bob}' but was made by another account", with_notebook(lambda f: None), named=bob)
    attempt("who is not a student", with_notebook(lambda f: None), named=f"{ann}\n")
    attempt("is not named as nbgrader's", with_notebook(lambda f: None), name=f"{ann}+{ASSIGNMENT}")
    attempt(f"'{ASSIGNMENT}.ipynb' is not a Jupyter notebook: it is not valid JSON (Expecting value at line 1, "
            "column 1)", lambda f: (f / f"{ASSIGNMENT}.ipynb").write_text("not { json"))
    linked = f"{ann}+{ASSIGNMENT}+{inbound.when:%Y-%m-%d %H:%M:%S.%f} UTC+linked"
    as_user(ann, lambda: (inbound.folder / linked).symlink_to(elsewhere))
    hostile[linked] = "is not a folder (a link or a file)"
    graded = inbound.hand_in(bob, lambda folder: (folder / f"{ASSIGNMENT}.ipynb").write_text(good))
    _grade_all(service)
    rows = {row.entry: row for row in SubmitQueue(course.course_dir).all()}
    for entry, reason in hostile.items():
        row = rows[entry]
        assert (row.student, row.state) == (ann, "refused" if "JSON" not in reason else "failed"), (entry, row)
        assert reason in row.message, (entry, row.message)
    assert rows[graded].state == "released" and rows[graded].score == rows[graded].max_score > 0, rows[graded]

    ann_page, bob_page = grading_status.page(service.queue, ann), grading_status.page(service.queue, bob)
    assert ann_page.count("<tr class='submission") == len(hostile)
    assert bob_page.count("<tr class='submission") == 1 and ann not in bob_page

    # Nothing was followed: no link and nothing of /etc/shadow or the solution in what root copied,
    # graded or released; no folder outside submitted/<student>/; refused entries are out of inbound/.
    shadow = [line.split(":")[1] for line in SHADOW.read_text().splitlines() if len(line.split(":")[1]) > 8]
    released = [p for p in (course.exchange / course.course_id / "feedback").iterdir()]
    written = [p for folder in ("submitted", "autograded", "feedback") for p in (course.course_dir / folder).rglob("*")]
    assert not [p for p in written + released if p.is_symlink()]
    written += [p for p in course.course_dir.rglob("*") if "refused" not in p.parts and not p.is_symlink()]
    for path in (p for p in written + released if p.is_file() and p.stat().st_size < 10_000_000):
        text = path.read_text(errors="replace")
        assert not any(secret in text for secret in shadow), path
        if path.suffix in (".html", ".ipynb") and ann in str(path):
            assert "BEGIN SOLUTION" not in text, path
    assert sorted(p.name for p in (course.course_dir / "submitted").iterdir()) == [ann, bob]
    assert sorted(p.name for p in (course.course_dir / "submitted" / ann / ASSIGNMENT).iterdir()) == [
        f"{ASSIGNMENT}.ipynb", "submission_secret.txt", "timestamp.txt"]  # the one that is not JSON
    assert set(p.name for p in course.course_dir.iterdir()) - set(before) <= {"submitted", "autograded", "feedback",
                                                                              "grades.csv", "autograder",
                                                                              "grading_report.csv"}
    assert sorted(p.name for p in inbound.folder.iterdir()) == sorted(
        [graded, next(e for e, r in hostile.items() if "JSON" in r)])


def test_the_instructors_collect_takes_no_link_and_no_folder_in_anothers_name(course):
    """nbgrader collect as the instructor (coursehub.checked_collect): ann's newest entries, a link
    to the solution and a folder in bob's name, are left out with their reasons; each student's
    newest acceptable submission is collected, and what was collected before stays."""
    ann, bob = course.students
    inbound = Inbound(course)
    inbound.when += timedelta(hours=2)  # newer than everything handed in before
    ann_before = course.course_dir / "submitted" / ann / ASSIGNMENT
    ann_before.mkdir(parents=True, exist_ok=True)
    (ann_before / "kept.txt").write_text("collected before")
    solution = course.course_dir / "source" / ASSIGNMENT / f"{ASSIGNMENT}.ipynb"
    linked = inbound.hand_in(ann, lambda folder: (folder / f"{ASSIGNMENT}.ipynb").symlink_to(solution))
    forged = inbound.hand_in(ann, lambda folder: (folder / f"{ASSIGNMENT}.ipynb").write_text("{}"), named=bob)
    output = coursehub(course.hub_dir, "collect", ASSIGNMENT)
    assert f"Not collected: '{linked}': '{ASSIGNMENT}.ipynb' in your submission is a symbolic link" in output
    assert f"Not collected: '{forged}' names {bob} but was made by another account" in output
    assert (ann_before / "kept.txt").read_text() == "collected before"
    collected = (course.course_dir / "submitted" / bob / ASSIGNMENT / f"{ASSIGNMENT}.ipynb").read_text()
    assert "BEGIN SOLUTION" not in collected and collected != "{}"
