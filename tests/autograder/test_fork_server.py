"""The grader's fork server (autograder.grading.fork_server), run for real: a program it runs for a client in
the sandbox is where the client is (its namespaces, limits, folder, environment and streams), ends
as the client reports, and ends with the client; other uids are not served. Gradings through it:
test_autograder_pipeline and the zoo."""

from __future__ import annotations

import os
import signal
import sys
import time
from pathlib import Path

import pytest

from autograder.grading import fork_server
from autograder.sandbox import namespaces as sandbox
from course_lib import contract
from course_lib.ros import processes

REPO = contract.ROOT
#: The run's memory limit: a fork of this test process maps as much as it does, a few GB with rclpy.
MEMORY_MB = 16384
pytestmark = pytest.mark.skipif(sandbox.isolation() != "root", reason="the fork server serves the root sandbox only")

#: The program: named NAME (its comm), it reports where it runs, then ends as told.
PROGRAM = """import ctypes, json, os, resource, socket, sys, time
name, end = sys.argv[1], sys.argv[2]
ctypes.CDLL(None).prctl(15, name.encode(), 0, 0, 0)
print(json.dumps({"interfaces": sorted(n for _, n in socket.if_nameindex()), "pid": os.getpid(),
                  "hidden": os.listdir(os.environ["HIDDEN"]), "cwd": os.getcwd(), "flag": os.environ.get("FLAG"),
                  "memory": resource.getrlimit(resource.RLIMIT_AS)[0], "umask": os.umask(0)}), flush=True)
print("to stderr", file=sys.stderr, flush=True)
if end == "sleep":
    time.sleep(600)
elif end == "kill":
    os.kill(os.getpid(), 9)
sys.exit(int(end))
"""


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    folder = tmp_path_factory.mktemp("program")
    (folder / "fork_probe.py").write_text(PROGRAM)
    served = fork_server.ForkServer(programs=("fork_probe",), preload=())
    served.path = folder
    yield served
    served.close()
    assert not served.alive()


def _run(server, tmp_path, end: str, name: str, wall: float = 60.0, on_start=None):
    hidden = tmp_path / "hidden"
    hidden.mkdir(exist_ok=True)
    (hidden / "secret").write_text("x")
    env = {"PYTHONPATH": str(server.path), "HIDDEN": str(hidden), "FLAG": "set"}
    command = server.command("fork_probe", [name, end], REPO)
    return sandbox.run_sandboxed(command, [hidden], "fork probe", None, env, tmp_path,
                                 processes.Limits(wall_seconds=wall, memory_mb=MEMORY_MB, grace_seconds=1.0),
                                 on_start=on_start)


def _alive(name: str) -> bool:
    """Whether a process whose comm is `name` runs on this machine."""
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            if Path(f"/proc/{pid}/comm").read_text().strip() == name:
                return True
        except OSError:
            continue
    return False


def test_a_run_is_in_the_clients_sandbox_with_its_limits_folder_and_environment(server, tmp_path):
    """Only loopback, the hidden folder empty, a small pid (its own pid namespace), the client's
    memory limit, folder and variables; its output and exit code are the client's."""
    import json

    proc = _run(server, tmp_path, "3", "fork-probe-a")
    assert proc.returncode == 3, proc.log
    seen = json.loads(proc.log.splitlines()[0])
    assert seen["interfaces"] == ["lo"] and seen["hidden"] == [] and seen["pid"] < 20, seen
    assert (seen["memory"], seen["cwd"], seen["flag"]) == (MEMORY_MB << 20, str(tmp_path), "set"), seen
    assert "to stderr" in proc.log


def test_a_run_killed_by_a_signal_is_reported_as_killed(server, tmp_path):
    proc = _run(server, tmp_path, "kill", "fork-probe-k")
    assert "SIGKILL" in proc.describe_exit() or proc.returncode in (-9, 137), proc.describe_exit()


def test_a_stop_at_the_wall_time_ends_the_run(server, tmp_path):
    """The sandbox's stop reaches the run through the client; nothing of it is left."""
    started = time.monotonic()
    proc = _run(server, tmp_path, "sleep", "fork-probe-s", wall=3.0)
    assert proc.exit_reason == "wall_seconds" and time.monotonic() - started < 30
    deadline = time.monotonic() + 10
    while _alive("fork-probe-s") and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not _alive("fork-probe-s")


