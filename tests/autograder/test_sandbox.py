"""The grader's sandbox (autograder.sandbox.namespaces), run for real: what a sandboxed process can and
cannot see, without a notebook or nbgrader (the grading runs cover those end to end)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from autograder.sandbox import namespaces
from course_lib import contract
from course_lib.ros import processes
from course_lib.supervision import process_tree

needs_namespaces = pytest.mark.skipif(namespaces.isolation() == "none",
                                      reason="no namespaces here (not root, no user namespaces): "
                                             "the sandbox runs commands unwrapped")
needs_root = pytest.mark.skipif(os.geteuid() != 0, reason="per-uid isolation needs root")


def _inside(code: str, hide=(), env=None) -> subprocess.CompletedProcess:
    """Run Python `code` in the sandbox with `hide` hidden; its output and exit code."""
    command = namespaces.sandbox_command([sys.executable, "-c", code], [Path(p) for p in hide])
    return subprocess.run(command, capture_output=True, text=True, timeout=60, env={**os.environ, **(env or {})})


@needs_namespaces
def test_only_loopback_exists_and_is_up():
    """The sandbox has no network interface but loopback, and loopback carries traffic (DDS needs it)."""
    done = _inside("import socket\n"
                   "print(sorted(name for _, name in socket.if_nameindex()))\n"
                   "server = socket.socket(); server.bind(('127.0.0.1', 0)); server.listen()\n"
                   "client = socket.create_connection(server.getsockname(), timeout=5)\n"
                   "peer, _ = server.accept(); client.sendall(b'ping'); print(peer.recv(4).decode())\n"
                   "try:\n"
                   "    socket.create_connection(('192.0.2.1', 80), timeout=5)\n"
                   "except OSError as error:\n"
                   "    print('outside:', error.strerror)\n")
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == ["['lo']", "ping", "outside: Network is unreachable"]


@needs_namespaces
def test_hidden_folders_look_empty_and_others_stay(tmp_path):
    """A hidden folder is an empty mount inside (its files unreadable by path); the sandbox changes
    nothing outside, and a folder not hidden keeps its files."""
    hidden, kept = tmp_path / "course", tmp_path / "kept"
    hidden.mkdir()
    kept.mkdir()
    (hidden / "gradebook.db").write_text("secret")
    (kept / "module.py").write_text("x = 1")
    done = _inside(f"import os\nprint(os.listdir({str(hidden)!r}), os.listdir({str(kept)!r}))\n"
                   f"print(os.path.exists({str(hidden / 'gradebook.db')!r}))", hide=[hidden, tmp_path / "missing"])
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == ["[] ['module.py']", "False"]
    assert (hidden / "gradebook.db").read_text() == "secret"


@needs_namespaces
def test_the_repository_instructor_folders_are_hidden():
    """HIDDEN_FROM_STUDENTS (reference solutions, the grader, the tests) are empty inside."""
    folders = [str(p) for p in namespaces.HIDDEN_FROM_STUDENTS]
    done = _inside(f"import os\nprint([os.listdir(p) for p in {folders!r}])", hide=namespaces.HIDDEN_FROM_STUDENTS)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == str([[] for _ in folders])
    assert any(Path(__file__).parent.iterdir())  # still there outside


@needs_namespaces
def test_dev_shm_is_private_and_writable_by_anyone(tmp_path):
    """/dev/shm inside is a tmpfs of its own, mode 0777 without sticky bit (Fast DDS ports): a file
    made there is gone outside, and the host's /dev/shm files are not seen inside."""
    outside = Path("/dev/shm") / f"autograder-test-{os.getpid()}"
    outside.write_text("host")
    try:
        done = _inside("import os, stat\n"
                       f"print(os.path.exists({str(outside)!r}), oct(stat.S_IMODE(os.stat('/dev/shm').st_mode)))\n"
                       "open('/dev/shm/made-inside', 'w').write('x')")
    finally:
        outside.unlink()
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False 0o777"
    assert not Path("/dev/shm/made-inside").exists()


@needs_root
def test_interpreter_below_a_closed_folder_is_reachable_for_another_uid_and_nothing_else(tmp_path):
    """With the interpreter exposed (interpreter_exposure), a student's uid runs it inside the sandbox,
    and the closed folder holds nothing but the path to the interpreter."""
    exposure = namespaces.interpreter_exposure()
    if not exposure:
        pytest.skip(f"this interpreter ({sys.base_prefix}) is reachable for every uid already")
    stage = tmp_path / "stage"
    stage.mkdir()
    blocked = exposure["AUTOGRADER_BLOCKED"]
    command = namespaces.sandbox_command(
        ["setpriv", "--reuid=61999", "--regid=61999", "--clear-groups", "--", sys.executable, "-I", "-c",
         f"import os, sys; print(os.getuid(), os.listdir({blocked!r}) == "
         f"[{Path(sys.base_prefix).relative_to(blocked).parts[0]!r}])"],
        [])
    done = subprocess.run(command, capture_output=True, text=True, timeout=60,
                          env={**os.environ, **exposure, "AUTOGRADER_STAGE": str(stage)})
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "61999 True"


