"""The course for a class on a real JupyterHub (coursehub): an instructor and two students on
127.0.0.1, PAM logins, each server in namespaces of its own.

Both students' kernels run talkers on `chatter` with the same ROS_DOMAIN_ID and discovery range
and hear only themselves, and cannot read each other's home, the gradebook, the exchange's
submissions or the reference solutions. In headless Chromium the students log in, fetch
brightness from the Assignments panel and submit; the hub's grading service grades each
submission and releases its feedback, with no instructor step: bob's wrong average shows its
reasons, his fix full marks, a Submit past the attempts is refused with the reason; each student
sees only their own submissions and feedback and cannot reach the other's server. The
instructor's collect, grade and feedback afterwards agree with the service and grade nothing
again. 30 submissions at once survive a SIGKILL of the service in the middle of a sandboxed
grading, each graded once, each content once, in arrival order per worker of the restarted
service's two. A student's uid opens nothing of the hub's, the course's and the repository's closed files
but what their server needs. Stopping the hub leaves no process of the course behind. Root only; skipped otherwise."""

from __future__ import annotations

import concurrent.futures
import contextlib
import csv
import os
import re
import secrets
import shutil
import signal
import time
from pathlib import Path

import nbformat
import pytest
from support import zoo
from support.browser import CHROMIUM_ARGS, VIEWPORT, ChromiumUnavailable, find_chromium
from support.browser_nbgrader import wait_for_assignment
from support.browser_notebook import click_menu
from support.hub import (
    course_processes,
    enroll,
    grading_service,
    log_in,
    namespace_bystanders,
    run_in_kernel,
    running_hub,
    sandboxed,
    student_access,
    submission_states,
    wait_until,
    wait_until_gone,
    why_no_hub,
    work_folders_of,
)
from support.zoo.brightness import SUM

from course_lib import contract

pytestmark = [pytest.mark.hub, pytest.mark.browser, pytest.mark.slow, pytest.mark.timeout(600),
              pytest.mark.skipif(why_no_hub() is not None, reason=str(why_no_hub()))]

ASSIGNMENT = "brightness"
SCREENSHOTS = contract.ROOT / "artifacts" / "browser"
#: The wrong submission: the brightest pixel instead of the average.
WRONG_AVERAGE = [(SUM, "return int(image.max())")]
#: Submissions graded before the due date (the course's nbgrader_config.py; coursehub.grading_service).
ATTEMPTS = 2
SETTINGS = f"c.GradeOnSubmit.assignments = {{{ASSIGNMENT!r}: {{'attempts': {ATTEMPTS}}}}}\n"

#: Each student's kernel: a talker and a listener on `chatter`, on the same domain and discovery
#: range as the other student (set on purpose); prints who it heard, and what it may read.
TALKER = '''
import os, time
os.environ["ROS_DOMAIN_ID"] = "7"
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "SUBNET"
import rclpy
from rclpy.node import Node
from std_msgs.msg import String


class Chatter(Node):
    def __init__(self):
        super().__init__("chatter_{me}")
        self.heard = set()
        self.publisher = self.create_publisher(String, "chatter", 10)
        self.create_subscription(String, "chatter", lambda msg: self.heard.add(msg.data), 10)
        self.create_timer(0.1, lambda: self.publisher.publish(String(data="{me}")))


rclpy.init()
try:
    node = Chatter()
    end = time.monotonic() + {seconds}
    while time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.1)
    print("heard", sorted(node.heard))
finally:
    rclpy.try_shutdown()
for path in {private!r}:
    try:
        os.listdir(path) if os.path.isdir(path) else open(path, "rb").read(1)
        print("read", path)
    except PermissionError:
        print("denied", path)
print("reference solutions", os.listdir({hidden!r}))
'''


@pytest.fixture(scope="module")
def hub(tmp_path_factory):
    prefix = "h15" + "".join(secrets.choice("abcdefghijkmnpqrstuvwxyz") for _ in range(4))
    hub_dir = Path("/srv") / f"{prefix}-hub"
    scratch = tmp_path_factory.mktemp("hub")
    with running_hub(prefix, ["alice", "bob"], hub_dir, scratch, release=[ASSIGNMENT],
                     settings=SETTINGS) as running:
        yield running


