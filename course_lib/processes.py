"""Run ROS nodes (or any command) as child processes that never outlive the notebook or script.

There is no ``ros2 launch`` in the pip-installed ROS 2, so lessons start their nodes with this
module, and the autograder runs student code through it with resource limits::

    from course_lib import processes

    with processes.python_node("demo_nodes.talker:main", name="talker") as talker:
        talker.wait_for_node("talker")
        ...                      # talk to it
    print(talker.log)            # everything it printed, rclpy log lines included

How children are kept from outliving their caller: each NodeProcess starts a small supervisor
(this same file, run as a script by a fresh ``python -I -S``, so neither site-packages, the
ROS bootstrapper nor course_lib's other imports cost start-up time). The supervisor is the
node's direct parent, and

- it puts the node in a process group of its own, so a stop reaches the node's own children;
- it is a child subreaper, so descendants that leave the group (``setsid``, daemons) are
  re-parented to it and killed too;
- it reads a pipe whose only writer is the caller: when the caller dies in any way (atexit,
  SIGTERM, even SIGKILL) the pipe closes, and the supervisor stops the group;
- the node gets PR_SET_PDEATHSIG=SIGKILL, so it dies with the supervisor;
- resource limits (setrlimit) and the switch to an unprivileged user happen in the
  supervisor's fork, which has no threads, never in the caller (a kernel or a process that
  runs DDS threads, where ``preexec_fn`` is unsafe).

The supervisor also relays the node's output to a log that keeps its head and its tail, so a
node that prints a gigabyte neither blocks nor fills memory or disk.
"""

from __future__ import annotations

# The supervisor part of this file (first) needs only these; see the imports after it.
import json
import os
import select
import shutil
import signal
import subprocess
import sys
import time

#: Bytes of a node's output kept from its start and from its end; the middle is dropped.
LOG_HEAD_BYTES = 64 * 1024
LOG_TAIL_BYTES = 256 * 1024

#: Seconds a node gets to shut down after SIGINT when its caller has gone away.
PARENT_GONE_GRACE = 1.0

#: Largest piece of output in one echo frame: a frame (3 header bytes + piece) stays within
#: PIPE_BUF, so a non-blocking write of it is all or nothing and frames never interleave.
_ECHO_PIECE = 4000

_PR_SET_PDEATHSIG = 1
_PR_SET_CHILD_SUBREAPER = 36


# ---------------------------------------------------------------------------------------------
# The supervisor. It runs as `python -I -S processes.py`, stops at the __main__ check below,
# and so never pays for the imports of the public part (dataclasses alone costs more than
# the whole supervisor needs).


