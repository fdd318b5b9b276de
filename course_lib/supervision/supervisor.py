"""The supervisor of one node process (course_lib.ros.processes.NodeProcess starts it).

It runs as a script of a fresh ``python -I -S``, so neither site-packages, the ROS bootstrapper
nor course_lib's package imports cost start-up time. The supervisor is the node's direct parent, and

- it puts the node in a process group of its own, so a stop reaches the node's own children;
- it is a child subreaper, so descendants that leave the group (``setsid``, daemons) are
  re-parented to it and killed too;
- it reads a pipe whose only writer is the caller: when the caller dies in any way (atexit,
  SIGTERM, even SIGKILL) the pipe closes, and the supervisor stops the group;
- the node gets PR_SET_PDEATHSIG=SIGKILL, so it dies with the supervisor;
- resource limits (setrlimit) are set in the supervisor's fork, which has no threads, never in
  the caller (a kernel or a process that runs DDS threads, where ``preexec_fn`` is unsafe).

The supervisor also relays the node's output to a log that keeps its head and its tail, so a
node that prints a gigabyte neither blocks nor fills memory or disk.
"""

from __future__ import annotations

import ctypes
import json
import os
import resource
import select
import shutil
import signal
import subprocess
import sys
import time

if __name__ == "__main__":  # run as a script (python -I -S): find the sibling modules by their folder
    sys.path.append(os.path.dirname(os.path.abspath(__file__)))
    import process_tree
    from bounded_log import BoundedLog
else:
    from course_lib.supervision import process_tree
    from course_lib.supervision.bounded_log import BoundedLog

#: Seconds a node gets to shut down after SIGINT when its caller has gone away.
PARENT_GONE_GRACE = 1.0

#: Largest piece of output in one echo frame: a frame (3 header bytes + piece) stays within
#: PIPE_BUF, so a non-blocking write of it is all or nothing and frames never interleave.
_ECHO_PIECE = 4000

_PR_SET_PDEATHSIG = 1
_PR_SET_CHILD_SUBREAPER = 36

#: Seconds between two counts of the child's processes and threads against config["max_tasks"].
TASKS_EVERY = 0.1
#: A user's processes and threads are counted one process after the other while they fork and end:
#: a count within this share of the limit is taken for the limit.
TASKS_SLACK = 1 / 32



def _peak_rss_kb() -> int:
    """This process's peak resident memory since its exec (getrusage's ru_maxrss would include
    the memory of the process it was forked from)."""
    with open("/proc/self/status") as handle:
        for line in handle:
            if line.startswith("VmHWM:"):
                return int(line.split()[1])
    return 0


def _parse_arguments(argv: list[str]) -> tuple[int, dict]:
    """The status pipe's fd and the config from argv [status_fd, config_json]."""
    status_fd, config = argv
    config = json.loads(config)
    return int(status_fd), config