@pytest.fixture(scope="module")
def sessions(hub):
    """Everyone logged in over HTTP at once (three servers start side by side): user -> session."""
    users = [hub.instructor, *hub.students]
    with concurrent.futures.ThreadPoolExecutor(len(users)) as pool:
        sessions = [session for session, _ in pool.map(lambda user: log_in(hub, user), users)]
        return dict(zip(users, sessions, strict=True))


@pytest.fixture(scope="module")
def chromium():
    from playwright.sync_api import sync_playwright

    try:
        executable = find_chromium()
    except ChromiumUnavailable as why:
        pytest.skip(f"the hub test needs Chromium: {why}")
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=executable, headless=True, args=CHROMIUM_ARGS)
        try:
            yield browser
        finally:
            browser.close()


def _log_in_page(chromium, hub, user):
    """A browser context of its own (cookies) with `user` logged in at the hub's login form."""
    context = chromium.new_context(viewport=VIEWPORT)
    page = context.new_page()
    page.set_default_timeout(180_000)
    page.goto(f"{hub.url}/hub/login", wait_until="domcontentloaded")
    page.fill("#username_input", user)
    page.fill("#password_input", hub.passwords[user])
    page.click("#login_submit")
    return page


def _open_assignments(page, hub, user):
    page.wait_for_url(re.compile(f"/user/{user}/lab"), timeout=180_000)
    page.locator("#jp-MainMenu .lm-MenuBar-item").first.wait_for()
    click_menu(page, "Nbgrader", "Assignment List")
    page.locator("#released_assignments_list").wait_for()


def _press(page, listed, label):
    page.locator(f"#{listed}_assignments_list > .list_item", has_text=ASSIGNMENT).get_by_role(
        "button", name=label).click()


def _hand_in(hub, user, edits):
    """What the student's work leaves in the fetched notebook: the reference, or it with `edits`."""
    import pwd

    account = pwd.getpwnam(user)
    target = Path(account.pw_dir) / ASSIGNMENT / f"{ASSIGNMENT}.ipynb"
    nbformat.write(zoo.edited_notebook(hub.course_dir, ASSIGNMENT, edits, user), target)
    os.chown(target, account.pw_uid, account.pw_gid)


def test_talkers_in_two_students_kernels_on_one_domain_never_hear_each_other(hub, sessions):
    alice, bob = hub.students
    from autograder.config import COURSE_ID

    hub.released.result()  # nbgrader made the exchange's inbound/ (students may write, not list)
    inbound = str(hub.hub_dir / "exchange" / COURSE_ID / "inbound")
    private = {alice: [f"/home/{bob}", str(hub.course_dir / "gradebook.db"), inbound],
               bob: [f"/home/{alice}", str(hub.course_dir / "gradebook.db"), inbound]}
    hidden = str(contract.ROOT / "assignments")
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        said = dict(zip((alice, bob), pool.map(
            lambda user: run_in_kernel(hub, sessions[user], user, TALKER.format(
                me=user, seconds=6, private=private[user], hidden=hidden)), (alice, bob)), strict=True))
    for user in (alice, bob):
        assert f"heard ['{user}']" in said[user], said
        for path in private[user]:
            assert f"denied {path}" in said[user], said
        assert "reference solutions []" in said[user], said


def _status(page, hub, attempt: int, timeout: float = 420) -> tuple[dict, list[str]]:
    """Wait until the grading service's page shows the student's submission `attempt` graded, refused
    or failed (its feedback released); return that row and every state the page said meanwhile."""
    said, deadline = [], time.monotonic() + timeout
    while True:
        # The context's cookies (the service's login, done by page.goto) go with the request.
        rows = submission_states(page.context.request.get(f"{hub.url}/services/grading/").text())
        row = next((r for r in rows if r["assignment"] == ASSIGNMENT and r["attempt"] == attempt), None)
        if row is not None and (not said or said[-1] != row["says"]):
            said.append(row["says"])
        if row is not None and row["state"] in ("released", "refused", "failed"):
            return row, said
        if time.monotonic() > deadline:
            raise TimeoutError(f"submission {attempt} not graded after {timeout:.0f} s; the page said {said}, "
                               f"the service's log:\n{hub.log_tail()}")
        time.sleep(1.5)  # a grading takes ten seconds and more; each look costs the proxy and the service


