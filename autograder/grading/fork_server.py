"""A warm process that the grader's sandboxed programs are forked from (a fork server, as Python's
multiprocessing forkserver and Chromium's zygote are): the notebook's run (autograder.grading.sandboxed_autograde)
starts with nbgrader, nbconvert, nbclient and the grader already imported instead of importing them
again in every submission's sandbox (about 1 CPU-s each).

The grader forks the server before its worker threads start (:func:`serving`); the server imports
the programs' modules once and listens on a Unix socket in a folder only root may enter. A grader
that has loaded rclpy (a test's process) is no safe parent for runs that start ROS
(:func:`forkable`): its server is a fresh Python instead, the same server with imports of its own. In the
sandbox, :meth:`ForkServer.command` runs autograder/grading/fork_client.py in place of
``python -m MODULE ARG...``; for each client the server forks a handler, which

- checks that the client is root (SO_PEERCRED): a student's uid cannot enter the folder, and
  could not be served if it could;
- joins the client's network and mount namespaces and makes its child in its process-id namespace
  (setns), with the client's resource limits (prlimit), so the run is where the client is, bounded
  as the client is, and ends with the sandbox like every process of it;
- runs MODULE as ``__main__`` in that child with the client's environment, working directory, umask
  and standard streams (passed with SCM_RIGHTS), the grader's own modules imported again from the
  client's PYTHONPATH (the sandbox's private copy; the repository's is hidden there);
- passes on the signals the client forwards, kills the run when the client is gone, and tells
  the client how it ended.

Only in the "root" isolation (autograder.sandbox.namespaces): elsewhere :func:`serving` gives None and the
programs start as processes of their own. Everything the server forks is its descendant and is
reaped, so a grade command's processor time (wait4) still counts every run.
"""

from __future__ import annotations

import contextlib
import ctypes
import importlib
import json
import os
import resource
import runpy
import select
import signal
import socket
import stat
import struct
import sys
import tempfile
import traceback
from pathlib import Path

from autograder.sandbox.sandbox_entry import CLONE_NEWPID, FORWARDED, PR_SET_PDEATHSIG

CLIENT = Path(__file__).resolve().parent / "fork_client.py"
#: Where the client is in a folder that holds the autograder package (a copy of it: autograder.grading.staging).
CLIENT_IN_PACKAGE = CLIENT.relative_to(CLIENT.parents[2])
#: The programs the server runs (``python -m`` modules).
NOTEBOOK_RUN = "autograder.grading.sandboxed_autograde"  # the notebook's run (nbgrader's autograde)
CHECKS_RUN = "autograder.grading.hidden_checks_process"  # the hidden checks' process
PROGRAMS = (NOTEBOOK_RUN, CHECKS_RUN)
#: What the programs import when they run, imported by the server once (the grader's own modules
#: are imported again by each run, from the sandbox's copy).
PRELOAD = ("nbgrader.converters", "nbgrader.preprocessors", "nbclient", "jupyter_client", "rclpy",
           "course_lib.checks.registry", "course_lib.checks.student_server", "course_lib.checks.probe",
           *PROGRAMS)
_CLONE_NEWNS, _CLONE_NEWNET = 0x00020000, 0x40000000
_PR_SET_NAME = 15
_RLIMITS = [getattr(resource, name) for name in dir(resource) if name.startswith("RLIMIT_")]

#: The name of a server's socket folder, in the temporary folder: FOLDER_PREFIX and a random part.
FOLDER_PREFIX = "autograder-fork-server-"

_current: ForkServer | None = None


def current() -> ForkServer | None:
    """The fork server of this grader process, if one serves (see :func:`serving`)."""
    server = _current
    return server if server is not None and server.alive() else None


def program(module: str, args: list[str], env: dict) -> list[str]:
    """The command line of the grader's program ``python -m MODULE ARG...`` in a sandbox with the
    environment `env`: through this process's fork server when one serves, with the client from
    the grader that the sandbox's Python would import (the first folder on env's PYTHONPATH that
    holds it); else a Python of its own."""
    server = current()
    folders = [Path(p) for p in (env.get("PYTHONPATH") or "").split(os.pathsep) if p]
    grader = next((folder for folder in folders if (folder / CLIENT_IN_PACKAGE).is_file()), None)
    if server is None or grader is None or module not in server.programs:
        return [sys.executable, "-m", module, *args]
    return server.command(module, args, grader)


