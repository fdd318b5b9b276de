"""Use a course hub as students do, from tests and benchmarks: create it with its admin command,
start and stop it, log in over HTTP, run code in a student's kernel (Jupyter's kernel websocket),
and find every process of the course's users.

- ``running_hub``: a course (prefixed accounts) created by ``python -m coursehub create-course``,
  the hub started by ``python -m coursehub start``; on exit the hub is stopped and the course removed;
- ``log_in``: a requests session logged in through the hub's login form, with the user's server up;
- ``run_in_kernel``: start a kernel in a user's server, run code, return what it printed;
- ``course_processes``: the processes of the course's uids and of their network namespaces;
- ``namespace_bystanders``: processes in network namespaces of their own that come and go (as a
  grader's sandboxes do) while the hub is stopped;
- ``grading_service``, ``sandboxed``, ``submission_states``: the hub's grading service process,
  its processes in the grader's sandbox (a grading runs), and the rows of its queue as its page
  shows them to a student;
- ``student_access``: what a student's uid opens of the hub's, the course's and the repository's
  closed files beyond ``STUDENT_MAY_READ``, and what their server needs that does not open.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import csv
import dataclasses
import json
import os
import pwd
import re
import signal
import socket
import stat
import subprocess
import sys
import threading
import time
import uuid
from pathlib import Path

import psutil

from course_lib import contract

REPO = contract.ROOT
PROXY = Path(sys.prefix) / "chp" / "node_modules" / ".bin" / "configurable-http-proxy"


def why_no_hub() -> str | None:
    """Why a hub cannot run here (the reason names the fix), or None."""
    if os.geteuid() != 0:
        return "the hub test creates Linux accounts and namespaces: run `make test` as root"
    if not PROXY.exists():
        return f"configurable-http-proxy is not installed at {PROXY}: run `make hub-deps`"
    return None


@dataclasses.dataclass
class Hub:
    url: str
    hub_dir: Path
    instructor: str
    students: list[str]
    passwords: dict
    process: subprocess.Popen
    log: Path
    #: The release of the assignments named to running_hub, done while the hub starts and
    #: students log in (a concurrent.futures.Future: .result() waits for it).
    released: object = None

    @property
    def course_dir(self) -> Path:
        return Path(pwd.getpwnam(self.instructor).pw_dir) / "course"

    def coursehub(self, *args: str, timeout: float = 600) -> str:
        """Run ``python -m coursehub --hub-dir HUB_DIR ARGS`` (root); return its output, raise on failure."""
        return coursehub(self.hub_dir, *args, timeout=timeout)

    def uids(self) -> set[int]:
        found = set()
        for user in [self.instructor, *self.students]:
            with contextlib.suppress(KeyError):
                found.add(pwd.getpwnam(user).pw_uid)
        return found

    def stop(self, timeout: float = 60) -> None:
        """Stop the hub as Ctrl-C does (it stops every server first)."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
            try:
                self.process.wait(timeout)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait(10)

    def log_tail(self, lines: int = 60) -> str:
        """The hub log's last lines, without the proxy's repeated "404 GET" and connection errors (a
        service's traceback is what says why a hub did not come up)."""
        noise = ("[ConfigProxy]", "    at ", "  errno:", "  code:", "  syscall:", "  address:", "  port:", "}")
        kept = [line for line in self.log.read_text(errors="replace").splitlines() if not line.startswith(noise)]
        return "\n".join(kept[-lines:])


def coursehub(hub_dir: Path, *args: str, timeout: float = 600) -> str:
    done = subprocess.run([sys.executable, "-m", "coursehub", "--hub-dir", str(hub_dir), *args], cwd=REPO,
                          capture_output=True, text=True, timeout=timeout,
                          env=dict(os.environ, PYTHONPATH=str(REPO)))
    if done.returncode != 0:
        raise RuntimeError(f"python -m coursehub {' '.join(args)} failed ({done.returncode}):\n"
                           f"{done.stdout}{done.stderr}")
    return done.stdout + done.stderr