def _submit(page, hub, user, edits, attempt: int) -> tuple[dict, list[str]]:
    """Hand in the reference with `edits`, press Submit, and wait for the service's verdict."""
    _hand_in(hub, user, edits)
    _press(page, "fetched", "Submit")
    return _status(page, hub, attempt)


def _fetch_feedback(page, hub, user, count: int) -> str:
    """Press Fetch Feedback until the student's home holds `count` feedback pages; open the newest
    from the student's server in a tab of its own (the lab stays open) and return its text."""
    folder = Path(f"/home/{user}") / ASSIGNMENT / "feedback"
    _press(page, "submitted", "Fetch Feedback")
    deadline = time.monotonic() + 60
    while len(pages := sorted(folder.glob(f"*/{ASSIGNMENT}.html"))) < count and time.monotonic() < deadline:
        time.sleep(0.2)
    assert len(pages) == count, f"{user} fetched {pages}, not {count} feedback pages"
    relative = pages[-1].relative_to(f"/home/{user}").as_posix()  # the folders are the submissions' times
    viewer = page.context.new_page()
    try:
        viewer.goto(f"{hub.url}/user/{user}/files/{relative}", wait_until="domcontentloaded")
        return viewer.inner_text("body")
    finally:
        viewer.close()


def test_students_get_graded_feedback_minutes_after_submit_and_only_their_own(hub, sessions, chromium):
    alice, bob = hub.students
    pages = {user: _log_in_page(chromium, hub, user) for user in (alice, bob)}
    hub.released.result()
    for user, page in pages.items():
        _open_assignments(page, hub, user)
        wait_for_assignment(page, "released", ASSIGNMENT, 60)
        _press(page, "released", "Fetch")
        wait_for_assignment(page, "fetched", ASSIGNMENT, 60)
    # Each student's page of the grading service, behind the hub's login (HubOAuth); closed while
    # the test looks through the same login with requests (a page open reloads itself every 2 s).
    for page in pages.values():
        status = page.context.new_page()
        status.goto(f"{hub.url}/services/grading/", wait_until="domcontentloaded")
        assert "No submission yet" in status.inner_text("body"), status.url
        status.close()

    _hand_in(hub, bob, WRONG_AVERAGE)
    _hand_in(hub, alice, [])
    for page in (pages[bob], pages[alice]):  # one after the other: alice's waits behind bob's
        _press(page, "fetched", "Submit")
    wrong, said = _status(pages[bob], hub, 1)
    first, seen = _status(pages[alice], hub, 1)
    assert wrong["state"] == "released" and wrong["says"].startswith("graded: "), said
    score, maximum = (float(x) for x in re.match(r"graded: ([\d.]+) / ([\d.]+)", wrong["says"]).groups())
    assert 0 <= score < maximum, said
    # What bob saw: queued or grading first, then the score (the page asks for Fetch Feedback).
    assert said[0].startswith(("queued (", "grading")) and "Fetch Feedback" in said[-1], said
    text = _fetch_feedback(pages[bob], hub, bob, 1)
    assert f"{ASSIGNMENT} (Score: {score:.1f} / {maximum:.1f})" in text, text[:500]
    assert "\u2718" in text and "expected" in text, text  # the reasons: each failed item, what was expected

    fixed, said = _submit(pages[bob], hub, bob, [], 2)
    assert fixed["says"].startswith(f"graded: {maximum:g} / {maximum:g}"), said
    text = _fetch_feedback(pages[bob], hub, bob, 2)
    assert f"{ASSIGNMENT} (Score: {maximum:.1f} / {maximum:.1f})" in text, text[:500]
    # A third Submit before the due date: the panel refuses it and says why (coursehub.limited_submit).
    _press(pages[bob], "fetched", "Submit")
    dialog = pages[bob].locator("#submission-message")
    dialog.wait_for()
    SCREENSHOTS.mkdir(parents=True, exist_ok=True)
    pages[bob].screenshot(path=str(SCREENSHOTS / "hub_submit_refused.png"))
    # The reason first and alone (course_lib.notebook.student_lab.assignment_list), not nbgrader's traceback.
    said = " ".join(dialog.inner_text().split())
    assert said.startswith(f"Assignment not submitted: {ASSIGNMENT} allows {ATTEMPTS} graded submissions before "
                           "the due date") and "Traceback" not in said, said
    assert said.endswith("Your submissions and their scores: /services/grading/ on the hub (its home page: "
                         "Services > grading)."), said
    pages[bob].locator(".jp-Dialog .jp-mod-accept").click()
    # The page it names is in the hub's Services menu (File > Hub Control Panel in the lab).
    home = pages[bob].context.new_page()
    home.goto(f"{hub.url}/hub/home", wait_until="domcontentloaded")
    assert home.locator("a.dropdown-item", has_text="grading").get_attribute("href") == "/services/grading/"
    home.close()
    # Copied into inbound/ past the panel (from a terminal, say): the service refuses it and says so.
    _drop_in_inbound(hub, bob, hub.course_dir / "submitted" / bob / ASSIGNMENT)
    refused, said = _status(pages[bob], hub, 3)
    assert refused["state"] == "refused", said
    assert f"{ASSIGNMENT} allows {ATTEMPTS} graded submissions before the due date" in refused["says"], said
    status = {user: page.context.new_page() for user, page in pages.items()}
    for page in status.values():
        page.goto(f"{hub.url}/services/grading/", wait_until="domcontentloaded")
    status[bob].screenshot(path=str(SCREENSHOTS / "hub_grading_status.png"))
    assert "this is your 3rd" in status[bob].inner_text("body")

    # What the page showed came in the queue's order (how many states a look catches depends on speed).
    order = [next(n for n, start in enumerate(("queued (", "grading", "graded")) if text.startswith(start))
             for text in seen]
    assert order == sorted(order), seen
    assert first["says"].startswith(f"graded: {maximum:g} / {maximum:g}"), seen
    shown = status[alice].inner_text("body")
    assert status[alice].locator("tr.submission").count() == 1 and bob not in shown, shown
    text = _fetch_feedback(pages[alice], hub, alice, 1)
    assert f"{ASSIGNMENT} (Score: {maximum:.1f} / {maximum:.1f})" in text, text[:500]
    answer = pages[alice].goto(f"{hub.url}/user/{bob}/lab", wait_until="domcontentloaded")
    assert answer.status == 403 or f"/user/{bob}/lab" not in pages[alice].url, (answer.status, pages[alice].url)

    # After the due date the instructor's usual steps find what the service recorded: the same
    # scores in the formgrader, nothing graded again (the refused submission is not in inbound/).
    hub.coursehub("collect", ASSIGNMENT)
    hub.coursehub("grade", ASSIGNMENT)
    hub.coursehub("feedback", ASSIGNMENT)
    xsrf = sessions[hub.instructor].cookies.get("_xsrf", path=f"/user/{hub.instructor}/")
    listed = sessions[hub.instructor].get(f"{hub.url}/user/{hub.instructor}/formgrader/api/submissions/{ASSIGNMENT}",
                                          headers={"X-XSRFToken": xsrf}, timeout=60).json()
    scores = {row["student"]: (row["score"], row["max_score"]) for row in listed}
    assert scores[alice] == scores[bob] == (maximum, maximum), listed
    with open(hub.course_dir / "grading_report.csv", newline="") as handle:
        report = {row["student_id"]: row for row in csv.DictReader(handle)}
    assert report[alice]["from_cache"] == report[bob]["from_cache"] == "1", report
    for page in pages.values():
        page.context.close()


