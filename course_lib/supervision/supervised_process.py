"""A command run as a child process that never outlives its caller: its own process group, a
supervisor as its direct parent (course_lib.supervision.supervisor), a bounded log, resource limits.

This is the part of course_lib.ros.processes.NodeProcess that knows nothing of ROS: starting,
waiting, reading the log, stopping (also every running one at exit, and none after a fork).
NodeProcess adds the ROS side: the child's ROS domain, waiting for its node in the graph, and
the warnings when another program runs a node of the same name.
"""

from __future__ import annotations

import atexit
import errno
import json
import os
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path

from course_lib import waiting
from course_lib.supervision.bounded_log import LOG_HEAD_BYTES, LOG_TAIL_BYTES, read_log
from course_lib.supervision.process_limits import Limits
from course_lib.supervision.process_tree import TreeMember, signal_group

#: Seconds start() waits for the supervisor to report that the command runs.
START_TIMEOUT = 30.0

#: How the supervisor starts: its file run as a script by a fresh python -I -S.
_SUPERVISOR_COMMAND = [sys.executable, "-I", "-S", os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                             "supervisor.py")]

#: Every supervised process this process started and has not yet stopped (for stop_all and atexit).
_RUNNING: set[SupervisedProcess] = set()
_RUNNING_LOCK = threading.Lock()