def free_port_pair() -> int:
    """A free port p whose neighbour p + 1 (the proxy's API, the grading service) is free too, below
    the kernel's ephemeral range: a port from bind(("127.0.0.1", 0)) is one the kernel also hands
    to any program's outgoing connection, which can take p + 1 between this check and the grading
    service's listen() (a clean-clone run saw the service exit with status 1 as the hub started,
    and the hub never answered)."""
    import random
    import socket

    low = int(Path("/proc/sys/net/ipv4/ip_local_port_range").read_text().split()[0])
    for _ in range(200):
        port = random.randrange(max(1024, low - 12000), low - 2)
        try:
            with socket.socket() as first, socket.socket() as second:
                first.bind(("127.0.0.1", port))
                second.bind(("127.0.0.1", port + 1))
        except OSError:
            continue
        return port
    raise RuntimeError("no two neighbouring free ports on 127.0.0.1")


@contextlib.contextmanager
def running_hub(prefix: str, students: list[str], hub_dir: Path, scratch: Path, release: list[str] = (),
                timeout: float = 60, settings: str = ""):
    """Create a course (instructor ``<prefix>i``, the students ``<prefix><name>``) and run its hub;
    the roster and the hub's log go to `scratch`. `settings`: lines for the instructor's part of
    the course's nbgrader_config.py (e.g. c.GradeOnSubmit.assignments)."""
    import requests

    roster = scratch / f"{prefix}-roster.csv"
    roster.write_text("id,first_name,last_name\n" + "".join(f"{prefix}{s},{s.title()},Test\n" for s in students))
    port, hub_port = free_port_pair(), free_port_pair()
    process, hub = None, None
    try:
        coursehub(hub_dir, "create-course", str(roster), "--instructor", f"{prefix}i", "--group", f"{prefix}g",
                  "--exchange", str(hub_dir / "exchange"), "--port", str(port), "--hub-port", str(hub_port))
        if settings:
            instructor = pwd.getpwnam(f"{prefix}i")
            with open(Path(instructor.pw_dir) / "course" / "nbgrader_config.py", "a") as handle:
                handle.write(settings)
        with open(hub_dir / "passwords.csv", newline="") as handle:
            passwords = {row["user"]: row["password"] for row in csv.DictReader(handle)}
        log = scratch / f"{prefix}-hub.log"
        with open(log, "w") as out:
            process = subprocess.Popen([sys.executable, "-m", "coursehub", "--hub-dir", str(hub_dir), "start"],
                                       cwd=REPO, stdout=out, stderr=subprocess.STDOUT,
                                       env=dict(os.environ, PYTHONPATH=str(REPO)))
        hub = Hub(f"http://127.0.0.1:{port}", hub_dir, f"{prefix}i", [f"{prefix}{s}" for s in students], passwords,
                  process, log)
        deadline = time.monotonic() + timeout
        while True:
            with contextlib.suppress(requests.RequestException):
                if requests.get(f"{hub.url}/hub/api", timeout=5).status_code == 200:
                    break
            if process.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f"the hub did not answer at {hub.url} within {timeout:.0f} s:\n{hub.log_tail()}")
            time.sleep(0.2)
        with concurrent.futures.ThreadPoolExecutor(1) as releasing:
            hub.released = releasing.submit(lambda: [coursehub(hub_dir, "release", name) for name in release])
            yield hub
    finally:
        if hub is not None:
            hub.stop()
        elif process is not None:
            process.kill()
            process.wait(10)
        if (hub_dir / "course.json").exists():
            coursehub(hub_dir, "remove-course")


def log_in(hub: Hub, user: str, timeout: float = 180):
    """A requests session logged in as `user` through the login form, once JupyterLab answers; and
    the seconds from the login form's submit to JupyterLab's page."""
    import requests

    session = requests.Session()
    session.get(f"{hub.url}/hub/login", timeout=30)
    started = time.monotonic()
    answer = session.post(f"{hub.url}/hub/login", timeout=60, data={
        "username": user, "password": hub.passwords[user], "_xsrf": session.cookies.get("_xsrf", path="/hub/")})
    if answer.status_code != 200 or "/hub/login" in answer.url:
        raise RuntimeError(f"login of {user} failed ({answer.status_code} at {answer.url})")
    deadline = started + timeout
    while time.monotonic() < deadline:
        page = session.get(f"{hub.url}/user/{user}/lab", timeout=60)
        if page.status_code == 200 and f"/user/{user}/lab" in page.url:
            return session, time.monotonic() - started
        time.sleep(0.25)
    raise TimeoutError(f"{user}'s JupyterLab did not open within {timeout:.0f} s:\n{hub.log_tail()}")