#: The queue test: submissions handed in at once, those among them with files nobody handed in before
#: (their place in the queue), and those handed in while the service is down. The rest are alice's
#: files, graded in the browser test: the service reuses that grading, which is cheap.
AT_ONCE, NEW_AT, WHILE_DOWN = 30, (0, 1, 15, 29), 2
#: The new files: the reference with a comment in the student's module (full marks, graded once).
NEW_FILES = [(SUM, f"{SUM}  # handed in by four students")]
#: Submissions the restarted service grades at the same time (c.GradeOnSubmit.workers).
WORKERS = 2


def _drop_in_inbound(hub, student: str, like: Path) -> str:
    """A submission of `student` in the exchange's inbound/ as nbgrader's submit leaves it (the files
    of `like`, a submitted folder; a time and secret of its own; the folder made 0777 last)."""
    from datetime import datetime, timezone

    from autograder.config import COURSE_ID
    from coursehub.accounts import chown_tree

    stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M:%S.%f %Z")
    folder = hub.hub_dir / "exchange" / COURSE_ID / "inbound" / f"{student}+{ASSIGNMENT}+{stamp}+{secrets.token_hex(4)}"
    shutil.copytree(like, folder, ignore=shutil.ignore_patterns("timestamp.txt", "submission_secret.txt"))
    (folder / "timestamp.txt").write_text(stamp)
    (folder / "submission_secret.txt").write_text(secrets.token_hex(64))
    chown_tree(folder, student)  # the student's, as their submit makes it: the service takes no other
    os.chmod(folder, 0o777)
    return folder.name


