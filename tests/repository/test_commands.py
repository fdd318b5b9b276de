"""The README's commands: `make lab` serves the course; `make setup` is idempotent."""

import os
import re
import signal
import subprocess
import time
import urllib.request

import pytest
from support import course as course_support
from support.browser import free_port

from course_lib import contract
from course_lib.supervision import process_tree

ROOT = contract.ROOT


def test_make_setup_twice_changes_nothing():
    result = subprocess.run(["make", "-s", "setup"], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    again = subprocess.run(["make", "setup"], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert again.returncode == 0 and "Nothing to be done" in again.stdout + again.stderr, again.stdout


@pytest.mark.slow
def test_make_lab_serves_the_course_and_prints_its_url(tmp_path, tmp_path_factory):
    # The assignments in the lab's exchange from the run's shared release: make lab's release-lab
    # (about 45 s of processor time on a fresh clone) then has nothing to do.
    course_support.seed_lab_exchange(tmp_path_factory, ROOT)
    port = free_port()
    log = tmp_path / "lab.log"
    with open(log, "w") as out:
        lab = subprocess.Popen(["make", "-s", "lab", f"LAB_PORT={port}"], cwd=ROOT, stdout=out,
                               stderr=subprocess.STDOUT, start_new_session=True,
                               env={**os.environ, "JUPYTER_RUNTIME_DIR": str(tmp_path)})
    try:
        url = None
        deadline = time.monotonic() + 300  # a backstop: the loop ends when the URL shows or make lab ends
        while url is None and time.monotonic() < deadline and lab.poll() is None:
            found = re.search(rf"http://127\.0\.0\.1:{port}/lab\S*\?token=(\w+)", log.read_text())
            url = found and found.group(0)
            time.sleep(0.5)
        assert url, f"make lab printed no URL:\n{log.read_text()[-2000:]}"
        token = url.rsplit("=", 1)[1]
        listing_url = f"http://127.0.0.1:{port}/api/contents/notebooks?token={token}"
        with urllib.request.urlopen(listing_url, timeout=30) as reply:
            listing = reply.read().decode()
        assert "00_setup_and_workspace.ipynb" in listing
        # A JupyterLab terminal finds the venv's commands, `ros2` among them (on the pip install).
        prefix = terminal_output(port, token, "ros2 pkg prefix std_msgs", until=str(ROOT / ".venv"))
        assert str(ROOT / ".venv") in prefix
    finally:
        process_tree.stop_group(lab, ((signal.SIGTERM, 20), (signal.SIGKILL, 20)))


def terminal_output(port: int, token: str, command: str, until: str, timeout: float = 60) -> str:
    """Open a JupyterLab terminal, type `command`, and return what it printed once `until` shows."""
    import asyncio
    import json

    from tornado.websocket import websocket_connect

    request = urllib.request.Request(f"http://127.0.0.1:{port}/api/terminals?token={token}", method="POST")
    with urllib.request.urlopen(request, timeout=30) as reply:
        name = json.loads(reply.read())["name"]

    async def talk() -> str:
        socket = await websocket_connect(f"ws://127.0.0.1:{port}/terminals/websocket/{name}?token={token}")
        socket.write_message(json.dumps(["stdin", command + "\r"]))
        seen = ""
        while until not in seen.split(command, 1)[-1]:
            message = await socket.read_message()
            if message is None:
                break
            kind, *content = json.loads(message)
            if kind == "stdout":
                seen += content[0]
        socket.close()
        return seen

    return asyncio.run(asyncio.wait_for(talk(), timeout))