def run_in_kernel(hub: Hub, session, user: str, code: str, timeout: float = 120) -> str:
    """Start a python3 kernel in `user`'s server, run `code`, shut the kernel down; return its printed
    output. Raises RuntimeError with the traceback when the code raised."""
    base = f"{hub.url}/user/{user}/api/kernels"
    headers = {"X-XSRFToken": session.cookies.get("_xsrf", path=f"/user/{user}/") or ""}
    kernel = session.post(base, json={"name": "python3"}, headers=headers, timeout=60)
    kernel.raise_for_status()
    kernel_id = kernel.json()["id"]
    try:
        return asyncio.run(_execute(hub, session, f"{base}/{kernel_id}/channels", code, timeout))
    finally:
        session.delete(f"{base}/{kernel_id}", headers=headers, timeout=60)


async def _execute(hub, session, url: str, code: str, timeout: float) -> str:
    from tornado.httpclient import HTTPRequest
    from tornado.websocket import websocket_connect

    cookies = "; ".join(f"{c.name}={c.value}" for c in session.cookies)
    connection = await websocket_connect(HTTPRequest(url.replace("http://", "ws://"), headers={"Cookie": cookies}))
    msg_id = uuid.uuid4().hex
    connection.write_message(json.dumps({
        "header": {"msg_id": msg_id, "username": "test", "session": uuid.uuid4().hex, "msg_type": "execute_request",
                   "version": "5.3"},
        "parent_header": {}, "metadata": {}, "channel": "shell", "buffers": [],
        "content": {"code": code, "silent": False, "store_history": False, "user_expressions": {},
                    "allow_stdin": False, "stop_on_error": True}}))
    printed, error = [], None
    deadline = time.monotonic() + timeout
    try:
        while True:
            raw = await asyncio.wait_for(connection.read_message(), max(0.1, deadline - time.monotonic()))
            if raw is None:
                raise RuntimeError(f"the kernel's websocket closed; printed so far: {''.join(printed)}")
            message = json.loads(raw)
            if message.get("parent_header", {}).get("msg_id") != msg_id:
                continue
            kind, content = message["msg_type"], message["content"]
            if kind == "stream":
                printed.append(content["text"])
            elif kind == "error":
                error = "\n".join(content["traceback"])
            elif kind == "status" and content["execution_state"] == "idle":
                break
    finally:
        connection.close()
    if error:
        raise RuntimeError(f"the kernel's code raised:\n{error}\nprinted: {''.join(printed)}")
    return "".join(printed)


def course_processes(hub: Hub, namespaces=()) -> list[psutil.Process]:
    """The processes of the course's uids, and those in one of `namespaces`
    (coursehub.netns.PinnedNamespace: a namespace named by its number alone may be a grading's by now)."""
    from coursehub import netns

    uids, found = hub.uids(), []
    identities = {namespace.identity for namespace in namespaces}
    for process in psutil.process_iter(["uids"]):
        try:
            if process.info["uids"].real in uids or netns.identity(process.pid) in identities:
                found.append(process)
        except (psutil.Error, OSError, TypeError):
            pass
    return found


@contextlib.contextmanager
def namespace_bystanders(every: float = 0.02):
    """Short-lived processes in network namespaces of their own, one more every `every` s while the
    block runs, as a grader makes them (a sandbox for each build, notebook run and check); yields
    the list."""
    made, done = [], threading.Event()

    def make() -> None:
        while not done.is_set():
            made.append(subprocess.Popen(["unshare", "--net", "sleep", "2"]))
            time.sleep(every)

    thread = threading.Thread(target=make, daemon=True)
    thread.start()
    try:
        yield made
    finally:
        done.set()
        thread.join()
        for process in made:
            process.wait(60)