def _queue_rows(hub, students) -> dict:
    import sqlite3

    with contextlib.closing(sqlite3.connect(hub.course_dir / "autograder" / "submit_queue.sqlite", timeout=30)) as db:
        db.row_factory = sqlite3.Row
        return {row["student"]: dict(row) for row in db.execute("SELECT * FROM submissions")
                if row["student"] in students}


def _wait_for_rows(hub, students, done, timeout: float = 300) -> dict:
    deadline = time.monotonic() + timeout
    while not done(rows := _queue_rows(hub, students)):
        assert time.monotonic() < deadline, (rows, hub.log_tail())
        time.sleep(0.25)
    return rows


def _new_files(hub, like: Path, folder: Path) -> Path:
    """A submitted folder like `like` whose notebook has NEW_FILES."""
    shutil.copytree(like, folder)
    nbformat.write(zoo.edited_notebook(hub.course_dir, ASSIGNMENT, NEW_FILES), folder / f"{ASSIGNMENT}.ipynb")
    return folder


def test_submissions_at_once_are_each_graded_once_across_a_kill_of_the_service(hub, tmp_path):
    """30 submissions at once, the service killed with SIGKILL while it grades one in the sandbox,
    two more handed in while it is down: the service the hub restarts (with two workers) grades each
    exactly once, in arrival order per worker, each content once, with the scores of a plain grade
    run."""
    from nbgrader.utils import notebook_hash

    from autograder.config import COURSE_ID
    from autograder.results import store

    alice = hub.students[0]
    like = hub.course_dir / "submitted" / alice / ASSIGNMENT
    new = _new_files(hub, like, tmp_path / "new")
    graded = store.recorded_results(hub.course_dir, ASSIGNMENT, alice)[0]
    students = [f"{hub.instructor[:-1]}q{n:02d}" for n in range(AT_ONCE + WHILE_DOWN)]
    enroll(hub, students)  # the service grades only the roster's students, from their own accounts
    service = grading_service(hub)
    for n, student in enumerate(students[:AT_ONCE]):
        _drop_in_inbound(hub, student, new if n in NEW_AT else like)
    first = students[NEW_AT[0]]

    def grading_in_sandbox(rows) -> bool:
        assert rows.get(first, {}).get("state") in (None, "queued", "grading"), f"graded before the kill: {rows[first]}"
        return rows.get(first, {}).get("state") == "grading" and bool(sandboxed(service))

    _wait_for_rows(hub, students, grading_in_sandbox)
    running = sandboxed(service)
    cut_short = work_folders_of(running)
    assert cut_short, [p.cmdline() for p in running]
    with open(hub.course_dir / "nbgrader_config.py", "a") as handle:  # read when the service starts again
        handle.write(f"c.GradeOnSubmit.workers = {WORKERS}\n")
    service.kill()
    wait_until_gone(service)
    for process in running:  # the sandbox goes with the service (course_lib.processes: never an orphan)
        wait_until_gone(process)
    for student in students[AT_ONCE:]:  # handed in while the service is down
        _drop_in_inbound(hub, student, like)
    assert grading_service(hub, timeout=180).pid != service.pid  # the hub restarts it
    wait_until(lambda: not any(folder.exists() for folder in cut_short), 60)  # swept by the new service

    rows = _wait_for_rows(hub, students, lambda rows: len(rows) == len(students) and all(
        r["state"] == "released" for r in rows.values()))
    new_rows = [rows[students[n]] for n in NEW_AT]
    for student, row in rows.items():
        assert row["gradings"] == 1, row  # graded once each, the one cut short by the kill too
        with open(hub.course_dir / "feedback" / student / ASSIGNMENT / "submission_secret.txt") as handle:
            checksum = notebook_hash(secret=handle.read(), notebook_id=ASSIGNMENT)
        assert (hub.hub_dir / "exchange" / COURSE_ID / "feedback" / f"{checksum}.html").is_file(), student
        if row not in new_rows:  # alice's files: her grading reused
            assert row["reused_from"] is not None and (row["score"], row["max_score"]) == (graded.score,
                                                                                          graded.max_score), row
    # Each content graded once: the new files in the sandbox for one of the first two only (the
    # workers took both at once after the restart; the one to reach them first graded them, the other
    # waited and reused that grading), then reused by the later two.
    graded_new = [r["reused_from"] is None for r in new_rows]
    assert sum(graded_new) == 1 and any(graded_new[:2]), new_rows
    assert len({(r["content"], r["score"]) for r in new_rows}) == 1, new_rows
    # Arrival order per worker: each worker took its rows oldest first, and so did both together.
    by_claim = sorted(rows.values(), key=lambda r: r["claimed"])
    assert [r["id"] for r in by_claim] == sorted(r["id"] for r in rows.values()), by_claim
    assert {r["worker"] for r in rows.values()} == set(range(WORKERS)), by_claim

    # The instructor's plain grade run of the new files, from scratch, gives the same scores.
    service_cells = store.recorded_results(hub.course_dir, ASSIGNMENT, first)[0].cells
    hub.coursehub("grade", ASSIGNMENT, "--student", first, "--force")
    plain = store.recorded_results(hub.course_dir, ASSIGNMENT, first)[0]
    assert not plain.from_cache and plain.score == new_rows[0]["score"] == plain.max_score, (plain, new_rows[0])
    assert [c["auto_score"] for c in plain.cells] == [c["auto_score"] for c in service_cells], (
        plain.cells, service_cells)