@needs_namespaces
def test_a_command_killed_by_sigkill_is_reported_killed(tmp_path):
    """The sandbox ends as its command ended, also for SIGKILL (which has no handler to reset)."""
    proc = namespaces.run_sandboxed([sys.executable, "-c", "import os; os.kill(os.getpid(), 9)"], [], "killed", None,
                                 {}, tmp_path, processes.Limits(wall_seconds=60))
    assert proc.returncode == -signal.SIGKILL and "Traceback" not in proc.log, (proc.describe_exit(), proc.log)


@needs_namespaces
def test_a_limit_holds_inside_the_sandbox(tmp_path):
    """run_sandboxed applies the Limits to the sandboxed command: memory beyond memory_mb fails."""
    code = "bytearray(512 * 1024 * 1024)"
    proc = namespaces.run_sandboxed([sys.executable, "-c", code], [], "memory hog", None, {}, tmp_path,
                                 processes.Limits(memory_mb=256, wall_seconds=60))
    assert proc.returncode != 0 and "MemoryError" in proc.log, proc.log


#: Left behind by a sandboxed command: a daemon (its own session, re-parented) that sleeps.
DAEMON = ("import os, sys, time\n"
          "if os.fork() == 0:\n"
          "    os.setsid()\n"
          "    if os.fork() == 0:\n"
          "        time.sleep(600)\n"
          "    os._exit(0)\n"
          "os.wait()\n"
          "print('pid', os.getpid())\n"
          "sys.exit(5)\n")


@needs_namespaces
def test_nothing_the_command_started_outlives_it():
    """A daemon the command leaves (setsid, double fork) ends with it: the command is pid 2 of a
    process-id namespace whose pid 1 ends with it. Its exit code comes through unchanged."""
    token = f"sandbox-daemon-{os.getpid()}"
    done = _inside(DAEMON + f"# {token}")
    assert (done.returncode, done.stdout) == (5, "pid 2\n"), done.stderr
    left = [pid for pid in os.listdir("/proc") if pid.isdigit() and _has_token(pid, token)]
    assert left == []


def _has_token(pid: str, token: str) -> bool:
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as handle:
            return token.encode() in handle.read()
    except OSError:
        return False


@needs_namespaces
def test_a_stop_reaches_the_command_once_and_its_signal_comes_through():
    """SIGINT to the caller's process group (as NodeProcess.stop sends it) reaches the command,
    and only through the sandbox's outer process, the group's one member (so exactly once); a
    command killed by a signal looks killed by that signal from outside."""
    code = ("import signal, sys, time\n"
            "got = []\n"
            "signal.signal(signal.SIGINT, lambda n, f: got.append(n))\n"
            "print('ready', flush=True)\n"
            "while not got:\n"
            "    time.sleep(0.05)\n"
            "print('got', got, flush=True)\n"
            "signal.signal(signal.SIGTERM, signal.SIG_DFL)\n"
            "import os; os.kill(os.getpid(), signal.SIGTERM)\n")
    command = namespaces.sandbox_command([sys.executable, "-c", code], [])
    proc = subprocess.Popen(command, stdout=subprocess.PIPE, text=True, start_new_session=True)
    try:
        assert proc.stdout.readline() == "ready\n"
        assert [p for p in os.listdir("/proc") if p.isdigit() and _group_of(p) == proc.pid] == [str(proc.pid)]
        os.killpg(proc.pid, signal.SIGINT)
        assert proc.stdout.readline() == f"got [{int(signal.SIGINT)}]\n"
        assert proc.wait(60) == -signal.SIGTERM
    finally:
        proc.kill()
        proc.wait()


def _group_of(pid: str) -> int | None:
    try:
        return int(process_tree.stat_fields(int(pid))[2])
    except (OSError, IndexError, ValueError):
        return None


@needs_namespaces
def test_a_process_in_the_sandbox_leaves_the_notes_of_the_machines_named_processes_alone():
    """course_lib.supervision.process_registry's notes hold process ids: the sandbox's own process-id namespace
    must not take a running process of the machine for one that has ended and delete its note
    (a clean-clone run lost lesson 02's camera note so, and lesson 03 then did not name it)."""
    from course_lib.supervision import process_registry

    process_registry.record("registry_probe", 7, os.getpid())
    try:
        done = _inside("from course_lib import process_registry\n"
                       "print(process_registry.started_elsewhere('registry_probe', 7))\n",
                       env={"PYTHONPATH": str(contract.ROOT)})
        assert (done.returncode, done.stdout) == (0, "[]\n"), done.stderr
        assert [e["pid"] for e in process_registry.started_elsewhere("registry_probe", 7)] == []  # own
        notes = list(process_registry._folder().glob(f"{os.getpid()}.json"))
        assert len(notes) == 1, "the sandboxed process deleted the machine's note"
    finally:
        process_registry.forget(os.getpid())