def grading_service(hub: Hub, timeout: float = 120) -> psutil.Process:
    """The hub's grading service (coursehub.grading_service), a child of the hub's process, once it
    answers on its port (the hub restarts it when it dies)."""
    import socket

    from coursehub import course as course_settings

    port = course_settings.load(hub.hub_dir).grading_port
    deadline = time.monotonic() + timeout
    while True:
        found = [child for child in psutil.Process(hub.process.pid).children()
                 if "coursehub.grading_service" in " ".join(_cmdline(child))]
        if found:
            with contextlib.suppress(OSError), socket.create_connection(("127.0.0.1", port), timeout=2):
                return found[0]
        if time.monotonic() > deadline:
            raise TimeoutError(f"the grading service did not answer on 127.0.0.1:{port} within {timeout:.0f} s:\n"
                               f"{hub.log_tail()}")
        time.sleep(0.2)


def sandboxed(process: psutil.Process) -> list[psutil.Process]:
    """The processes below `process` that run in the grader's sandbox (autograder/sandbox/sandbox_entry.py)."""
    from autograder.sandbox.namespaces import ENTRY

    try:
        below = process.children(recursive=True)
    except psutil.Error:
        return []
    return [child for child in below if str(ENTRY) in _cmdline(child)]


def _cmdline(process: psutil.Process) -> list[str]:
    try:
        return process.cmdline()
    except psutil.Error:
        return []


#: A row of the grading service's page (coursehub.grading_status.page).
_STATUS_ROW = r"<tr class='submission (\w+)'><td>([^<]*)</td><td>(\d+)</td><td>[^<]*</td><td>([^<]*)</td></tr>"


def submission_states(html_text: str) -> list[dict]:
    """The rows of the grading service's page: state, assignment, attempt, what it says (newest first)."""
    import html
    import re

    return [{"state": state, "assignment": assignment, "attempt": int(attempt), "says": html.unescape(says)}
            for state, assignment, attempt, says in re.findall(_STATUS_ROW, html_text)]


#: What a student may open of the hub directory ({hub}; {me}: the student; * within a folder, ** across
#: folders): the nbgrader settings and Submit rules every server reads, the hub's socket, their own
#: server's folder, and nbgrader's exchange as nbgrader makes it (outbound/ for all; a submission or a
#: feedback page by its unguessable name, in a folder nobody may list). Nothing of the instructor's
#: course directory or of the repository's closed folders.
STUDENT_MAY_READ = ("{hub}/jupyter", "{hub}/jupyter/nbgrader_config.py", "{hub}/jupyter/submit_rules.json",
                    "{hub}/jupyter/.submit_rules.json.tmp", "{hub}/run/hub.sock", "{hub}/run/{me}",
                    "{hub}/run/{me}/**", "{hub}/exchange", "{hub}/exchange/*", "{hub}/exchange/*/outbound",
                    "{hub}/exchange/*/outbound/**", "{hub}/exchange/*/inbound/**", "{hub}/exchange/*/feedback/**")
#: What a student's server and login need to open: the settings, the hub's and their server's sockets,
#: the course's library and lessons in the repository.
STUDENT_NEEDS = ("{hub}/jupyter/nbgrader_config.py", "{hub}/run/hub.sock", "{hub}/run/{me}/server.sock",
                 f"{REPO}/course_lib/__init__.py", f"{REPO}/notebooks")


def closed_folders() -> list[Path]:
    """The repository's folders no student may open on the real filesystem: at least the instructor's
    folders their servers hide (autograder.sandbox.namespaces.HIDDEN_FROM_STUDENTS), the git history and `make
    lab`'s course, and whatever else coursehub closes."""
    from autograder.sandbox.namespaces import HIDDEN_FROM_STUDENTS
    from coursehub import closed_repository

    closed = {*HIDDEN_FROM_STUDENTS, REPO / ".git", REPO / ".lab", *closed_repository.closed_folders()}
    return sorted(path for path in closed if path.exists())