@contextlib.contextmanager
def serving(wait: float | None = None):
    """A fork server for the gradings of this block (None where the isolation is not "root").
    Enter it before the grading threads start: fork copies only the thread that calls it. At the
    end it waits for the runs still going, at most `wait` seconds (default: to their end)."""
    global _current
    from autograder.sandbox import namespaces

    if namespaces.isolation() != "root" or _current is not None:
        yield _current
        return
    server = _current = ForkServer()
    try:
        yield server
    finally:
        _current = None
        server.close(wait)


class ForkServer:
    """The server process (forked at construction) and what the grader needs of it."""

    def __init__(self, programs: tuple[str, ...] = PROGRAMS, preload: tuple[str, ...] = PRELOAD):
        self.programs = tuple(programs)
        # 0700, root's; a socket's path has at most 107 bytes, which a test's TMPDIR may leave no room for.
        short = len(tempfile.gettempdir()) < 64
        parent = tempfile.gettempdir() if short else "/tmp"
        _remove_stale_folders(Path(parent))
        self.folder = Path(tempfile.mkdtemp(prefix=FOLDER_PREFIX, dir=parent))
        self.socket_path = str(self.folder / "socket")
        listener = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        listener.bind(self.socket_path)
        listener.listen(64)
        control_here, control_there = socket.socketpair()
        fresh = not forkable()
        self.pid = os.fork()
        if self.pid == 0:
            try:
                control_here.close()
                if fresh:
                    _exec_server(listener, control_there, self.programs, preload)
                _serve(listener, control_there, self.programs, preload)
            finally:
                os._exit(0)
        listener.close()
        control_there.close()
        self._control = control_here

    def command(self, module: str, args: list[str], grader: Path) -> list[str]:
        """The command line that runs ``python -m MODULE ARG...`` through this server in a sandbox
        whose grader is the package in folder `grader` (autograder.grading.staging: the repository's is hidden)."""
        if module not in self.programs:
            raise ValueError(f"the fork server runs {', '.join(self.programs)}, not {module}")
        client = Path(grader) / CLIENT_IN_PACKAGE
        return [sys.executable, "-I", "-S", str(client), self.socket_path, module, *args]

    def alive(self) -> bool:
        if self.pid is None:
            return False
        try:
            pid, _status = os.waitpid(self.pid, os.WNOHANG)
        except ChildProcessError:
            pid = self.pid
        if pid:
            self.pid = None
        return self.pid is not None

    def close(self, wait: float | None = None) -> None:
        """End the server once its runs have ended (after `wait` seconds it is killed, and its runs
        with it), and reap it."""
        import time

        self._control.close()
        deadline = None if wait is None else time.monotonic() + wait
        while self.pid is not None:
            with contextlib.suppress(ChildProcessError):
                if deadline is not None and time.monotonic() > deadline:
                    os.kill(self.pid, signal.SIGKILL)
                    deadline = None
                if os.waitpid(self.pid, 0 if deadline is None else os.WNOHANG)[0] == 0:
                    time.sleep(0.05)
                    continue
            self.pid = None
        with contextlib.suppress(OSError):
            os.unlink(self.socket_path)
        with contextlib.suppress(OSError):
            self.folder.rmdir()


def _remove_stale_folders(parent: Path) -> None:
    """Remove the socket folders of servers that are gone (a grader killed with SIGKILL leaves its
    folder): those whose socket no server listens on any more. A folder without a socket yet may be
    a server's that is starting: it stays. The temporary folder is everyone's: only a real folder
    of this uid counts (opened without following a link), and its socket is looked at and removed
    through that open folder."""
    for folder in parent.glob(FOLDER_PREFIX + "*"):
        try:
            fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW)
        except OSError:
            continue
        try:
            if os.fstat(fd).st_uid != os.getuid() or not stat.S_ISSOCK(os.stat("socket", dir_fd=fd,
                                                                            follow_symlinks=False).st_mode):
                continue
            with socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET) as probe:
                probe.connect(f"/proc/self/fd/{fd}/socket")
        except ConnectionRefusedError:
            with contextlib.suppress(OSError):
                os.unlink("socket", dir_fd=fd)
                os.rmdir(folder)  # a link put in its place since is no folder: rmdir fails
        except OSError:
            continue
        finally:
            os.close(fd)