def test_a_student_opens_nothing_of_the_hub_the_course_or_the_solutions_but_what_they_need(hub, sessions):
    """As each student's uid (as ssh logs them in): what opens of the hub directory, the instructor's course and
    the repository's closed folders is allowed (support.hub.STUDENT_MAY_READ); what their server needs opens."""
    hub.released.result()  # the instructor's release read the closed folders
    for student in hub.students:
        assert student_access(hub, student) == {"opened, not allowed": [], "needed, not opened": []}, student


def test_stopping_the_hub_stops_every_process_of_the_course(hub):
    """Every process of the course's users and of their servers' namespaces ends with the hub, and
    nothing else: a namespace made meanwhile (a grading's, say) may get the number a server's had."""
    from coursehub.netns import PinnedNamespace

    service = grading_service(hub)
    namespaces = {}  # pinned: once the servers end, their numbers go to new namespaces
    try:
        for process in course_processes(hub):
            pinned = PinnedNamespace.of(process.pid)
            if pinned is not None:
                namespaces.setdefault(pinned.identity, pinned)
                if namespaces[pinned.identity] is not pinned:
                    pinned.close()
        assert namespaces, "no server of the course was running before the hub stopped"
        with namespace_bystanders() as bystanders:
            hub.stop()
            deadline = time.monotonic() + 60  # a backstop: stopping the servers of a loaded machine takes seconds
            while (left := course_processes(hub, namespaces.values())) and time.monotonic() < deadline:
                time.sleep(0.2)
        assert not left, [(p.pid, p.info) for p in left]
    finally:
        for pinned in namespaces.values():
            pinned.close()
    killed = [p.pid for p in bystanders if p.returncode == -signal.SIGKILL]
    assert killed == [], f"stopping the hub killed {len(killed)} of {len(bystanders)} processes of other namespaces"
    wait_until_gone(service)  # the grading service (root) stops with the hub
