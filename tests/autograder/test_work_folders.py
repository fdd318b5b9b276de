"""Tests for autograder.grading.work_folders: a grading's work folder outlives no process that made it,
and a sweep never takes the folder of a grading that still runs."""

import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from types import SimpleNamespace

import pytest

from autograder.grading import work_folders
from course_lib import contract

REPO = contract.ROOT

#: A grading process: makes its work folder, copies a submission into it, says where, and waits.
MAKE = """
import sys
from autograder.grading import work_folders

work = work_folders.make()
(work / "course").mkdir()
(work / "course" / "submission.ipynb").write_text("{}")
print(work, flush=True)
sys.stdin.read()
"""

#: The grading service's main() as the hub runs it, with a course of nothing: its Service grades
#: in a worker thread, which would record a failure for the student if it saw its folder go. The
#: interpreter's exit runs atexit functions while daemon threads still run; one that lasts until
#: the grading has seen its folder go makes that window as wide as it may be.
SERVICE = """
import atexit, signal, sys, threading, time
from pathlib import Path
from types import SimpleNamespace
from autograder.grading import work_folders
from coursehub import grading_service, grading_status

saw_it_go, grading, to_a_thread = Path(sys.argv[1]), sys.argv[2] != "idle", sys.argv[2] == "thread"
seen = threading.Event()

class Service:
    def __init__(self, course, workers, rules_file):
        self.workers, self.queue, self.stopping = workers, None, threading.Event()

    def start(self):
        if grading:
            threading.Thread(target=self._grade, name="grading-worker-0", daemon=True).start()
        else:
            print("idle", flush=True)

    def rules(self):
        return {}

    def _grade(self):
        work = work_folders.make()
        (work / "submission.ipynb").write_text("{}")
        atexit.register(self.exiting, work)
        print(work, flush=True)
        if to_a_thread:  # as the kernel may deliver the hub's SIGINT: to this thread, the main one in select()
            time.sleep(0.5)
            signal.pthread_kill(threading.get_ident(), signal.SIGINT)
        while (work / "submission.ipynb").exists():  # the grading goes on
            time.sleep(0.01)
        saw_it_go.write_text("a grading saw its folder go, and would record a failure")
        seen.set()

    def exiting(self, work):
        if not work.exists():
            seen.wait(60)

grading_service.Service = Service
grading_service.course_settings.load = lambda hub_dir: SimpleNamespace(submit_rules=None, grading_port=0)
grading_status.application = lambda queue, prefix: SimpleNamespace(listen=lambda port, host: None)
sys.exit(grading_service.main(["--workers", "1"]))
"""


def _python(code: str, tmp: Path, *args: str) -> subprocess.Popen:
    """`code` in a new Python process whose temporary directory is `tmp`; its output in a pipe."""
    return subprocess.Popen([sys.executable, "-c", code, *args], cwd=REPO, env={**os.environ, "TMPDIR": str(tmp)},
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)


def _grading_process(tmp: Path) -> tuple[subprocess.Popen, Path]:
    """A process grading in a work folder of `tmp`, and that folder."""
    process = _python(MAKE, tmp)
    work = Path(process.stdout.readline().strip())
    assert work.parent == tmp.resolve() and (work / "course" / "submission.ipynb").is_file(), work
    return process, work


def _killed_grading(tmp: Path) -> Path:
    """The work folder of a grading process killed with SIGKILL."""
    tmp.mkdir(exist_ok=True)
    process, work = _grading_process(tmp)
    process.kill()
    process.wait(timeout=60)
    assert work.is_dir()
    return work


def test_the_folder_of_a_killed_grading_process_goes_at_the_next_sweep(tmp_path):
    work = _killed_grading(tmp_path)
    assert work_folders.sweep(tmp_path) == [work]
    assert not work.exists()
    assert work_folders.sweep(tmp_path) == []


def test_a_sweep_keeps_the_folders_of_live_gradings_in_other_processes_and_its_own(tmp_path):
    process, theirs = _grading_process(tmp_path)
    try:
        ours = work_folders.make(tmp_path)
        assert work_folders.sweep(tmp_path) == []
        assert (theirs / "course" / "submission.ipynb").is_file() and ours.is_dir()
        work_folders.remove(ours)
        assert not ours.exists()
    finally:
        process.communicate(timeout=60)  # its stdin closed: it ends, without removing its folder
    assert work_folders.sweep(tmp_path) == [theirs]