class _BoundedLog:
    """Write a stream to `head` (its first head_bytes) and to numbered `tail.N` chunk files of
    tail_bytes/2 each, deleting all but the newest two chunks: bounded disk, no memory growth."""

    def __init__(self, directory: str, head_bytes: int, tail_bytes: int):
        self.directory = directory
        self.head = open(os.path.join(directory, "head"), "wb", buffering=0)
        self.head_left = head_bytes
        self.chunk = max(1, tail_bytes // 2)
        self.index = -1
        self.tail = None
        self.tail_left = 0

    def write(self, data: bytes) -> None:
        if self.head_left:
            piece = data[:self.head_left]
            self.head.write(piece)
            self.head_left -= len(piece)
            data = data[len(piece):]
        while data:
            if self.tail_left == 0:
                self._next_chunk()
            piece = data[:self.tail_left]
            self.tail.write(piece)
            self.tail_left -= len(piece)
            data = data[len(piece):]

    def _next_chunk(self) -> None:
        if self.tail is not None:
            self.tail.close()
        self.index += 1
        self.tail = open(os.path.join(self.directory, f"tail.{self.index:012d}"), "wb", buffering=0)
        self.tail_left = self.chunk
        if self.index >= 2:
            try:
                os.remove(os.path.join(self.directory, f"tail.{self.index - 2:012d}"))
            except FileNotFoundError:
                pass

    def close(self) -> None:
        self.head.close()
        if self.tail is not None:
            self.tail.close()


def _children(pid: int) -> list[int]:
    """Direct children of process `pid` (this supervisor has a single thread)."""
    try:
        with open(f"/proc/{pid}/task/{pid}/children") as handle:
            return [int(p) for p in handle.read().split()]
    except FileNotFoundError:  # kernel without CONFIG_PROC_CHILDREN: scan /proc
        found = []
        for entry in os.listdir("/proc"):
            if entry.isdigit():
                try:
                    with open(f"/proc/{entry}/stat") as handle:
                        stat = handle.read()
                except OSError:
                    continue
                if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                    found.append(int(entry))
        return found


def _peak_rss_kb() -> int:
    """This process's peak resident memory since its exec (getrusage's ru_maxrss would include
    the memory of the process it was forked from)."""
    with open("/proc/self/status") as handle:
        for line in handle:
            if line.startswith("VmHWM:"):
                return int(line.split()[1])
    return 0


def _supervisor_main(argv: list[str] | None = None) -> int:
    """Entry of the supervisor process: argv is [status_fd, config_json]; stdin is the control pipe."""
    import ctypes
    import resource

    status_fd, config = sys.argv[1:3] if argv is None else argv
    config = json.loads(config)
    status = os.fdopen(int(status_fd), "wb", buffering=0)
    me, parent = os.getpid(), os.getppid()
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(_PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0)

    def report(**event) -> None:
        try:
            status.write(json.dumps(event).encode() + b"\n")
        except OSError:  # the caller has gone
            pass

    wake_read, wake_write = os.pipe()
    os.set_blocking(wake_read, False)
    os.set_blocking(wake_write, False)
    signal.set_wakeup_fd(wake_write, warn_on_full_buffer=False)
    signalled = []
    signal.signal(signal.SIGCHLD, lambda *_: None)
    for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
        signal.signal(sig, lambda number, _frame: signalled.append(number))

    rlimits = [(getattr(resource, name), tuple(pair)) for name, pair in config["rlimits"].items()]

    def prepare_child() -> None:
        # Runs in the forked child, before exec. Safe here: the supervisor has no threads.
        os.setpgid(0, 0)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        if os.getppid() != me:  # the supervisor died before prctl took effect
            os.kill(os.getpid(), signal.SIGKILL)
        for resource_id, pair in rlimits:
            resource.setrlimit(resource_id, pair)

    # Without an echo the child's stdout and stderr share one pipe, so the log keeps their exact
    # order; with one they get a pipe each, so the caller can tell them apart.
    echo_fd = config.get("echo_fd")
    output_read, output_write = os.pipe()
    streams = {output_read: b"o"}
    error_write = output_write
    if echo_fd is not None:
        os.set_blocking(echo_fd, False)
        error_read, error_write = os.pipe()
        streams[error_read] = b"e"
    log = _BoundedLog(config["log_dir"], config["head_bytes"], config["tail_bytes"])
    user = config["user"]
    try:
        child = subprocess.Popen(config["command"], stdin=subprocess.DEVNULL, stdout=output_write,
                                 stderr=error_write, cwd=config["cwd"], preexec_fn=prepare_child,
                                 user=user, group=None if user is None else _group_of(user),
                                 extra_groups=None if user is None else [])
    except OSError as error:
        report(event="error", errno=error.errno, message=str(error))
        report(event="exited", returncode=127, reason="not_started", max_rss_kb=0, cpu_seconds=0.0,
               supervisor_max_rss_kb=_peak_rss_kb())
        log.close()
        return 0
    finally:
        os.close(output_write)
        if error_write != output_write:
            os.close(error_write)
    report(event="started", pid=child.pid)

    poller = select.poll()
    poller.register(0, select.POLLIN)
    for fd in streams:
        os.set_blocking(fd, False)
        poller.register(fd, select.POLLIN)
    poller.register(wake_read, select.POLLIN)
    wall = config["wall_seconds"]
    wall_deadline = None if wall is None else time.monotonic() + wall
    reason = None
    kill_at = None
    parent_gone = False

    def begin_stop(why: str, grace: float) -> None:
        nonlocal reason, kill_at
        if reason is None:
            reason = why
            _signal_tree(child.pid, signal.SIGINT)
        deadline = time.monotonic() + max(0.0, grace)
        kill_at = deadline if kill_at is None else min(kill_at, deadline)

    echo_dropped = {b"o": 0, b"e": 0}

    def echo(stream: bytes, data: bytes) -> None:
        """Pass output on to the caller in frames (stream, length, bytes); what does not fit
        in the pipe is dropped (the log keeps it) and counted in a note, so the child never
        waits for a slow reader."""
        nonlocal echo_fd
        dropped_before, echo_dropped[stream] = echo_dropped[stream], 0
        note = f"[... {dropped_before} bytes of output not shown ...]\n".encode() if dropped_before else b""
        payload = note + data
        for start in range(0, len(payload), _ECHO_PIECE):
            piece = payload[start:start + _ECHO_PIECE]
            try:
                os.write(echo_fd, stream + len(piece).to_bytes(2, "big") + piece)
            except BlockingIOError:
                unsent = len(payload) - start
                echo_dropped[stream] = min(unsent, len(data)) + (dropped_before if unsent > len(data) else 0)
                return
            except OSError:  # the caller closed its end: stop echoing
                os.close(echo_fd)
                echo_fd = None
                return

    def relay_output(fd: int) -> bool:
        """Copy what the child wrote to the log (and the echo); False at end of stream."""
        while True:
            try:
                data = os.read(fd, 65536)
            except BlockingIOError:
                return True
            if not data:
                return False
            log.write(data)
            if echo_fd is not None:
                echo(streams[fd], data)

    while os.waitid(os.P_PID, child.pid, os.WEXITED | os.WNOHANG | os.WNOWAIT) is None:
        timeouts = [0.5] + [t - time.monotonic() for t in (kill_at, wall_deadline) if t is not None]
        for fd, _events in poller.poll(max(0, int(min(timeouts) * 1000) + 1)):
            if fd in streams and not relay_output(fd):
                poller.unregister(fd)
            elif fd == wake_read:
                while True:
                    try:
                        if not os.read(wake_read, 512):
                            break
                    except BlockingIOError:
                        break
            elif fd == 0:
                command = os.read(0, 4096)
                if not command:  # the caller closed its end: it has exited, one way or another
                    parent_gone = True
                    poller.unregister(0)
                    begin_stop("parent_exited", PARENT_GONE_GRACE)
                for line in command.decode(errors="replace").splitlines():
                    if line.startswith("stop"):
                        begin_stop("stopped", float(line.split()[1]))
        if signalled:
            signalled.clear()
            begin_stop("stopped", PARENT_GONE_GRACE)
        if not parent_gone and os.getppid() != parent:
            parent_gone = True
            begin_stop("parent_exited", PARENT_GONE_GRACE)
        if wall_deadline is not None and time.monotonic() >= wall_deadline:
            wall_deadline = None
            begin_stop("wall_seconds", config["grace_seconds"])
        if kill_at is not None and time.monotonic() >= kill_at:
            _signal_tree(child.pid, signal.SIGKILL)
            kill_at = None  # once is enough; SIGCHLD wakes us when it has died

    # The child has exited but is not reaped yet, so its process group id cannot be reused:
    # kill what it left in its group, then whatever was re-parented to us.
    _killpg(child.pid, signal.SIGKILL)
    _, wait_status, usage = os.wait4(child.pid, 0)
    child.returncode = os.waitstatus_to_exitcode(wait_status)  # keeps Popen from waiting again
    leftovers_deadline = time.monotonic() + 5.0
    while (orphans := _children(me)) and time.monotonic() < leftovers_deadline:
        for pid in orphans:
            try:
                os.kill(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
            except (ProcessLookupError, ChildProcessError):
                pass
    drain_deadline = time.monotonic() + 2.0
    open_streams = list(streams)
    while open_streams and time.monotonic() < drain_deadline:
        ready = select.select(open_streams, [], [], max(0.0, drain_deadline - time.monotonic()))[0]
        if not ready:
            break
        for fd in ready:
            if not relay_output(fd):
                open_streams.remove(fd)
    if echo_fd is not None and any(echo_dropped.values()):
        # Say what was not shown, if the reader catches up soon enough.
        if select.select([], [echo_fd], [], PARENT_GONE_GRACE * 2)[1]:
            for stream in echo_dropped:
                if echo_dropped[stream] and echo_fd is not None:
                    echo(stream, b"")
    log.close()
    report(event="exited", returncode=child.returncode, reason=reason or "exited",
           max_rss_kb=usage.ru_maxrss, cpu_seconds=round(usage.ru_utime + usage.ru_stime, 3),
           supervisor_max_rss_kb=_peak_rss_kb())
    if parent_gone:  # nobody will read the log: leave nothing behind
        for path in config["cleanup"]:
            shutil.rmtree(path, ignore_errors=True)
    return 0


def _group_of(user: str | int) -> int:
    """The primary group of a user name; a bare uid (no passwd entry needed) is its own group."""
    import pwd

    return user if isinstance(user, int) else pwd.getpwnam(user).pw_gid


def _killpg(pgid: int, sig: int) -> None:
    try:
        os.killpg(pgid, sig)
    except (ProcessLookupError, PermissionError):
        pass


def _signal_tree(pid: int, sig: int) -> None:
    """Signal the process group `pid` leads, and `pid` itself only if it left that group.

    Signalling a group member twice would deliver SIGINT twice: the second one can land in the
    node's own clean-up (its finally block) and turn a clean exit into a traceback.
    """
    _killpg(pid, sig)
    try:
        if os.getpgid(pid) != pid:
            os.kill(pid, sig)
    except ProcessLookupError:
        pass


if __name__ == "__main__":
    sys.exit(_supervisor_main())

# ---------------------------------------------------------------------------------------------
# The public part, used in the caller.

import atexit  # noqa: E402 (after the supervisor on purpose, see above)
import dataclasses  # noqa: E402
import errno  # noqa: E402
import itertools  # noqa: E402
import tempfile  # noqa: E402
import threading  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Callable  # noqa: E402

#: Seconds start() waits for the supervisor to report that the command runs.
START_TIMEOUT = 30.0

#: How the supervisor starts: this file run as a script by a fresh python -I -S.
_SUPERVISOR_COMMAND = [sys.executable, "-I", "-S", os.path.abspath(__file__)]

#: Every NodeProcess this process started and has not yet stopped (for stop_all and atexit).
_RUNNING: set["NodeProcess"] = set()
_RUNNING_LOCK = threading.Lock()
_WATCHER_IDS = itertools.count()


@dataclasses.dataclass(frozen=True)
class Limits:
    """Bounds for a child that runs untrusted code (the autograder); None means no bound.

    Attributes:
        wall_seconds: real time after which the child is stopped (SIGINT, then SIGKILL after
            grace_seconds); its exit_reason becomes "wall_seconds".
        memory_mb: address space (RLIMIT_AS). Allocations beyond it fail (MemoryError in Python).
            rclpy with Fast DDS maps a few hundred MB of address space, so stay above ~1024 for
            ROS nodes.
        cpu_seconds: CPU time (RLIMIT_CPU); the child gets SIGXCPU when it is used up.
        max_processes: processes *and threads* of the child's user (RLIMIT_NPROC). Fast DDS
            starts about a dozen threads per node. The kernel does not enforce it for root, so
            combine it with ``user`` when the caller runs as root.
        file_size_mb: largest file the child may write (RLIMIT_FSIZE); SIGXFSZ beyond it.
        open_files: open file descriptors (RLIMIT_NOFILE).
        user: run the child as this user (for example "nobody"), or as this numeric uid (and gid),
            which needs no passwd entry; needs a caller running as root.
            The child gets a fresh HOME/ROS_HOME it owns, since ROS writes logs there.
        grace_seconds: time between SIGINT and SIGKILL when the wall time runs out.
    """

    wall_seconds: float | None = None
    memory_mb: int | None = None
    cpu_seconds: int | None = None
    max_processes: int | None = None
    file_size_mb: int | None = None
    open_files: int | None = None
    user: str | int | None = None
    grace_seconds: float = 2.0

    def __post_init__(self):
        for field in ("wall_seconds", "memory_mb", "cpu_seconds", "max_processes", "file_size_mb",
                      "open_files"):
            value = getattr(self, field)
            if value is not None and not value > 0:
                raise ValueError(f"Limits.{field} is {value!r}: use a positive number, or None for no limit")
        if self.grace_seconds < 0:
            raise ValueError(f"Limits.grace_seconds is {self.grace_seconds!r}: use 0 or more seconds")

    def rlimits(self) -> dict[str, int]:
        """The limits to set, by name of the resource constant (RLIMIT_AS is in bytes)."""
        mb = 1024 * 1024
        values = {"RLIMIT_AS": self.memory_mb and self.memory_mb * mb,
                  "RLIMIT_CPU": self.cpu_seconds and int(self.cpu_seconds),
                  "RLIMIT_NPROC": self.max_processes,
                  "RLIMIT_FSIZE": self.file_size_mb and self.file_size_mb * mb,
                  "RLIMIT_NOFILE": self.open_files}
        return {name: int(value) for name, value in values.items() if value}

    def rlimit_pairs(self) -> dict[str, tuple[int, int]]:
        """(soft, hard) per resource. The CPU hard limit is one second above the soft one, so
        the child gets SIGXCPU (which says why) rather than a bare SIGKILL."""
        return {name: (value, value + 1 if name == "RLIMIT_CPU" else value)
                for name, value in self.rlimits().items()}


class NodeProcess:
    """One node (or any command) running as a child process in its own process group.

    Args:
        command: the program and its arguments, e.g. ``[sys.executable, "-m", "pkg.node"]``.
        name: a label for messages. When given explicitly, starting a NodeProcess stops a
            running one of the same name first, so re-running a notebook cell replaces its node;
            and when another program (a notebook whose kernel still runs) runs one of that name
            in the same domain, start() prints a plain warning that names it
            (course_lib.process_registry).
        domain_id: ROS_DOMAIN_ID of the child; None keeps the caller's.
        env: variables to set for the child on top of the caller's environment (a value of
            None removes a variable).
        cwd: working directory of the child.
        limits: resource bounds (see Limits); None for none.
        on_output: called as ``on_output(stream, data)`` with each piece of the child's output
            as it arrives, stream being "stdout" or "stderr" (from a thread of its own; the
            log keeps everything as well). By the time returncode is known, on_output has had
            all of it (so on_output must not wait for this process). With it the child's stdout
            and stderr are separate pipes, so their order in the log is only as exact as their
            arrival.

    Attributes:
        pid: the child's process id (it also leads the child's process group) once started.
        domain_id: the child's ROS_DOMAIN_ID, where wait_for_node looks.
        exit_reason: None while running, then "exited" (on its own), "stopped" (stop()),
            "wall_seconds" (Limits), "parent_exited" or "supervisor_died".
        usage: after the end, {"max_rss_kb", "cpu_seconds"} of the child (the peak memory
            includes the ~20 MB of the supervisor it was forked from) and the supervisor's own
            "supervisor_max_rss_kb".
    """

    def __init__(self, command: list[str], *, name: str | None = None, domain_id: int | None = None,
                 env: dict | None = None, cwd=None, limits: Limits | None = None,
                 on_output: Callable[[str, bytes], None] | None = None):
        from course_lib import rosenv  # imported here: the supervisor runs this file without it

        if isinstance(command, (str, bytes)) or not command:
            raise TypeError(f"command must be a non-empty list of strings like ['python', '-m', 'pkg.node'], "
                            f"not {command!r}")
        self.command = [os.fspath(part) for part in command]
        self._explicit_name = name is not None
        self.name = name or Path(self.command[0]).name
        self.cwd = None if cwd is None else os.fspath(cwd)
        self.limits = limits or Limits()
        self._on_output = on_output
        self._relay: threading.Thread | None = None
        base = dict(os.environ)
        for key, value in (env or {}).items():
            if value is None:
                base.pop(key, None)
            else:
                base[key] = str(value)
        self.env = rosenv.ros_environment(domain_id=domain_id, base=base)
        self.domain_id = int(self.env["ROS_DOMAIN_ID"])
        self.pid: int | None = None
        self.exit_reason: str | None = None
        self.usage: dict | None = None
        self.warned_duplicate = False  # start() said that another program runs one of this name
        self._supervisor: subprocess.Popen | None = None
        self._control: int | None = None
        self._status: int | None = None
        self._status_buffer = b""
        self._log_dir: Path | None = None
        self._home_dir: Path | None = None
        self._final_log: bytes | None = None
        self._returncode: int | None = None
        self._lock = threading.RLock()

    def __repr__(self) -> str:
        state = "not started" if self._supervisor is None else (
            "running" if self.running() else self.describe_exit())
        return f"<NodeProcess {self.name!r} pid={self.pid} {state}>"

    # -- starting ---------------------------------------------------------------------------

    def start(self) -> "NodeProcess":
        """Start the command under a supervisor and return self.

        Raises:
            RuntimeError: this NodeProcess was started before.
            FileNotFoundError, PermissionError, OSError: the command could not be executed.
        """
        with self._lock:
            if self._supervisor is not None:
                raise RuntimeError(f"{self.name} was already started; create a new NodeProcess to run it again")
            if self._explicit_name:
                for other in _running_processes():
                    if other is not self and other._explicit_name and other.name == self.name:
                        other.stop()
            env = dict(self.env)
            self._log_dir = Path(tempfile.mkdtemp(prefix="course_lib-node-"))
            cleanup = [str(self._log_dir)]
            if self.limits.user is not None:
                self._home_dir = _home_for(self.limits.user)
                env["HOME"] = env["ROS_HOME"] = str(self._home_dir)
                env.pop("ROS_LOG_DIR", None)
                cleanup.append(str(self._home_dir))
            control_read, self._control = os.pipe()
            self._status, status_write = os.pipe()
            echo_read, echo_write = os.pipe() if self._on_output is not None else (None, None)
            config = {"command": self.command, "cwd": self.cwd, "log_dir": str(self._log_dir),
                      "head_bytes": LOG_HEAD_BYTES, "tail_bytes": LOG_TAIL_BYTES,
                      "rlimits": self.limits.rlimit_pairs(), "wall_seconds": self.limits.wall_seconds,
                      "grace_seconds": self.limits.grace_seconds, "user": self.limits.user,
                      "cleanup": cleanup, "echo_fd": echo_write}
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
                if self._explicit_name:
                    self._note_running()
                return self
            if event and event.get("event") == "error":
                self._poll(wait=True)
                raise _start_error(event, self.command, self.cwd, self.limits.user)
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

    @property
    def log(self) -> str:
        """Everything the child wrote to stdout and stderr so far, with the middle of a very
        long output replaced by a line that says how many bytes were left out."""
        # No lock: stop() holds it while it waits, and reading the log must not wait for that.
        log_dir, data = self._log_dir, self._final_log
        if data is None and log_dir is not None:
            data = _read_log(log_dir, LOG_TAIL_BYTES // 2)
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
                 "supervisor_died": " because its supervisor died"}
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
        deadline = time.monotonic() + timeout
        while True:
            log = self.log
            if text in log:
                return log
            if not self.running():
                if text in self.log:
                    return self.log
                raise RuntimeError(f"{self.name} ended ({self.describe_exit()}) before printing {text!r}. "
                                   f"Last output:\n{self.log_tail()}")
            if time.monotonic() >= deadline:
                raise TimeoutError(f"{self.name} did not print {text!r} within {timeout} s. "
                                   f"Last output:\n{self.log_tail()}")
            time.sleep(0.05)

    def wait_for_node(self, node_name: str, timeout: float = 10.0, namespace: str | None = None) -> None:
        """Wait until a node of this name is in the ROS graph of the child's domain.

        Args:
            node_name: "talker", or a fully qualified "/ns/talker".
            timeout: seconds to wait; discovery alone takes about a second.
            namespace: only accept the node in this namespace; None accepts any.

        Raises:
            RuntimeError: the child exited first (the message has its exit code and last output).
            TimeoutError: the node did not appear (the message has the child's last output).
        """
        import rclpy
        from rclpy.context import Context

        self._require_started()
        if node_name.startswith("/"):
            namespace, _, node_name = node_name.rpartition("/")
            namespace = namespace or "/"
        elif namespace is not None:
            namespace = "/" + namespace.strip("/")
        wanted = node_name if namespace is None else f"{namespace.rstrip('/')}/{node_name}"
        already_running = _in_session_graph(node_name, namespace, self.domain_id)
        context = Context()
        rclpy.init(context=context, domain_id=self.domain_id)
        watcher = None
        try:
            watcher = rclpy.create_node(f"_course_lib_wait_{os.getpid()}_{next(_WATCHER_IDS)}",
                                        context=context, enable_rosout=False,
                                        start_parameter_services=False)
            deadline = time.monotonic() + timeout
            while True:
                # The graph is filled in by DDS discovery threads; no spinning needed to read it.
                if any(name == node_name and namespace in (None, ns)
                       for name, ns in watcher.get_node_names_and_namespaces()):
                    if already_running and not self.warned_duplicate:
                        _warn_if_still_running(already_running, self)
                    return
                if not self.running():
                    raise RuntimeError(f"{self.name} ended ({self.describe_exit()}) before node {wanted!r} "
                                       f"appeared. Last output:\n{self.log_tail()}")
                if time.monotonic() >= deadline:
                    raise TimeoutError(
                        f"Node {wanted!r} did not appear in ROS domain {self.domain_id} within {timeout} s, "
                        f"although {self.name} still runs: check the node name it passes to Node() and "
                        f"that it calls rclpy.init(). Last output:\n{self.log_tail()}")
                time.sleep(0.05)
        finally:
            if watcher is not None:
                watcher.destroy_node()
            context.try_shutdown()

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

    def _request_stop(self, timeout: float) -> None:
        if self._control is not None and self._returncode is None:
            try:
                os.write(self._control, f"stop {float(timeout)}\n".encode())
            except OSError:  # the supervisor has gone; _poll() will find out how
                pass

    def __enter__(self) -> "NodeProcess":
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
                    _killpg(self.pid, signal.SIGKILL)
                self._returncode = -signal.SIGKILL
                self.exit_reason = "supervisor_died"
            if self._log_dir is not None:
                self._final_log = _read_log(self._log_dir, LOG_TAIL_BYTES // 2)
            self._close_fds()
            self._remove_dirs()
            with _RUNNING_LOCK:
                _RUNNING.discard(self)
            if self._explicit_name:
                from course_lib import process_registry

                process_registry.forget(self.pid)

    def _note_running(self) -> None:
        """Record this named process machine-wide, and warn plainly when another program (a
        notebook whose kernel still runs) runs one of the same name in the same domain."""
        from course_lib import process_registry

        others = process_registry.started_elsewhere(self.name, self.domain_id)
        process_registry.record(self.name, self.domain_id, self.pid)
        if others:
            self.warned_duplicate = True
            print(f"Warning: another node process named {self.name!r} runs in ROS domain {self.domain_id}, "
                  f"started by {process_registry.describe(others[0])}. Both publish on the same topics, so "
                  "subscribers get their messages mixed (two cameras: frames from both). Stop the other one: "
                  "run the clean-up cell of that notebook or shut its kernel down (Kernel > Shut Down Kernel, "
                  "or the Running Terminals and Kernels panel), then run this cell again.", flush=True)

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
        self._log_dir = self._home_dir = None

    def _kill_supervisor(self) -> None:
        self._supervisor.kill()
        self._supervisor.wait()
        if self.pid is not None:
            _killpg(self.pid, signal.SIGKILL)

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
        for directory in (self._log_dir, self._home_dir):
            if directory is not None:
                shutil.rmtree(directory, ignore_errors=True)
        self._home_dir = None


#: Seconds a node of the same name that ran before a new node process started may take to
#: leave the graph (a re-run cell stopped it a moment ago) before wait_for_node warns.
DUPLICATE_GRACE = 2.0


def _in_session_graph(node_name: str, namespace: str | None, domain_id: int) -> dict[str, str]:
    """The nodes of this name that the notebook's ROS session sees (none when no session runs
    on this domain), as {id of the node's /rosout publisher: full node name}. Node names are not
    unique; the publisher id tells one node from another of the same name."""
    from course_lib import graph, session

    if not session.is_running() or session.tool_node().context.get_domain_id() != domain_id:
        return {}
    graph.node_list()  # the first query waits for discovery
    return {str(endpoint.endpoint_gid): full for endpoint, full in _rosout_publishers(session.tool_node())
            if full.rsplit("/", 1)[-1] == node_name
            and (namespace is None or full == f"{namespace.rstrip('/')}/{node_name}")}


def _rosout_publishers(node):
    """(endpoint, full node name) of every /rosout publisher: one per node with a logger."""
    for endpoint in node.get_publishers_info_by_topic("/rosout"):
        yield endpoint, f"{endpoint.node_namespace.rstrip('/')}/{endpoint.node_name}"


def _warn_if_still_running(earlier: dict[str, str], process: "NodeProcess") -> None:
    """Print a plain warning when a node of the same name ran before this process started and
    still runs next to its node, e.g. a camera that the previous lesson's kernel left running:
    two cameras on one topic mix their frames."""
    from course_lib import session

    deadline = time.monotonic() + DUPLICATE_GRACE
    while True:
        still = {str(endpoint.endpoint_gid) for endpoint, _ in _rosout_publishers(session.tool_node())} & set(earlier)
        if not still:
            return  # it has left: a re-run cell replaced it a moment ago
        if time.monotonic() >= deadline:
            break
        time.sleep(0.1)
    full = earlier[next(iter(still))]
    print(f"Warning: another node named {full} runs in ROS domain {process.domain_id}: it was already running "
          f"before {process.name} started, from another program, most likely another notebook whose kernel "
          "still runs (an earlier lesson left without its clean-up cell) or a terminal. Both publish on the "
          "same topics, so subscribers get their messages mixed (two cameras: frames from both). Stop the "
          "other one: run the clean-up cell of that notebook or shut its kernel down (Kernel > Shut Down "
          "Kernel, or the Running Terminals and Kernels panel), then run this cell again.", flush=True)


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
                    print(f"course_lib.processes: on_output raised {error!r}", file=sys.stderr)
    finally:
        os.close(fd)


def python_node(target: str, *args: str, **kwargs) -> NodeProcess:
    """Start a Python node with this interpreter and return its running NodeProcess.

    Args:
        target: "package.module" (run like ``python -m package.module``) or
            "package.module:function" (import it and call ``function()``, like a setup.py
            console-script entry point such as ``talker = demo.talker:main``).
        *args: command-line arguments for the node (sys.argv[1:]), e.g. "--ros-args", "-r", ...
        **kwargs: passed to NodeProcess (name, domain_id, env, cwd, limits).

    Raises:
        ValueError: the target is not in one of the two forms.
    """
    module, colon, function = target.partition(":")
    parts = module.split(".") + (function.split(".") if colon else [])
    if not all(part.isidentifier() for part in parts):
        raise ValueError(f"python_node target {target!r} is not 'package.module' or 'package.module:function' "
                         "(dotted Python names, like a setup.py entry point 'demo.talker:main')")
    if colon:
        code = ("import importlib, sys; "
                f"sys.argv[0] = {target!r}; "
                f"entry = importlib.import_module({module!r}); "
                + "".join(f"entry = entry.{name}; " for name in function.split("."))
                + "sys.exit(entry())")
        command = [sys.executable, "-c", code, *args]
    else:
        command = [sys.executable, "-m", module, *args]
    process = NodeProcess(command, **kwargs)
    if kwargs.get("name") is None:  # a label only: two nodes of one module may run side by side
        process.name = module.rsplit(".", 1)[-1]
    return process.start()


def stop_all(timeout: float = 5.0) -> None:
    """Stop every NodeProcess this process started: all get SIGINT at once, then each is awaited."""
    stop_together(_running_processes(), timeout)


def stop_together(processes, timeout: float = 5.0) -> None:
    """Stop these NodeProcesses: all get SIGINT at once (so their shutdowns overlap), then each
    is awaited and killed if it still runs after `timeout` seconds."""
    processes = list(processes)
    for process in processes:
        process._request_stop(timeout)
    for process in processes:
        process.stop(timeout)


def _running_processes() -> list[NodeProcess]:
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


def _start_error(event: dict, command: list[str], cwd: str | None, user: str | None) -> OSError:
    number = event.get("errno")
    if number == errno.ENOENT:
        where = f" (working directory {cwd})" if cwd else ""
        return FileNotFoundError(number, f"Cannot run {command[0]!r}{where}: no such file or program on PATH; "
                                 f"check the spelling or give a full path", command[0])
    if number in (errno.EACCES, errno.EPERM):
        if user is not None:
            fix = (f"user {user!r} (Limits.user) needs read and execute access to it, to the interpreter "
                   f"it runs and to every directory above them (a virtual environment under /root is not)")
        else:
            fix = "make it executable (chmod +x) or run it through its interpreter"
        return PermissionError(number, f"Cannot run {command[0]!r}: permission denied; {fix}", command[0])
    return OSError(number, f"Cannot run {command!r}: {event.get('message')}")


def _home_for(user: str | int) -> Path:
    """A fresh home directory owned by `user`, for a child that runs as that user."""
    import pwd

    if isinstance(user, int):
        uid = gid = user
    else:
        try:
            entry = pwd.getpwnam(user)
        except KeyError:
            raise ValueError(f"Limits.user {user!r} does not exist on this machine; use an existing "
                             f"unprivileged account such as 'nobody'") from None
        uid, gid = entry.pw_uid, entry.pw_gid
    if os.geteuid() != 0 and uid != os.geteuid():
        raise PermissionError(f"Limits.user={user!r} needs the caller to run as root; "
                              "leave user=None when not running as root")
    home = Path(tempfile.mkdtemp(prefix="course_lib-home-"))
    os.chown(home, uid, gid)
    return home


def _read_log(directory: Path, chunk: int) -> bytes:
    """Join the head and the newest tail chunks the supervisor wrote (see _BoundedLog)."""
    for _attempt in range(5):
        try:
            head = (directory / "head").read_bytes() if (directory / "head").exists() else b""
            tails = sorted(directory.glob("tail.*"))[-2:]
            if not tails:
                return head
            first = int(tails[0].suffix[1:])
            data = b"".join(path.read_bytes() for path in tails)
        except FileNotFoundError:  # rotated while we read: read again
            continue
        omitted = first * chunk
        marker = f"\n[... {omitted} bytes of output omitted ...]\n".encode() if omitted else b""
        return head + marker + data
    return b""
