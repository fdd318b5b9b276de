"""Which named node processes run on this machine, and which program started them.

A notebook's kernel keeps running when its tab is closed, and so do the node processes it
started: a lesson left without its clean-up cell leaves its camera publishing. Each
:class:`course_lib.ros.processes.NodeProcess` started with a name records itself here (a small JSON
file per process in a folder of the user's), so that a process started under the same name
elsewhere, in the same ROS domain, can say plainly which notebook still runs the other one.
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path


def _folder() -> Path:
    """The notes of this user's processes in this process-id namespace. Process ids mean something
    only in their own namespace: a process in the grader's sandbox (a namespace of its own, with
    /tmp shared) would take every note of the machine's for one of a process that has ended."""
    try:
        namespace = os.readlink("/proc/self/ns/pid").strip("pid:[]")
    except OSError:
        namespace = "unknown"
    return Path(tempfile.gettempdir()) / f"course_lib-running-{os.getuid()}-{namespace}"


def _alive(pid) -> bool:
    try:
        os.kill(int(pid), 0)
    except (OSError, ValueError, TypeError):
        return False
    return True


def record(name: str, domain_id: int, pid: int) -> None:
    """Note that node process ``pid``, called ``name``, runs in ``domain_id`` for this program."""
    folder = _folder()
    folder.mkdir(mode=0o700, exist_ok=True)
    entry = {"name": name, "domain_id": domain_id, "pid": pid, "owner": os.getpid(),
             "notebook": os.environ.get("JPY_SESSION_NAME", "")}
    (folder / f"{pid}.json").write_text(json.dumps(entry))


def forget(pid: int | None) -> None:
    """Remove the note of node process ``pid`` (it has ended)."""
    if pid is not None:
        (_folder() / f"{pid}.json").unlink(missing_ok=True)


def started_elsewhere(name: str, domain_id: int) -> list[dict]:
    """The live node processes called ``name`` in ``domain_id`` that another program started.

    Returns:
        their notes: {"name", "domain_id", "pid", "owner", "notebook"}; notes of processes that
        have ended are removed on the way.
    """
    found = []
    for path in sorted(_folder().glob("*.json")):
        try:
            entry = json.loads(path.read_text())
        except (OSError, ValueError):
            continue
        if not (_alive(entry.get("pid")) and _alive(entry.get("owner"))):
            path.unlink(missing_ok=True)
            continue
        if entry.get("name") == name and entry.get("domain_id") == domain_id and entry.get("owner") != os.getpid():
            found.append(entry)
    return found


def describe(entry: dict) -> str:
    """Who started a noted process, in words: 'notebook 02_images_and_brightness.ipynb (its kernel
    still runs)' or 'process 1234'."""
    if entry.get("notebook"):
        return f"notebook {Path(entry['notebook']).name} (its kernel still runs)"
    return f"process {entry.get('owner')}"