def test_a_folder_still_written_in_keeps_its_lock_file_for_the_next_sweep(tmp_path, monkeypatch):
    work = work_folders.make(tmp_path)
    (work / "out").mkdir()
    remove_entry = work_folders._remove_entry

    def still_written(entry):  # a sandboxed process of the grading writes again what is removed
        remove_entry(entry)
        (work / "out").mkdir(exist_ok=True)

    monkeypatch.setattr(work_folders, "_remove_entry", still_written)
    work_folders.remove(work)
    assert sorted(p.name for p in work.iterdir()) == sorted([work_folders.LOCK_NAME, "out"])
    monkeypatch.undo()
    assert work_folders.sweep(tmp_path) == [work]
    assert not work.exists()


def test_a_folder_without_a_lock_file_goes_only_when_unchanged_for_a_day(tmp_path):
    """Made by a grader before the lock files (it may still grade in it), or half made when killed."""
    old = tmp_path / f"{work_folders.PREFIX}old"
    (old / "course").mkdir(parents=True)
    assert work_folders.sweep(tmp_path) == []
    past = time.time() - work_folders.UNLOCKED_SECONDS - 60
    os.utime(old, (past, past))
    assert work_folders.sweep(tmp_path) == [old]
    assert not old.exists()


def test_a_sweep_leaves_links_and_other_users_folders_alone(tmp_path):
    """A link named like a work folder (to /tmp, say, with a lock file someone put there) is no
    work folder; another user's folder is theirs to sweep."""
    target = _killed_grading(tmp_path / "elsewhere")
    link = tmp_path / f"{work_folders.PREFIX}link"
    link.symlink_to(target)
    theirs = _killed_grading(tmp_path)
    if os.geteuid() == 0:
        for path in (theirs, *theirs.rglob("*")):
            os.chown(path, 65534, 65534, follow_symlinks=False)
        assert work_folders.sweep(tmp_path) == []
        assert (theirs / "course" / "submission.ipynb").is_file()
        os.chown(theirs, 0, 0)
    assert work_folders.sweep(tmp_path) == [theirs]
    assert link.is_symlink() and (target / "course" / "submission.ipynb").is_file()


def test_the_grading_service_sweeps_when_it_starts(tmp_path, monkeypatch):
    from coursehub import grading_service

    work = _killed_grading(tmp_path / "tmp")
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    service = grading_service.Service(SimpleNamespace(course_dir=tmp_path / "course"), workers=0)
    service.stopping.set()  # its threads end at once
    try:
        service.start()
    finally:
        service.queue.close()
    assert not work.exists()


def test_autograder_grade_sweeps_when_it_starts(tmp_path, monkeypatch):
    from autograder import __main__ as command
    from autograder.term import grade

    work = _killed_grading(tmp_path / "tmp")
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    monkeypatch.setattr(grade, "grade", lambda *args, **kwargs: [])
    assert command.main(["grade", str(tmp_path / "course")]) == 0
    assert not work.exists()


@pytest.mark.parametrize(("stop", "mode"), [(signal.SIGINT, "grading"), (signal.SIGTERM, "grading"),
                                           (signal.SIGTERM, "idle"), (None, "thread")],
                         ids=["SIGINT-grading", "SIGTERM-grading", "SIGTERM-idle", "SIGINT-to-a-worker-thread"])
def test_the_grading_service_stopped_as_the_hub_stops_it_leaves_no_work_folder(tmp_path, stop, mode):
    """The hub stops its services with SIGINT, then SIGTERM; a grading in a worker thread then is cut
    short (the queue grades it again at the next start) and neither sees its folder go nor leaves it.
    A signal the kernel hands to a worker thread while the main thread waits in the loop's select()
    stops the service too (a KeyboardInterrupt waited for select to return, which it never did)."""
    saw_it_go = tmp_path / "saw-it-go"
    service = _python(SERVICE, tmp_path, str(saw_it_go), mode)
    try:
        said = service.stdout.readline().strip()
        assert Path(said).is_dir() if mode != "idle" else said == "idle", said
        if stop is not None:
            service.send_signal(stop)
        assert service.wait(timeout=60) == 0
    finally:
        service.kill()
        service.communicate(timeout=60)
    assert [p.name for p in tmp_path.iterdir()] == []