def forkable() -> bool:
    """True when a child forked from this process may use ROS: rclpy's extension was never loaded
    here. Once rclpy.init has run (even after its shutdown), its signal handling's C++ thread, and
    Fast DDS's threads once a node existed, are objects whose threads a forked child lacks: a run
    forked from them that starts ROS ends with "std::system_error: Invalid argument" (SIGABRT). The
    grade command and the hub's service never load rclpy before the server; a test's process may."""
    return "rclpy._rclpy_pybind11" not in sys.modules


def _exec_server(listener: socket.socket, control: socket.socket, programs: tuple, preload: tuple) -> None:
    """Become a fresh Python that serves on `listener` (for a grader that is not :func:`forkable`):
    the same server, its imports its own."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}  # the grader's own modules
    for end in (listener, control):
        os.set_inheritable(end.fileno(), True)
    os.execve(sys.executable, [sys.executable, "-m", __name__, str(listener.fileno()), str(control.fileno()),
                               ",".join(programs), ",".join(preload)], env)


def run_name(module: str) -> str:
    """The name (comm, as ps shows it) of a run of `module`: "fork:" and the module's last part,
    "autograde" and "checks" for the grader's two programs."""
    short = {NOTEBOOK_RUN: "autograde", CHECKS_RUN: "checks"}
    return ("fork:" + short.get(module, module.rsplit(".", 1)[-1]))[:15]


def _libc():
    return ctypes.CDLL(None, use_errno=True)


def _serve(listener: socket.socket, control: socket.socket, programs: tuple, preload: tuple) -> None:
    """The server: the programs imported, then a handler forked per client until the grader closes
    `control`; it ends once they have. (What else the grader had open stays so: the runs are the
    grader's own programs, and they start a student's code with only its standard streams.)"""
    _libc().prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    _libc().prctl(_PR_SET_NAME, b"fork-server", 0, 0, 0)
    # A Ctrl-C to the grader's group is the grader's to handle; a SIGTERM ends the server (and
    # its runs, through their parent-death signals).
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    os.dup2(os.open(os.devnull, os.O_RDONLY), 0)  # its errors still reach the grader's stderr
    from autograder import nbgrader_cli

    nbgrader_cli.import_without_server_extensions()
    for name in preload:
        importlib.import_module(name)
    handlers = set()
    while True:
        ready, _, _ = select.select([listener, control], [], [], 1.0)
        if control in ready and not control.recv(1):
            break
        if listener in ready:
            client, _ = listener.accept()
            handler = os.fork()
            if handler == 0:
                try:
                    listener.close()
                    control.close()
                    _handle(client, programs)
                finally:
                    os._exit(1)
            client.close()
            handlers.add(handler)
        handlers -= _reaped(handlers)
    listener.close()
    for handler in handlers:
        with contextlib.suppress(ChildProcessError):
            os.waitpid(handler, 0)


def _reaped(pids: set) -> set:
    done = set()
    for pid in pids:
        with contextlib.suppress(ChildProcessError):
            if os.waitpid(pid, os.WNOHANG)[0]:
                done.add(pid)
    return done


