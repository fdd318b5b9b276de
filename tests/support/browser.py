"""Drive the course in JupyterLab as a student does: a real server, headless Chromium, the menus.

The pieces, each usable on its own:

- ``find_chromium`` / ``launched_chromium``: Debian's chromium driven by Playwright;
- ``running_jupyterlab``: a JupyterLab server on a directory, with a token and a free port,
  whose settings and workspaces live in a scratch directory (nothing in ~/.jupyter changes);

The notebook UI (opening a notebook, its toolbar and menus, Run All Cells) is browser_notebook's;
nbgrader's Validate button and Assignments panel are driven by browser_nbgrader.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.parse
import urllib.request
from pathlib import Path

import psutil

CHROMIUM = "chromium"
CHROMIUM_FIX = "install Debian's chromium: apt-get install chromium (`make test` does this when run as root)"
# Without the background-networking flags Chromium keeps calling Google services, which on a
# closed network floods the log and slows every page.
CHROMIUM_ARGS = [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
]
VIEWPORT = {"width": 1280, "height": 900}

# JupyterLab settings for the test server. windowingMode "none" attaches and lays out every
# cell, so every output is in the DOM (images decoded, prompts present) and the screenshot can
# show the whole notebook; the student default only lays out cells near the viewport.
LAB_SETTINGS = {
    "@jupyterlab/notebook-extension/tracker.jupyterlab-settings": {"windowingMode": "none"},
    # No news or update checks: the test is offline, and the prompt would cover the notebook.
    "@jupyterlab/apputils-extension/notification.jupyterlab-settings": {
        "fetchNews": "false", "checkForUpdates": False},
}


class ChromiumUnavailable(RuntimeError):
    """Chromium is missing or does not start; the message says what was tried and the fix."""


def find_chromium() -> str:
    """Return the path of the chromium executable on PATH.

    Raises:
        ChromiumUnavailable: when there is none.
    """
    path = shutil.which(CHROMIUM)
    if path is None:
        raise ChromiumUnavailable(f"no `{CHROMIUM}` executable on PATH ({os.environ.get('PATH', '')}); "
                                  f"{CHROMIUM_FIX}")
    return path


@contextlib.contextmanager
def launched_chromium(user_data_dir: Path):
    """Start headless Chromium with a fresh profile in user_data_dir; yield a Playwright context.

    Raises:
        ChromiumUnavailable: when chromium is missing or fails to start.
    """
    from playwright.sync_api import Error as PlaywrightError
    from playwright.sync_api import sync_playwright

    executable = find_chromium()
    with sync_playwright() as playwright:
        try:
            context = playwright.chromium.launch_persistent_context(
                str(user_data_dir), executable_path=executable, headless=True, args=CHROMIUM_ARGS,
                viewport=VIEWPORT, timeout=60_000)
        except PlaywrightError as error:
            lines = str(error).splitlines()
            stderr = list(dict.fromkeys(line.strip(" -") for line in lines if "[err]" in line))
            said = "\n".join(lines[:1] + stderr[:8])
            raise ChromiumUnavailable(f"{executable} did not start under Playwright: {said}\n"
                                      f"Check that it runs: {executable} --headless --dump-dom about:blank; "
                                      f"or {CHROMIUM_FIX}") from error
        try:
            yield context
        finally:
            context.close()


@dataclasses.dataclass
class JupyterLab:
    """A running JupyterLab server.

    Attributes:
        url: base URL, without a trailing slash.
        token: the access token.
        root_dir: the directory the server shows; notebook paths are relative to it.
        process: the server process.
        log_path: where the server writes its log.
        startup_seconds: time from launch until the server answered.
    """

    url: str
    token: str
    root_dir: Path
    process: subprocess.Popen
    log_path: Path
    startup_seconds: float

    def lab_url(self, path: str) -> str:
        """The URL that opens the notebook at path in a workspace of its own (no restored tabs)."""
        workspace = "test-" + "".join(c if c.isalnum() else "-" for c in path)
        return (f"{self.url}/lab/workspaces/{workspace}/tree/{urllib.parse.quote(path)}"
                f"?token={self.token}")

    def api(self, method: str, endpoint: str, timeout: float = 30):
        """Call the Jupyter server REST API; return the decoded JSON (None for an empty body)."""
        request = urllib.request.Request(f"{self.url}/api/{endpoint}", method=method,
                                         headers={"Authorization": f"token {self.token}"})
        with urllib.request.urlopen(request, timeout=timeout) as response:
            body = response.read()
        return json.loads(body) if body else None

    def descendants(self) -> list[psutil.Process]:
        with contextlib.suppress(psutil.NoSuchProcess):
            return psutil.Process(self.process.pid).children(recursive=True)
        return []

    def shut_down_kernels_of(self, path: str, timeout: float = 30) -> None:
        """End the sessions (and kernels) of the notebook at path, and whatever those kernels started.

        A node process a kernel started outlives the kernel as an orphan; it is ended here
        (by pid, after a grace period), since the server no longer knows about it.
        """
        before = self.descendants()
        kernel_ids = set()
        for session in self.api("GET", "sessions"):
            if session.get("path") == path:
                kernel_ids.add((session.get("kernel") or {}).get("id"))
                self.api("DELETE", f"sessions/{session['id']}")
        deadline = time.monotonic() + timeout
        while kernel_ids & {k["id"] for k in self.api("GET", "kernels")} and time.monotonic() < deadline:
            time.sleep(0.25)
        still_served = set(self.descendants())
        _end_processes([p for p in before if p not in still_served], grace=10)

    def kernel_stacks(self, settle: float = 0.5, timeout: float = 10) -> str:
        """Every thread's Python stack in each kernel of the server, as the kernels print them to
        the log on SIGUSR1 (STACKS_ON_SIGUSR1): where a notebook that never ends waits."""
        start = self.log_path.stat().st_size
        kernels = self.kernels_that_print_stacks()
        for pid in kernels:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGUSR1)
        size, deadline = start, time.monotonic() + timeout
        while kernels and time.monotonic() < deadline:  # until the log stops growing
            time.sleep(settle)
            size, grown = self.log_path.stat().st_size, size
            if size == grown > start:
                break
        with open(self.log_path, "rb") as log:
            log.seek(start)
            return f"kernels {kernels}:\n" + log.read().decode(errors="replace")

    def kernels_that_print_stacks(self) -> list[int]:
        """The pids of the server's kernels that handle SIGUSR1 (the startup file has run: to a
        kernel without the handler the signal would be the end)."""
        pids = []
        for process in self.descendants():
            with contextlib.suppress(psutil.Error, OSError):
                if "ipykernel_launcher" in " ".join(process.cmdline()) and _catches(process.pid, signal.SIGUSR1):
                    pids.append(process.pid)
        return pids

    def log_tail(self, lines: int = 30) -> str:
        text = self.log_path.read_text(errors="replace") if self.log_path.exists() else ""
        return "\n".join(text.splitlines()[-lines:])


def _catches(pid: int, number: int) -> bool:
    """Whether the process has a handler for the signal (the SigCgt mask of /proc/PID/status)."""
    with open(f"/proc/{pid}/status") as status:
        mask = next(line.split()[1] for line in status if line.startswith("SigCgt:"))
    return bool(int(mask, 16) >> (number - 1) & 1)


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


#: An IPython startup file for the tests' kernels: SIGUSR1 prints every thread's Python stack to
#: the kernel's own stderr, which is the server's log (JupyterLab.kernel_stacks).
STACKS_ON_SIGUSR1 = """import faulthandler, signal, sys
faulthandler.register(signal.SIGUSR1, file=sys.__stderr__, all_threads=True)
"""


@contextlib.contextmanager
def running_jupyterlab(root_dir: Path, state_dir: Path, timeout: float = 120):
    """Start JupyterLab on root_dir (settings, workspaces, log in state_dir); yield a JupyterLab.

    The server inherits os.environ, so its kernels get the test run's ROS_DOMAIN_ID and
    COURSE_LIB_UNDER_TEST. On exit the server, its kernels and their children are ended.

    Raises:
        RuntimeError: when the server exits or does not answer within timeout seconds.
    """
    settings_dir = state_dir / "settings"
    for name, values in LAB_SETTINGS.items():
        target = settings_dir / name
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(json.dumps(values))
    startup = state_dir / "ipython" / "profile_default" / "startup" / "00_stacks_on_sigusr1.py"
    startup.parent.mkdir(parents=True, exist_ok=True)
    startup.write_text(STACKS_ON_SIGUSR1)
    from course_lib.notebook import student_lab

    env = dict(os.environ, IPYTHONDIR=str(state_dir / "ipython"),
               # As `make lab` does: nbgrader's student side only (course_lib/notebook/student_lab).
               JUPYTER_CONFIG_PATH=os.pathsep.join(filter(None, [str(student_lab.CONFIG_DIR),
                                                                  os.environ.get("JUPYTER_CONFIG_PATH")])),
               JUPYTERLAB_SETTINGS_DIR=str(settings_dir),
               JUPYTERLAB_WORKSPACES_DIR=str(state_dir / "workspaces"),
               JUPYTER_RUNTIME_DIR=str(state_dir / "runtime"))
    token, port = secrets.token_hex(16), free_port()
    command = [
        sys.executable, "-m", "jupyterlab", "--no-browser", "--ip=127.0.0.1", f"--port={port}",
        "--ServerApp.port_retries=0", f"--IdentityProvider.token={token}",
        f"--ServerApp.root_dir={root_dir}",
        # window.jupyterapp lets the checker read output models: JupyterLab renders an error
        # with the same stderr renderer as a warning, so the DOM cannot tell them apart.
        "--LabApp.expose_app_in_browser=True",
        "--LabApp.news_url=None", "--LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate",
    ]
    if os.geteuid() == 0:  # CI containers run as root; JupyterLab refuses that unless told
        command.append("--allow-root")
    log_path = state_dir / "jupyterlab.log"
    started = time.monotonic()
    with open(log_path, "wb") as log:
        process = subprocess.Popen(command, cwd=root_dir, env=env, stdout=log, stderr=subprocess.STDOUT,
                                   stdin=subprocess.DEVNULL, start_new_session=True)
    lab = JupyterLab(f"http://127.0.0.1:{port}", token, Path(root_dir), process, log_path, 0.0)
    try:
        while True:
            if process.poll() is not None:
                raise RuntimeError(f"JupyterLab exited with {process.returncode}:\n{lab.log_tail()}")
            try:
                lab.api("GET", "status", timeout=5)
                break
            except (urllib.error.URLError, ConnectionError, TimeoutError):
                pass
            if time.monotonic() - started > timeout:
                raise RuntimeError(f"JupyterLab did not answer on {lab.url} within {timeout:.0f} s:\n"
                                   f"{lab.log_tail()}")
            time.sleep(0.25)
        lab.startup_seconds = time.monotonic() - started
        yield lab
    finally:
        _end_process_tree(process)


def _end_process_tree(process: subprocess.Popen, grace: float = 15) -> None:
    """End a server and every process it started (kernels run in sessions of their own)."""
    try:
        descendants = psutil.Process(process.pid).children(recursive=True)
    except psutil.NoSuchProcess:
        descendants = []
    if process.poll() is None:
        process.send_signal(signal.SIGTERM)  # the server shuts its kernels down on SIGTERM
        try:
            process.wait(timeout=grace)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(timeout=grace)
    _end_processes(descendants, grace)


def _end_processes(processes: list[psutil.Process], grace: float) -> None:
    """Give processes grace seconds to exit by themselves (they were told to), then kill them."""
    _, alive = psutil.wait_procs(processes, timeout=grace)
    for leftover in alive:
        with contextlib.suppress(psutil.NoSuchProcess):
            leftover.kill()
    psutil.wait_procs(alive, timeout=grace)