def student_access(hub: Hub, student: str) -> dict[str, list[str]]:
    """Every file and folder of the hub directory, the instructor's course directory and the
    repository's closed folders that `student` opens (their uid and groups, as a login gives them)
    and STUDENT_MAY_READ does not allow; and what of STUDENT_NEEDS they cannot open."""
    places = {"hub": hub.hub_dir, "me": student}
    allowed = [re.compile(re.escape(glob.format(**places)).replace(r"\*\*", ".*").replace(r"\*", "[^/]*") + "$")
               for glob in STUDENT_MAY_READ]
    found = [str(path) for root in [hub.hub_dir, hub.course_dir, *closed_folders()] for path in _every_path(root)]
    needed = [glob.format(**places) for glob in STUDENT_NEEDS]
    opened = set(opened_as(student, found + needed))
    return {"opened, not allowed": [p for p in found if p in opened and not any(a.match(p) for a in allowed)],
            "needed, not opened": [p for p in needed if p not in opened]}


def _every_path(root: Path) -> list[Path]:
    paths = [root]
    for folder, dirs, files in os.walk(root):  # (a file gone meanwhile is left out, or found not to open)
        paths += [Path(folder) / name for name in dirs + files]
    return paths


def opened_as(user: str, paths: list[str]) -> list[str]:
    """Those of `paths` that `user` opens (a file or folder for reading, a socket to connect to), tried
    in a child process with the user's uid, gid and groups."""
    account = pwd.getpwnam(user)
    groups = os.getgrouplist(user, account.pw_gid)
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child never returns: it answers through the pipe and exits
        code = 1
        try:
            os.close(read)
            os.setgroups(groups)
            os.setgid(account.pw_gid)
            os.setuid(account.pw_uid)
            with os.fdopen(write, "w") as answer:
                answer.write(json.dumps([n for n, path in enumerate(paths) if _opens(path)]))
            code = 0
        finally:
            os._exit(code)
    os.close(write)
    with os.fdopen(read) as answer:
        text = answer.read()
    _, status = os.waitpid(pid, 0)
    assert status == 0 and text, f"the check as {user} failed (wait status {status})"
    return [paths[n] for n in json.loads(text)]


def _opens(path: str) -> bool:
    try:
        if stat.S_ISSOCK(os.lstat(path).st_mode):
            with socket.socket(socket.AF_UNIX) as door:
                door.connect(path)
        else:
            os.close(os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_NOCTTY))
    except (PermissionError, FileNotFoundError):
        return False
    except OSError:  # allowed, but not now (a socket nobody listens on, say)
        return True
    return True


def enroll(hub: Hub, students: list[str]) -> None:
    """Add accounts of the course's group to the roster of the running hub, as running create-course
    again with a longer roster does for the grading service (its roster is course.json), without
    the lessons and settings each new home would get."""
    from coursehub import accounts
    from coursehub import course as course_settings

    group = f"{hub.instructor[:-1]}g"
    for student in students:
        accounts.ensure_user(student, group)
    course = course_settings.load(hub.hub_dir)
    course.students = sorted({*course.students, *students})
    course.save()


def wait_until_gone(process, timeout: float = 60) -> None:
    """Wait until `process` has ended (a zombie its parent has not reaped yet counts as ended)."""
    deadline = time.monotonic() + timeout
    while True:
        try:
            if process.status() == psutil.STATUS_ZOMBIE:
                return
        except psutil.NoSuchProcess:
            return
        assert time.monotonic() < deadline, f"{process} still runs after {timeout:.0f} s"
        time.sleep(0.1)


def wait_until(condition, timeout: float = 60) -> None:
    """Wait until `condition()` holds (the suite's backstop: `timeout` s)."""
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, f"not true after {timeout:.0f} s: {condition}"
        time.sleep(0.1)


def work_folders_of(processes: list[psutil.Process]) -> set[Path]:
    """The grading work folders (autograder.grading.work_folders) the sandboxed `processes` run in, read
    from their command lines (nbgrader's --CourseDirectory.root=<work folder>/course)."""
    from autograder.grading import work_folders

    found = set()
    for process in processes:
        for word in _cmdline(process):
            for part in Path(word.split("=", 1)[-1]).parents:
                if part.name.startswith(work_folders.PREFIX):
                    found.add(part)
    return found