def _handle(client: socket.socket, programs: tuple) -> None:
    """One client: its run forked into its namespaces, signals passed on, its end reported."""
    _libc().prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    _libc().prctl(_PR_SET_NAME, b"fork-handler", 0, 0, 0)
    message, fds, _flags, _address = socket.recv_fds(client, 1 << 20, 3)
    if not message:  # a look whether the server still listens (_remove_stale_folders)
        return
    pid, uid, _gid = struct.unpack("3i", client.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED,
                                                           struct.calcsize("3i")))
    request = json.loads(message)
    if uid != 0 or len(fds) != 3 or request.get("module") not in programs:
        client.send(b"exit 126")
        return
    spaces = {kind: os.open(f"/proc/{pid}/ns/{kind}", os.O_RDONLY) for kind in ("net", "mnt", "pid")}
    limits = {limit: resource.prlimit(pid, limit) for limit in _RLIMITS}
    for kind, flag in (("net", _CLONE_NEWNET), ("mnt", _CLONE_NEWNS), ("pid", CLONE_NEWPID)):
        if _libc().setns(spaces[kind], flag) != 0:
            error = ctypes.get_errno()
            os.write(fds[2], f"autograder: the fork server could not join the sandbox's {kind} namespace: "
                             f"{os.strerror(error)}\n".encode())
            client.send(b"exit 1")
            return
        os.close(spaces[kind])
    run = os.fork()  # in the client's process-id namespace
    if run == 0:
        client.close()
        _run(request, fds, limits)
    for fd in fds:
        os.close(fd)
    watch = os.pidfd_open(run)
    while True:
        ready, _, _ = select.select([client, watch], [], [])
        if watch in ready:
            break
        message = client.recv(64)
        if not message:  # the client is gone: so is the run
            os.kill(run, signal.SIGKILL)
            continue
        kind, number = message.decode().split()
        if kind == "signal":
            with contextlib.suppress(ProcessLookupError):
                os.kill(run, int(number))
    _, status = os.waitpid(run, 0)
    ended = f"exit {os.WEXITSTATUS(status)}" if os.WIFEXITED(status) else f"signal {os.WTERMSIG(status)}"
    with contextlib.suppress(OSError):
        client.send(ended.encode())


def _run(request: dict, fds: list[int], limits: dict) -> None:
    """The run (never returns): the client's limits, streams, folder, umask and environment, the
    grader's modules again from the client's PYTHONPATH, then MODULE as __main__."""
    code = 1
    try:
        _libc().prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        _libc().prctl(_PR_SET_NAME, run_name(request["module"]).encode(), 0, 0, 0)
        for target, fd in enumerate(fds):
            os.dup2(fd, target)
            os.close(fd)
        # Python's own objects for them, as a new Python makes them (the grader's may be anything:
        # a test's capture, a progress bar's stream).
        sys.stdin = sys.__stdin__ = open(0, closefd=False)
        sys.stdout = sys.__stdout__ = open(1, "w", closefd=False)
        sys.stderr = sys.__stderr__ = open(2, "w", buffering=1, errors="backslashreplace", closefd=False)
        mapped = int(Path("/proc/self/statm").read_text().split()[0]) * os.sysconf("SC_PAGE_SIZE")
        memory = limits.get(resource.RLIMIT_AS, (resource.RLIM_INFINITY,))[0]
        if memory != resource.RLIM_INFINITY and mapped + (256 << 20) > memory:
            print(f"autograder: the fork server maps {mapped >> 20} MB already, too close to the run's memory limit "
                  f"of {memory >> 20} MB: raise the limit, or start the program without the server", file=sys.stderr)
            os._exit(1)
        for limit, pair in limits.items():
            resource.setrlimit(limit, pair)
        os.chdir(request["cwd"])
        os.umask(request["umask"])
        os.environ.clear()
        os.environ.update(request["env"])
        # As ``python -m`` has it: the working folder, then PYTHONPATH, then the rest.
        first = [request["cwd"], *(p for p in request["env"].get("PYTHONPATH", "").split(os.pathsep) if p)]
        sys.path[:] = first + [p for p in sys.path if p and p not in first]
        for name in [name for name in sys.modules if name == "autograder" or name.startswith("autograder.")]:
            del sys.modules[name]
        importlib.invalidate_caches()
        sys.argv = [request["module"], *request["args"]]
        for number in FORWARDED:  # as a new Python has them, whatever the grader set
            signal.signal(number, signal.default_int_handler if number == signal.SIGINT else signal.SIG_DFL)
        runpy.run_module(request["module"], run_name="__main__", alter_sys=True)
        code = 0
    except SystemExit as end:
        code = end.code if isinstance(end.code, int) else (0 if end.code is None else 1)
    except BaseException:
        traceback.print_exc()
    finally:
        with contextlib.suppress(Exception):
            sys.stdout.flush()
            sys.stderr.flush()
        os._exit(code)


if __name__ == "__main__":  # a server started by _exec_server
    _listener_fd, _control_fd, _programs, _preload = sys.argv[1:5]
    _serve(socket.socket(fileno=int(_listener_fd)), socket.socket(fileno=int(_control_fd)),
           tuple(_programs.split(",")), tuple(p for p in _preload.split(",") if p))
