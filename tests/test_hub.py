"""The course for a class on a real JupyterHub (coursehub): an instructor and two students on
127.0.0.1, PAM logins, each server in namespaces of its own.

Both students' kernels run talkers on `chatter` with the same ROS_DOMAIN_ID and discovery range
and hear only themselves, and cannot read each other's home, the gradebook, the exchange's
submissions or the reference solutions. In headless Chromium the students log in,
fetch brightness from the Assignments panel and submit (one the reference solution, one a wrong
average); the instructor's commands collect, grade in the sandbox and release feedback; the
formgrader shows the grader's scores; each student fetches their own feedback and cannot reach
the other's server. Stopping the hub leaves no process of the course behind. Root only
(accounts, namespaces); skipped otherwise.
"""

from __future__ import annotations

import concurrent.futures
import os
import re
import secrets
import sys
import time
from pathlib import Path

import nbformat
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import zoo  # noqa: E402
from browser_nbgrader import wait_for_assignment  # noqa: E402
from browser_support import CHROMIUM_ARGS, VIEWPORT, ChromiumUnavailable, click_menu, find_chromium  # noqa: E402
from hub_support import course_processes, log_in, run_in_kernel, running_hub, why_no_hub  # noqa: E402
from zoo.brightness import SUM  # noqa: E402

pytestmark = [pytest.mark.hub, pytest.mark.browser, pytest.mark.slow, pytest.mark.timeout(600),
              pytest.mark.skipif(why_no_hub() is not None, reason=str(why_no_hub()))]

ASSIGNMENT = "brightness"
SCREENSHOTS = Path(__file__).resolve().parents[1] / "artifacts" / "browser"
#: The wrong submission: the brightest pixel instead of the average.
WRONG_AVERAGE = [(SUM, "return int(image.max())")]

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
    with running_hub(prefix, ["alice", "bob"], hub_dir, scratch, release=[ASSIGNMENT]) as running:
        yield running


@pytest.fixture(scope="module")
def sessions(hub):
    """Everyone logged in over HTTP at once (three servers start side by side): user -> session."""
    users = [hub.instructor, *hub.students]
    with concurrent.futures.ThreadPoolExecutor(len(users)) as pool:
        return dict(zip(users, (session for session, _ in pool.map(lambda user: log_in(hub, user), users))))


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
    hidden = str(Path(__file__).resolve().parent.parent / "assignments")
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        said = dict(zip((alice, bob), pool.map(
            lambda user: run_in_kernel(hub, sessions[user], user, TALKER.format(
                me=user, seconds=6, private=private[user], hidden=hidden)), (alice, bob))))
    for user in (alice, bob):
        assert f"heard ['{user}']" in said[user], said
        for path in private[user]:
            assert f"denied {path}" in said[user], said
        assert "reference solutions []" in said[user], said


def test_students_submit_in_the_assignments_panel_and_each_fetches_only_their_feedback(hub, sessions, chromium):
    alice, bob = hub.students
    pages = {user: _log_in_page(chromium, hub, user) for user in (alice, bob)}
    instructor = sessions[hub.instructor]
    hub.released.result()
    for user, page in pages.items():
        _open_assignments(page, hub, user)
        wait_for_assignment(page, "released", ASSIGNMENT, 60)
        _press(page, "released", "Fetch")
        wait_for_assignment(page, "fetched", ASSIGNMENT, 60)
    _hand_in(hub, alice, [])
    _hand_in(hub, bob, WRONG_AVERAGE)
    for user, page in pages.items():
        _press(page, "fetched", "Submit")
        wait_for_assignment(page, "submitted", ASSIGNMENT, 60)

    hub.coursehub("collect", ASSIGNMENT)
    hub.coursehub("grade", ASSIGNMENT)
    hub.coursehub("feedback", ASSIGNMENT)

    xsrf = instructor.cookies.get("_xsrf", path=f"/user/{hub.instructor}/")
    shown = instructor.get(f"{hub.url}/user/{hub.instructor}/formgrader/api/submissions/{ASSIGNMENT}",
                           headers={"X-XSRFToken": xsrf}, timeout=60).json()
    scores = {row["student"]: (row["score"], row["max_score"]) for row in shown}
    # On failure, the grader's verdicts say which item cost the points.
    assert scores[alice][0] == scores[alice][1] > 0, (shown, zoo.graded_outputs(hub.course_dir, alice, ASSIGNMENT)[-3000:])
    assert 0 <= scores[bob][0] < scores[bob][1], (shown, zoo.graded_outputs(hub.course_dir, bob, ASSIGNMENT)[-3000:])

    for user, page in pages.items():
        _press(page, "submitted", "Fetch Feedback")
    for user, page in pages.items():
        other = bob if user == alice else alice
        page.wait_for_function(
            "() => [...document.querySelectorAll('#submitted_assignments_list .list_item')]"
            ".some(row => row.innerText.includes('feedback'))", timeout=60_000)
        SCREENSHOTS.mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(SCREENSHOTS / f"hub_assignments_{'first' if user == alice else 'second'}.png"))
        feedback = sorted((Path(f"/home/{user}") / ASSIGNMENT / "feedback").glob(f"*/{ASSIGNMENT}.html"))
        assert len(feedback) == 1, f"{user} fetched {feedback}"
        relative = feedback[0].relative_to(f"/home/{user}").as_posix()
        page.goto(f"{hub.url}/user/{user}/files/{relative}", wait_until="domcontentloaded")
        text = page.inner_text("body")
        page.screenshot(path=str(SCREENSHOTS / f"hub_feedback_{'first' if user == alice else 'second'}.png"))
        # nbgrader's feedback page of the student's own submission: their score, not the other's.
        assert f"{ASSIGNMENT} (Score: {scores[user][0]:.1f} / {scores[user][1]:.1f})" in text, text[:500]
        assert f"(Score: {scores[other][0]:.1f} / {scores[other][1]:.1f})" not in text, text[:500]
        answer = page.goto(f"{hub.url}/user/{other}/lab", wait_until="domcontentloaded")
        assert answer.status == 403 or f"/user/{other}/lab" not in page.url, (answer.status, page.url)
        page.context.close()


def test_stopping_the_hub_stops_every_process_of_the_course(hub):
    namespaces = set()
    for process in course_processes(hub):
        try:
            namespaces.add(os.readlink(f"/proc/{process.pid}/ns/net"))
        except OSError:
            pass
    namespaces.discard(os.readlink("/proc/self/ns/net"))
    assert namespaces, "no server of the course was running before the hub stopped"
    hub.stop()
    deadline = time.monotonic() + 60  # a backstop: stopping the servers of a loaded machine takes seconds
    while (left := course_processes(hub, namespaces)) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not left, [(p.pid, p.info) for p in left]