def test_killing_the_client_ends_the_run(server, tmp_path):
    """The client gone (SIGKILL, no word to pass on): the handler kills the run."""
    client = {}

    def kill_client(proc):
        deadline = time.monotonic() + 30
        while not _alive("fork-probe-c") and time.monotonic() < deadline:
            time.sleep(0.05)
        for pid in filter(str.isdigit, os.listdir("/proc")):
            try:
                cmdline = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
            except OSError:
                continue
            if any(part.endswith(b"fork_client.py") for part in cmdline[:4]) and b"fork-probe-c" in cmdline:
                client["pid"] = int(pid)
                os.kill(int(pid), signal.SIGKILL)

    proc = _run(server, tmp_path, "sleep", "fork-probe-c", wall=60.0, on_start=kill_client)
    assert client, "the client was not found"
    assert proc.returncode != 0
    assert not _alive("fork-probe-c")


def test_another_uid_cannot_reach_the_socket(server):
    """The socket's folder is root's alone: a process of a student's uid cannot connect."""
    import socket
    import stat

    folder = os.stat(server.folder)
    assert (folder.st_uid, stat.S_IMODE(folder.st_mode)) == (0, 0o700)
    child = os.fork()
    if child == 0:  # only system calls here, then out
        code = 4
        try:
            os.setgid(61999)
            os.setuid(61999)
            socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET).connect(server.socket_path)
            code = 0
        except PermissionError:
            code = 3
        finally:
            os._exit(code)
    assert os.waitstatus_to_exitcode(os.waitpid(child, 0)[1]) == 3


def test_program_falls_back_to_a_python_of_its_own_without_a_server():
    """No server serving this process: the program starts as ``python -m``."""
    assert fork_server.current() is None
    assert fork_server.program("autograder.grading.sandboxed_autograde", ["a"], {"PYTHONPATH": str(REPO)}) == [
        sys.executable, "-m", "autograder.grading.sandboxed_autograde", "a"]


def test_program_goes_through_the_server_while_one_serves():
    """Serving: the grader's programs start as the client, found in the sandbox's grader copy."""
    with fork_server.serving() as server:
        command = fork_server.program(fork_server.PROGRAMS[0], ["a"], {"PYTHONPATH": f"/nowhere:{REPO}"})
    assert command == [sys.executable, "-I", "-S", str(REPO / fork_server.CLIENT_IN_PACKAGE), server.socket_path,
                       fork_server.PROGRAMS[0], "a"]
    assert not server.alive()


#: A grader that has run rclpy.init (a test's process, say) serves a run that starts ROS: the
#: server must not be a fork of it (rclpy's signal thread, a C++ object, would be copied without
#: its thread, and the run would end with "std::system_error: Invalid argument", SIGABRT).
GRADER_AFTER_RCLPY = """import json, sys
from pathlib import Path
import rclpy
rclpy.init()
rclpy.create_node("the_graders_own").destroy_node()
rclpy.shutdown()
from autograder.grading import fork_server
from autograder.sandbox import namespaces
from course_lib.ros import processes
folder = Path(sys.argv[1])
server = fork_server.ForkServer(programs=("ros_probe",), preload=())
try:
    proc = namespaces.run_sandboxed(server.command("ros_probe", [], Path(sys.argv[2])), [], "ros probe", None,
                                    {"PYTHONPATH": str(folder)}, folder,
                                    processes.Limits(wall_seconds=60, memory_mb=16384, grace_seconds=1.0))
    print(json.dumps({"forkable": fork_server.forkable(), "code": proc.returncode, "log": proc.log[-3000:]}))
finally:
    server.close()
"""
ROS_PROBE = """import rclpy
rclpy.init()
node = rclpy.create_node("ros_probe")
print("node", node.get_name())
node.destroy_node()
rclpy.shutdown()
"""


def test_a_grader_that_ran_rclpy_serves_runs_that_start_ros(tmp_path):
    import json
    import subprocess

    (tmp_path / "ros_probe.py").write_text(ROS_PROBE)
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    done = subprocess.run([sys.executable, "-c", GRADER_AFTER_RCLPY, str(tmp_path), str(REPO)], env=env,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-3000:]
    report = json.loads(done.stdout.strip().splitlines()[-1])
    assert report["forkable"] is False
    assert report["code"] == 0 and "node ros_probe" in report["log"], report["log"]


def test_the_folder_of_a_killed_server_is_removed_by_the_next_and_a_live_ones_stays():
    """A grader killed with SIGKILL leaves its server's socket folder; the next server removes it."""
    live = fork_server.ForkServer(programs=("fork_probe",), preload=())
    killed = fork_server.ForkServer(programs=("fork_probe",), preload=())
    try:
        os.kill(killed.pid, signal.SIGKILL)
        os.waitpid(killed.pid, 0)
        killed.pid = None
        assert killed.folder.is_dir()
        next_one = fork_server.ForkServer(programs=("fork_probe",), preload=())
        next_one.close()
        assert not killed.folder.exists() and live.folder.is_dir() and live.alive()
    finally:
        live.close()
        killed.close()
