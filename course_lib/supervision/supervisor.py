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

import json
import os
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
    log = BoundedLog(config["log_dir"], config["head_bytes"], config["tail_bytes"])
    try:
        child = subprocess.Popen(config["command"], stdin=subprocess.DEVNULL, stdout=output_write,
                                 stderr=error_write, cwd=config["cwd"], preexec_fn=prepare_child)
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
            process_tree.signal_tree(child.pid, signal.SIGINT)
        deadline = time.monotonic() + max(0.0, grace)
        kill_at = deadline if kill_at is None else min(kill_at, deadline)

    def send(number: int) -> None:
        """A signal the caller sends as a step of its own stop (ros2 launch's escalation)."""
        nonlocal reason
        reason = reason or "stopped"
        process_tree.signal_tree(child.pid, number)

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
                    elif line.startswith("signal"):
                        send(int(line.split()[1]))
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
            process_tree.signal_tree(child.pid, signal.SIGKILL)
            kill_at = None  # once is enough; SIGCHLD wakes us when it has died

    # The child has exited but is not reaped yet, so its process group id cannot be reused:
    # kill what it left in its group, then whatever was re-parented to us.
    process_tree.signal_group(child.pid, signal.SIGKILL)
    _, wait_status, usage = os.wait4(child.pid, 0)
    child.returncode = os.waitstatus_to_exitcode(wait_status)  # keeps Popen from waiting again
    process_tree.kill_children(timeout=5.0)
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


if __name__ == "__main__":
    sys.exit(_supervisor_main())