class SupervisedProcess:
    """A command running as a child process in its own process group, under a supervisor.

    Args:
        command: the program and its arguments, e.g. ``[sys.executable, "-m", "pkg.node"]``.
        name: a label for messages (default: the program's name).
        env: the child's whole environment (None: the caller's).
        cwd: working directory of the child.
        limits: resource bounds (see Limits); None for none.
        private_dirs: folders that belong to the child (a HOME made for it): removed when it has
            ended, also when its caller dies first.
        on_output: called as ``on_output(stream, data)`` with each piece of the child's output
            as it arrives, stream being "stdout" or "stderr" (from a thread of its own; the
            log keeps everything as well). By the time returncode is known, on_output has had
            all of it (so on_output must not wait for this process). With it the child's stdout
            and stderr are separate pipes, so their order in the log is only as exact as their
            arrival.

    Attributes:
        pid: the child's process id (it also leads the child's process group) once started.
        exit_reason: None while running, then "exited" (on its own), "stopped" (stop()),
            "wall_seconds" (Limits), "max_processes" (Limits: its user reached the limit and this
            tree held at least a quarter of it), "parent_exited" or "supervisor_died".
        usage: after the end, {"max_rss_kb", "cpu_seconds"} of the child (the peak memory
            includes the ~20 MB of the supervisor it was forked from) and the supervisor's own
            "supervisor_max_rss_kb".
    """

    def __init__(self, command: list[str], *, name: str | None = None, env: dict | None = None, cwd=None,
                 limits: Limits | None = None, on_output: Callable[[str, bytes], None] | None = None,
                 private_dirs=()):
        if isinstance(command, (str, bytes)) or not command:
            raise TypeError(f"command must be a non-empty list of strings like ['python', '-m', 'pkg.node'], "
                            f"not {command!r}")
        self.command = [os.fspath(part) for part in command]
        self.name = name or Path(self.command[0]).name
        self.cwd = None if cwd is None else os.fspath(cwd)
        self.limits = limits or Limits()
        self._on_output = on_output
        self._relay: threading.Thread | None = None
        self.env = dict(os.environ if env is None else env)
        self.pid: int | None = None
        self.exit_reason: str | None = None
        self.usage: dict | None = None
        self._supervisor: subprocess.Popen | None = None
        self._control: int | None = None
        self._status: int | None = None
        self._status_buffer = b""
        self._log_dir: Path | None = None
        self._private_dirs = [Path(directory) for directory in private_dirs]
        self._final_log: bytes | None = None
        self._returncode: int | None = None
        self._lock = threading.RLock()

    def __repr__(self) -> str:
        state = "not started" if self._supervisor is None else (
            "running" if self.running() else self.describe_exit())
        return f"<{type(self).__name__} {self.name!r} pid={self.pid} {state}>"

    # -- starting ---------------------------------------------------------------------------

    def start(self) -> SupervisedProcess:
        """Start the command under a supervisor and return self.

        Raises:
            RuntimeError: this NodeProcess was started before.
            FileNotFoundError, PermissionError, OSError: the command could not be executed.
        """
        with self._lock:
            if self._supervisor is not None:
                raise RuntimeError(f"{self.name} was already started; create a new {type(self).__name__} to run it "
                                   "again")
            self._before_start()
            env = dict(self.env)
            self._log_dir = Path(tempfile.mkdtemp(prefix="course_lib-node-"))
            cleanup = [str(self._log_dir), *map(str, self._private_dirs)]
            control_read, self._control = os.pipe()
            self._status, status_write = os.pipe()
            echo_read, echo_write = os.pipe() if self._on_output is not None else (None, None)
            config = {"command": self.command, "cwd": self.cwd, "log_dir": str(self._log_dir),
                      "head_bytes": LOG_HEAD_BYTES, "tail_bytes": LOG_TAIL_BYTES,
                      "rlimits": self.limits.rlimit_pairs(), "wall_seconds": self.limits.wall_seconds,
                      "grace_seconds": self.limits.grace_seconds, "cleanup": cleanup, "echo_fd": echo_write,
                      "max_tasks": self.limits.stop_at_tasks}
            try:
                with open(self._log_dir / "supervisor.err", "wb") as errors:
                    self._supervisor = subprocess.Popen(
                        [*_SUPERVISOR_COMMAND, str(status_write), json.dumps(config)],
                        stdin=control_read, stdout=subprocess.DEVNULL, stderr=errors,
                        pass_fds=(status_write,) if echo_write is None else (status_write, echo_write),
                        env=env, start_new_session=True)
            except BaseException:
                self._close_fds()
                self._remove_dirs()
                if echo_read is not None:
                    os.close(echo_read)
                raise
            finally:
                os.close(control_read)
                os.close(status_write)
                if echo_write is not None:
                    os.close(echo_write)
            if echo_read is not None:
                self._relay = threading.Thread(target=_relay_echo, args=(echo_read, self._on_output),
                                               name=f"course_lib-output-{self.name}", daemon=True)
                self._relay.start()
            with _RUNNING_LOCK:
                _RUNNING.add(self)
            event = self._next_event(START_TIMEOUT)
            if event and event.get("event") == "started":
                self.pid = event["pid"]
                self._after_start()
                return self
            if event and event.get("event") == "error":
                self._poll(wait=True)
                raise _start_error(event, self.command, self.cwd)
            errors = self._supervisor_errors() or "(none)"
            if self._supervisor.poll() is None:
                self._kill_supervisor()
            self._poll(wait=True)
            raise RuntimeError(f"The supervisor of {self.name} did not start it within {START_TIMEOUT} s; "
                               f"its errors: {errors}")

    # -- state --------------------------------------------------------------------------------

    @property
    def returncode(self) -> int | None:
        """The child's exit code, -N when signal N ended it, None while it runs or before start."""
        self._poll()
        return self._returncode

    def running(self) -> bool:
        """True between start() and the moment the child (and its leftovers) are gone."""
        return self._supervisor is not None and self.returncode is None

    def cpu_seconds(self) -> float:
        """Processor time the child and its descendants have used so far (user + system; see
        course_lib.supervision.process_tree.cpu_seconds): what a computation costs whatever the machine's
        load. Counts descendants that left the child's group too (the supervisor adopts them);
        0.0 before start and after the end."""
        if self._supervisor is None or not self.running():
            return 0.0
        from course_lib.supervision.process_tree import cpu_seconds

        return cpu_seconds(self._supervisor.pid, include_self=False)

    def member(self, executable: str) -> TreeMember | None:
        """The process of this child's tree (a launch's node, say) whose program is named
        `executable`, as a TreeMember; None while there is none."""
        if self._supervisor is None or not self.running():
            return None
        from course_lib.supervision.process_tree import command_line, descendants_of

        for pid in descendants_of(self._supervisor.pid):
            if any(Path(part).name == executable for part in command_line(pid)[:2]):
                return TreeMember(pid)
        return None

    @property
    def log(self) -> str:
        """Everything the child wrote to stdout and stderr so far, with the middle of a very
        long output replaced by a line that says how many bytes were left out."""
        # No lock: stop() holds it while it waits, and reading the log must not wait for that.
        log_dir, data = self._log_dir, self._final_log
        if data is None and log_dir is not None:
            data = read_log(log_dir, LOG_TAIL_BYTES // 2)
            if self._final_log is not None:  # the child ended while we read
                data = self._final_log
        return (data or b"").decode("utf-8", errors="replace")

    def log_tail(self, lines: int = 20) -> str:
        """The last `lines` lines of the log (for error messages)."""
        text = self.log.rstrip("\n")
        return "\n".join(text.splitlines()[-lines:]) if text else "(no output)"

    def describe_exit(self) -> str:
        """How the child ended, in words: 'exit code 3', 'killed by SIGKILL after ...'."""
        code = self.returncode
        if code is None:
            return "still running" if self._supervisor is not None else "not started"
        if code >= 0:
            text = f"exit code {code}"
        else:
            try:
                text = f"killed by {signal.Signals(-code).name}"
            except ValueError:
                text = f"killed by signal {-code}"
        hints = {"wall_seconds": f" after the wall-time limit of {self.limits.wall_seconds} s",
                 "stopped": " after stop()", "parent_exited": " because its caller exited",
                 "supervisor_died": " because its supervisor died",
                 "max_processes": f" when its user had the most processes and threads it may have "
                                  f"({self.limits.stop_at_tasks}: a fork() or a thread started in a loop?)"}
        text += hints.get(self.exit_reason, "")
        if code == -signal.SIGXCPU:
            text += f" (CPU time limit of {self.limits.cpu_seconds} s)"
        elif code == -signal.SIGXFSZ:
            text += f" (file size limit of {self.limits.file_size_mb} MB)"
        return text

    # -- waiting ------------------------------------------------------------------------------

    def wait(self, timeout: float | None = None) -> int:
        """Wait until the child has exited and return its returncode.

        Raises:
            TimeoutError: it still runs after `timeout` seconds (it keeps running).
        """
        self._require_started()
        try:
            self._supervisor.wait(timeout)
        except subprocess.TimeoutExpired:
            raise TimeoutError(f"{self.name} still runs after {timeout} s; call stop() to end it. "
                               f"Last output:\n{self.log_tail()}") from None
        self._poll(wait=True)
        return self._returncode

    def wait_for_output(self, text: str, timeout: float = 10.0) -> str:
        """Wait until the child's output contains `text` (e.g. a log line) and return the output.

        Raises:
            RuntimeError: the child exited first (with its exit and its last output).
            TimeoutError: `text` did not appear in time (with the last output).
        """
        self._require_started()
        waiting.spin_until(lambda: text in self.log or not self.running(), timeout)
        log = self.log
        if text in log:
            return log
        if not self.running():
            raise RuntimeError(f"{self.name} ended ({self.describe_exit()}) before printing {text!r}. "
                               f"Last output:\n{self.log_tail()}")
        raise TimeoutError(f"{self.name} did not print {text!r} within {timeout} s. "
                           f"Last output:\n{self.log_tail()}")

    # -- stopping -----------------------------------------------------------------------------

    def stop(self, timeout: float = 5.0) -> int | None:
        """Stop the child: SIGINT to its process group, SIGKILL after `timeout` seconds.

        Everything the child left behind (its process group, descendants that left it) is
        killed too. Calling stop() again, or on a child that has ended, does nothing.

        Returns:
            The child's returncode (None if it was never started).
        """
        with self._lock:
            if self._supervisor is None or self._returncode is not None:
                return self._returncode
            self._request_stop(timeout)
            try:
                self._supervisor.wait(timeout + 5.0)
            except subprocess.TimeoutExpired:
                self._kill_supervisor()
            self._poll(wait=True)
            return self._returncode

    def send_signal(self, number: int) -> None:
        """Send one signal to the child's process group (and what left it) now, as one step of
        a stop the caller paces itself (``ros2 launch``: SIGINT, SIGTERM, SIGKILL); nothing once
        the child has ended. Its exit_reason becomes "stopped"."""
        self._tell_supervisor(f"signal {int(number)}")

    def _request_stop(self, timeout: float) -> None:
        self._tell_supervisor(f"stop {float(timeout)}")

    def _tell_supervisor(self, command: str) -> None:
        if self._control is not None and self._returncode is None:
            try:
                os.write(self._control, f"{command}\n".encode())
            except OSError:  # the supervisor has gone; _poll() will find out how
                pass

    def __enter__(self) -> SupervisedProcess:
        return self if self._supervisor is not None else self.start()

    def __exit__(self, *exc) -> None:
        self.stop()

    # -- internals ----------------------------------------------------------------------------

    def _require_started(self) -> None:
        if self._supervisor is None:
            raise RuntimeError(f"{self.name} has not been started: call start() first")

    def _next_event(self, timeout: float) -> dict | None:
        """Read one status line from the supervisor, or None on timeout or end of stream."""
        deadline = time.monotonic() + timeout
        while b"\n" not in self._status_buffer:
            remaining = max(0.0, deadline - time.monotonic())
            if self._status is None or not select.select([self._status], [], [], remaining)[0]:
                return None
            chunk = os.read(self._status, 4096)
            if not chunk:
                return None
            self._status_buffer += chunk
        line, self._status_buffer = self._status_buffer.split(b"\n", 1)
        return json.loads(line)

    def _poll(self, wait: bool = False) -> None:
        """Collect the supervisor's final report once it has exited."""
        with self._lock:
            if self._supervisor is None or self._returncode is not None:
                return
            if wait:
                self._supervisor.wait()
            elif self._supervisor.poll() is None:
                return
            final = None
            while (event := self._next_event(0)) is not None:
                if event.get("event") == "exited":
                    final = event
            if self._relay is not None and self._relay is not threading.current_thread():
                self._relay.join(timeout=5.0)  # the supervisor has exited: its last frames are in the pipe
            if final is not None:
                self._returncode = final["returncode"]
                self.exit_reason = final["reason"]
                self.usage = {key: final[key] for key in ("max_rss_kb", "cpu_seconds", "supervisor_max_rss_kb")}
            else:
                # The supervisor itself died (killed from outside). Its child got SIGKILL through
                # PR_SET_PDEATHSIG; the child's group may hold more.
                if self.pid is not None:
                    signal_group(self.pid, signal.SIGKILL)
                self._returncode = -signal.SIGKILL
                self.exit_reason = "supervisor_died"
            if self._log_dir is not None:
                self._final_log = read_log(self._log_dir, LOG_TAIL_BYTES // 2)
            self._close_fds()
            self._remove_dirs()
            with _RUNNING_LOCK:
                _RUNNING.discard(self)
            self._after_end()

    # -- what a subclass adds (processes.NodeProcess: the ROS graph) ---------------------------------

    def _before_start(self) -> None:
        """Called by start() before the child starts."""

    def _after_start(self) -> None:
        """Called by start() once the child runs (self.pid is set)."""

    def _after_end(self) -> None:
        """Called once when the child's end has been collected."""

    def _disown(self) -> None:
        self._lock = threading.RLock()
        for fd in (self._control, self._status):
            if fd is not None:
                try:
                    os.close(fd)
                except OSError:
                    pass
        self._control = self._status = None
        self._supervisor = None
        self._log_dir = None
        self._private_dirs = []

    def _kill_supervisor(self) -> None:
        self._supervisor.kill()
        self._supervisor.wait()
        if self.pid is not None:
            signal_group(self.pid, signal.SIGKILL)

    def _supervisor_errors(self) -> str:
        try:
            return (self._log_dir / "supervisor.err").read_text(errors="replace").strip()
        except (OSError, TypeError):
            return ""

    def _close_fds(self) -> None:
        for attribute in ("_control", "_status"):
            fd = getattr(self, attribute)
            if fd is not None:
                os.close(fd)
                setattr(self, attribute, None)

    def _remove_dirs(self) -> None:
        for directory in (self._log_dir, *self._private_dirs):
            if directory is not None:
                shutil.rmtree(directory, ignore_errors=True)
        self._private_dirs = []


def _relay_echo(fd: int, on_output: Callable[[str, bytes], None]) -> None:
    """Read the supervisor's echo frames until it exits, and hand each piece to on_output."""
    names = {b"o": "stdout", b"e": "stderr"}
    buffer = b""
    try:
        while chunk := os.read(fd, 65536):
            buffer += chunk
            while len(buffer) >= 3 and len(buffer) >= 3 + int.from_bytes(buffer[1:3], "big"):
                size = int.from_bytes(buffer[1:3], "big")
                stream, data, buffer = buffer[:1], buffer[3:3 + size], buffer[3 + size:]
                try:
                    on_output(names[stream], data)
                except Exception as error:  # a faulty callback must not stop the relay
                    print(f"course_lib.ros.processes: on_output raised {error!r}", file=sys.stderr)
    finally:
        os.close(fd)



def stop_all(timeout: float = 5.0) -> None:
    """Stop every supervised process (NodeProcess) this process started: all get SIGINT at once, then each is
    awaited."""
    stop_together(running_processes(), timeout)


def stop_together(processes, timeout: float = 5.0) -> None:
    """Stop these processes (NodeProcess): all get SIGINT at once (so their shutdowns overlap), then each
    is awaited and killed if it still runs after `timeout` seconds."""
    processes = list(processes)
    for process in processes:
        process._request_stop(timeout)
    for process in processes:
        process.stop(timeout)


def running_processes() -> list[SupervisedProcess]:
    with _RUNNING_LOCK:
        return list(_RUNNING)


def _disown_after_fork() -> None:
    """In a child made by os.fork (multiprocessing's "fork" start method), forget the parent's
    nodes: the child must neither stop them at its exit nor keep their control pipes open,
    which would hide the parent's death from the supervisors."""
    global _RUNNING_LOCK
    _RUNNING_LOCK = threading.Lock()  # another thread may have held it at the fork
    for process in list(_RUNNING):
        process._disown()
    _RUNNING.clear()


atexit.register(stop_all)
os.register_at_fork(after_in_child=_disown_after_fork)


def _start_error(event: dict, command: list[str], cwd: str | None) -> OSError:
    number = event.get("errno")
    if number == errno.ENOENT:
        where = f" (working directory {cwd})" if cwd else ""
        return FileNotFoundError(number, f"Cannot run {command[0]!r}{where}: no such file or program on PATH; "
                                 f"check the spelling or give a full path", command[0])
    if number in (errno.EACCES, errno.EPERM):
        fix = "make it executable (chmod +x) or run it through its interpreter"
        return PermissionError(number, f"Cannot run {command[0]!r}: permission denied; {fix}", command[0])
    return OSError(number, f"Cannot run {command!r}: {event.get('message')}")