class _Supervisor:
    """One child's supervision: the state its steps share, each step a method _supervisor_main calls in order."""

    def __init__(self, status_fd: int, config: dict) -> None:
        """Open the status pipe, become a subreaper and catch signals, before any child exists."""
        self.config = config
        self.status = os.fdopen(status_fd, "wb", buffering=0)
        self.me, self.parent = os.getpid(), os.getppid()
        self.libc = ctypes.CDLL(None, use_errno=True)
        self.libc.prctl(_PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0)
        self.signalled: list[int] = []
        self.wake_read = self._catch_signals()
        self.echo_fd = config.get("echo_fd")
        self.echo_dropped = {b"o": 0, b"e": 0}
        self.reason: str | None = None
        self.kill_at: float | None = None
        self.parent_gone = False
        self.count_at = None if not config.get("max_tasks") else time.monotonic()

    def report(self, **event) -> None:
        """Write one event as a JSON line to the status pipe; the caller may have gone."""
        try:
            self.status.write(json.dumps(event).encode() + b"\n")
        except OSError:  # the caller has gone
            pass

    def _catch_signals(self) -> int:
        """Note SIGTERM, SIGINT and SIGHUP, and wake poll on them and on SIGCHLD; returns the wake pipe's read end."""
        wake_read, wake_write = os.pipe()
        os.set_blocking(wake_read, False)
        os.set_blocking(wake_write, False)
        signal.set_wakeup_fd(wake_write, warn_on_full_buffer=False)
        signal.signal(signal.SIGCHLD, lambda *_: None)
        for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
            signal.signal(sig, lambda number, _frame: self.signalled.append(number))
        return wake_read

    def start_child(self) -> bool:
        """Start the command with its limits and output pipes; False, reported as not_started, if it cannot start."""
        config = self.config
        self.rlimits = [(getattr(resource, name), tuple(pair)) for name, pair in config["rlimits"].items()]
        # Without an echo the child's stdout and stderr share one pipe, so the log keeps their exact
        # order; with one they get a pipe each, so the caller can tell them apart.
        output_read, output_write = os.pipe()
        self.streams = {output_read: b"o"}
        error_write = output_write
        if self.echo_fd is not None:
            os.set_blocking(self.echo_fd, False)
            error_read, error_write = os.pipe()
            self.streams[error_read] = b"e"
        self.log = BoundedLog(config["log_dir"], config["head_bytes"], config["tail_bytes"])
        try:
            self.child = subprocess.Popen(config["command"], stdin=subprocess.DEVNULL, stdout=output_write,
                                          stderr=error_write, cwd=config["cwd"], preexec_fn=self._prepare_child)
        except OSError as error:
            self.report(event="error", errno=error.errno, message=str(error))
            self.report(event="exited", returncode=127, reason="not_started", max_rss_kb=0, cpu_seconds=0.0,
                        supervisor_max_rss_kb=_peak_rss_kb())
            self.log.close()
            return False
        finally:
            os.close(output_write)
            if error_write != output_write:
                os.close(error_write)
        self.report(event="started", pid=self.child.pid)
        return True

    def _prepare_child(self) -> None:
        """Own process group, death with the supervisor, rlimits: runs in the forked child before exec."""
        # Safe here: the supervisor has no threads. Only attribute look-ups and system calls, as before exec.
        os.setpgid(0, 0)
        self.libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        if os.getppid() != self.me:  # the supervisor died before prctl took effect
            os.kill(os.getpid(), signal.SIGKILL)
        for resource_id, pair in self.rlimits:
            resource.setrlimit(resource_id, pair)

    def wait_for_child(self) -> None:
        """Relay output until the child exits, stopping it on a stop request, a lost caller or its wall time."""
        self.poller = select.poll()
        self.poller.register(0, select.POLLIN)
        for fd in self.streams:
            os.set_blocking(fd, False)
            self.poller.register(fd, select.POLLIN)
        self.poller.register(self.wake_read, select.POLLIN)
        wall = self.config["wall_seconds"]
        self.wall_deadline = None if wall is None else time.monotonic() + wall
        while os.waitid(os.P_PID, self.child.pid, os.WEXITED | os.WNOHANG | os.WNOWAIT) is None:
            timeouts = [0.5] + [t - time.monotonic() for t in (self.kill_at, self.wall_deadline, self.count_at)
                                if t is not None]
            for fd, _events in self.poller.poll(max(0, int(min(timeouts) * 1000) + 1)):
                if fd in self.streams and not self.relay_output(fd):
                    self.poller.unregister(fd)
                elif fd == self.wake_read:
                    self._drain_wakeups()
                elif fd == 0:
                    self._read_control()
            self._enforce_stops()

    def _drain_wakeups(self) -> None:
        """Empty the signal wake-up pipe, so that poll sleeps again."""
        while True:
            try:
                if not os.read(self.wake_read, 512):
                    break
            except BlockingIOError:
                break

    def _read_control(self) -> None:
        """Act on the caller's lines on stdin ("stop GRACE", "signal NUMBER"); its end closed means it has gone."""
        command = os.read(0, 4096)
        if not command:  # the caller closed its end: it has exited, one way or another
            self.parent_gone = True
            self.poller.unregister(0)
            self.begin_stop("parent_exited", PARENT_GONE_GRACE)
        for line in command.decode(errors="replace").splitlines():
            if line.startswith("stop"):
                self.begin_stop("stopped", float(line.split()[1]))
            elif line.startswith("signal"):
                self.send(int(line.split()[1]))

    def _enforce_stops(self) -> None:
        """Begin a stop on a caught signal, a changed parent or the wall time; SIGKILL once the grace is over."""
        if self.signalled:
            self.signalled.clear()
            self.begin_stop("stopped", PARENT_GONE_GRACE)
        if not self.parent_gone and os.getppid() != self.parent:
            self.parent_gone = True
            self.begin_stop("parent_exited", PARENT_GONE_GRACE)
        if self.wall_deadline is not None and time.monotonic() >= self.wall_deadline:
            self.wall_deadline = None
            self.begin_stop("wall_seconds", self.config["grace_seconds"])
        if self.kill_at is not None and time.monotonic() >= self.kill_at:
            process_tree.signal_tree(self.child.pid, signal.SIGKILL)
            self.kill_at = None  # once is enough; SIGCHLD wakes us when it has died
        if self.count_at is not None and time.monotonic() >= self.count_at:
            self.count_at = time.monotonic() + TASKS_EVERY
            self._stop_at_process_limit()

    def _stop_at_process_limit(self) -> None:
        """SIGKILL the child's tree at once when its user has as many processes and threads as
        config["max_tasks"] (its RLIMIT_NPROC: no process of that user can fork or start a thread
        any more) and this tree holds at least a quarter of them: a fork bomb, whose copies would
        otherwise go on running (a forked ROS node spins in its shared memory) until a check stops
        them. A quarter, not half: two bombs of one user (the student's function and node) may
        share the limit. A node needs about 15 (Fast DDS), plus a thread per core for OpenCV's
        pool. Its exit_reason becomes "max_processes"."""
        max_tasks = self.config["max_tasks"]
        if self.reason is not None or process_tree.tree_tasks(self.me) * 4 < max_tasks:
            return
        try:
            uid = os.stat(f"/proc/{self.child.pid}").st_uid
        except OSError:
            return
        if uid != 0 and process_tree.uid_tasks(uid) >= max_tasks * (1 - TASKS_SLACK):  # root has no such limit
            self.reason, self.count_at = "max_processes", None
            process_tree.signal_tree(self.child.pid, signal.SIGKILL)

    def begin_stop(self, why: str, grace: float) -> None:
        """SIGINT the child's tree on the first stop only, and SIGKILL it after the earliest grace asked for."""
        if self.reason is None:
            self.reason = why
            process_tree.signal_tree(self.child.pid, signal.SIGINT)
        deadline = time.monotonic() + max(0.0, grace)
        self.kill_at = deadline if self.kill_at is None else min(self.kill_at, deadline)

    def send(self, number: int) -> None:
        """A signal the caller sends as a step of its own stop (ros2 launch's escalation)."""
        self.reason = self.reason or "stopped"
        process_tree.signal_tree(self.child.pid, number)

    def echo(self, stream: bytes, data: bytes) -> None:
        """Frame output (stream, length, bytes) to the caller, dropping and counting what its pipe cannot take
        (the log keeps it), so the child never waits for a slow reader."""
        dropped_before, self.echo_dropped[stream] = self.echo_dropped[stream], 0
        note = f"[... {dropped_before} bytes of output not shown ...]\n".encode() if dropped_before else b""
        payload = note + data
        for start in range(0, len(payload), _ECHO_PIECE):
            piece = payload[start:start + _ECHO_PIECE]
            try:
                os.write(self.echo_fd, stream + len(piece).to_bytes(2, "big") + piece)
            except BlockingIOError:
                unsent = len(payload) - start
                self.echo_dropped[stream] = min(unsent, len(data)) + (dropped_before if unsent > len(data) else 0)
                return
            except OSError:  # the caller closed its end: stop echoing
                os.close(self.echo_fd)
                self.echo_fd = None
                return

    def relay_output(self, fd: int) -> bool:
        """Copy what the child wrote to the log (and the echo); False at end of stream."""
        while True:
            try:
                data = os.read(fd, 65536)
            except BlockingIOError:
                return True
            if not data:
                return False
            self.log.write(data)
            if self.echo_fd is not None:
                self.echo(self.streams[fd], data)

    def reap_and_report(self) -> None:
        """Kill what the child left, reap it, relay its last output and report its exit status and usage."""
        usage = self._reap_child()
        self._drain_output()
        self._note_dropped_echo()
        self.log.close()
        self.report(event="exited", returncode=self.child.returncode, reason=self.reason or "exited",
                    max_rss_kb=usage.ru_maxrss, cpu_seconds=round(usage.ru_utime + usage.ru_stime, 3),
                    supervisor_max_rss_kb=_peak_rss_kb())

    def _reap_child(self) -> resource.struct_rusage:
        """Kill the child's group and re-parented descendants around reaping it; returns its usage."""
        # The child has exited but is not reaped yet, so its process group id cannot be reused:
        # kill what it left in its group, then whatever was re-parented to us.
        process_tree.signal_group(self.child.pid, signal.SIGKILL)
        _, wait_status, usage = os.wait4(self.child.pid, 0)
        self.child.returncode = os.waitstatus_to_exitcode(wait_status)  # keeps Popen from waiting again
        process_tree.kill_children(timeout=5.0)
        return usage

    def _drain_output(self) -> None:
        """Relay what is left in the output pipes, for at most 2 seconds (a kept descendant may hold them open)."""
        drain_deadline = time.monotonic() + 2.0
        open_streams = list(self.streams)
        while open_streams and time.monotonic() < drain_deadline:
            ready = select.select(open_streams, [], [], max(0.0, drain_deadline - time.monotonic()))[0]
            if not ready:
                break
            for fd in ready:
                if not self.relay_output(fd):
                    open_streams.remove(fd)

    def _note_dropped_echo(self) -> None:
        """Say what was not shown, if the reader catches up soon enough."""
        if self.echo_fd is not None and any(self.echo_dropped.values()):
            if select.select([], [self.echo_fd], [], PARENT_GONE_GRACE * 2)[1]:
                for stream in self.echo_dropped:
                    if self.echo_dropped[stream] and self.echo_fd is not None:
                        self.echo(stream, b"")

    def clean_up(self) -> None:
        """Remove the log and work folders when the caller has gone: nobody will read them."""
        if self.parent_gone:
            for path in self.config["cleanup"]:
                shutil.rmtree(path, ignore_errors=True)


def _supervisor_main(argv: list[str] | None = None) -> int:
    """Entry of the supervisor process: argv is [status_fd, config_json]; stdin is the control pipe."""
    supervisor = _Supervisor(*_parse_arguments(sys.argv[1:3] if argv is None else argv))
    if supervisor.start_child():
        supervisor.wait_for_child()
        supervisor.reap_and_report()
        supervisor.clean_up()
    return 0


if __name__ == "__main__":
    sys.exit(_supervisor_main())
