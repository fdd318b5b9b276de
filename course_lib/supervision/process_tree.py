"""Signal and stop a process tree: the process group a process leads, and what left that group.

The one place that ends process trees in the course:

- course_lib.supervision.supervisor (under every NodeProcess) signals its node's tree with :func:`signal_tree`,
  and kills what was re-parented to it with :func:`kill_children`;
- NodeProcess.stop and stop_together ask the supervisor to do that; when the supervisor itself is
  gone, :func:`signal_group` kills what its node's group left;
- a plain subprocess.Popen started with ``start_new_session=True`` (a build) is stopped with
  :func:`stop_group`: SIGINT, then SIGTERM, then SIGKILL, each given its time.
- what is left of a submission (:func:`kill_uid`) or of a student's server (its namespace,
  coursehub.spawner) is killed with :func:`kill_all`, until none is left.

The plain-terminal equivalent is ``kill -INT -- -PGID`` (a negative pid names a process group).
Standard library only: the supervisor runs without site-packages.
"""

from __future__ import annotations

import dataclasses
import os
import signal
import subprocess
import time

#: How stop_group escalates: (signal, seconds to wait for the leader after it).
STOP_STEPS = ((signal.SIGINT, 5.0), (signal.SIGTERM, 5.0), (signal.SIGKILL, 5.0))


def signal_group(pgid: int, sig: int) -> None:
    """Send `sig` to every process of process group `pgid`; nothing when the group has gone."""
    try:
        os.killpg(pgid, sig)
    except (ProcessLookupError, PermissionError):
        pass


def signal_tree(pid: int, sig: int) -> None:
    """Signal the process group `pid` leads, and `pid` itself only if it left that group.

    Signalling a group member twice would deliver SIGINT twice: the second one can land in the
    node's own clean-up (its finally block) and turn a clean exit into a traceback.
    """
    signal_group(pid, sig)
    try:
        if os.getpgid(pid) != pid:
            os.kill(pid, sig)
    except ProcessLookupError:
        pass


def stat_fields(pid: int) -> list[str]:
    """The fields of /proc/PID/stat after the command name (which may hold spaces and parentheses):
    proc(5)'s field 3 (the state) is [0], the parent's pid [1], the process group [2], utime,
    stime, cutime and cstime [11:15] (clock ticks), the start time [19].

    Raises:
        OSError: the process has gone.
    """
    with open(f"/proc/{pid}/stat") as handle:
        return handle.read().rsplit(")", 1)[1].split()


def running(pid: int) -> bool:
    """Whether process `pid` still runs: it exists and has not ended. An ended process stays in
    /proc as a zombie (state Z) until its parent waits for it, but it holds nothing any more: no
    sockets, no memory, no DDS participant."""
    try:
        return stat_fields(pid)[0] not in ("Z", "X")
    except (OSError, IndexError):
        return False


def processes_of_uid(uid: int) -> list[int]:
    """The running processes (zombies left out) whose real uid is `uid`, read from /proc."""
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/status") as handle:
                fields = dict(line.split(":", 1) for line in handle if line.startswith(("State:", "Uid:")))
        except OSError:
            continue  # gone meanwhile
        if int(fields.get("Uid", "-1 ").split()[0]) == uid and fields.get("State", "Z").split()[0] not in ("Z", "X"):
            found.append(int(entry))
    return found


def _task_count(pid: int) -> int:
    try:
        return len(os.listdir(f"/proc/{pid}/task"))
    except OSError:
        return 0  # gone meanwhile


def tree_tasks(pid: int) -> int:
    """Processes and threads of the descendants of process `pid` (zombies count one), not of `pid`."""
    return sum(_task_count(child) for child in descendants_of(pid))


def uid_tasks(uid: int) -> int:
    """Processes and threads whose owner is `uid` (zombies count one): what RLIMIT_NPROC counts for
    that user; read from /proc (a stat per process, a listing per process of the user)."""
    total = 0
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                if os.stat(f"/proc/{entry}").st_uid != uid:
                    continue
            except OSError:
                continue
            total += _task_count(int(entry))
    return total


def kill_all(find, timeout: float = 5.0) -> int:
    """SIGKILL every process that ``find()`` lists (running ones, zombies left out), again and
    again until it lists none (a process may fork while it is being killed) or `timeout` seconds
    pass. Returns how many processes it killed."""
    killed, deadline = set(), time.monotonic() + timeout
    while (alive := find()) and time.monotonic() < deadline:
        for pid in alive:
            try:
                os.kill(pid, signal.SIGKILL)
                killed.add(pid)
            except ProcessLookupError:
                pass
        time.sleep(0.01)  # SIGKILL is delivered at once, but the process needs a moment to end
    return len(killed)


def kill_uid(uid: int, timeout: float = 5.0) -> int:
    """kill_all of the running processes of real uid `uid`. For a uid that only one caller's
    processes use (the grader's per-worker uids). Returns how many processes it killed."""
    return kill_all(lambda: processes_of_uid(uid), timeout)


def children_of(pid: int) -> list[int]:
    """Direct children of process `pid` (read from /proc; exact when `pid` has a single thread)."""
    try:
        with open(f"/proc/{pid}/task/{pid}/children") as handle:
            return [int(p) for p in handle.read().split()]
    except FileNotFoundError:  # kernel without CONFIG_PROC_CHILDREN: scan /proc
        found = []
        for entry in os.listdir("/proc"):
            if entry.isdigit():
                try:
                    parent = int(stat_fields(int(entry))[1])
                except (OSError, IndexError):
                    continue
                if parent == pid:
                    found.append(int(entry))
        return found


def descendants_of(pid: int) -> list[int]:
    """Every live descendant of process `pid` (children of any of its threads, their children,
    ...), read from /proc; [] when `pid` has gone."""
    found, todo = [], [pid]
    while todo:
        parent = todo.pop()
        try:
            tasks = os.listdir(f"/proc/{parent}/task")
        except OSError:
            continue
        for task in tasks:
            try:
                with open(f"/proc/{parent}/task/{task}/children") as handle:
                    children = [int(p) for p in handle.read().split()]
            except OSError:
                continue
            found += children
            todo += children
    return found


def command_line(pid: int) -> list[str]:
    """The command line of process `pid` ([] when it has gone or has none)."""
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as handle:
            return [part.decode(errors="replace") for part in handle.read().split(b"\0") if part]
    except OSError:
        return []


def cpu_seconds(pid: int, include_self: bool = True) -> float:
    """Processor time (user + system, all threads) that process `pid` and its descendants have
    used so far, children they have reaped included; 0.0 for a process that has gone.

    Unlike wall time it does not grow when the machine is busy: a computation costs the same
    processor time whether it had a whole core or a tenth of one (the grader's verdicts rely on it).
    """
    tick = os.sysconf("SC_CLK_TCK")
    total = 0
    for member in ([pid] if include_self else []) + descendants_of(pid):
        try:
            total += sum(int(value) for value in stat_fields(member)[11:15])  # utime, stime, cutime, cstime
        except (OSError, IndexError):
            continue
    return total / tick


def kill_children(timeout: float = 5.0) -> None:
    """SIGKILL and reap every child of this process until none is left or `timeout` seconds pass
    (a child subreaper's leftovers: descendants that left their group were re-parented to it)."""
    deadline = time.monotonic() + timeout
    while (orphans := children_of(os.getpid())) and time.monotonic() < deadline:
        for pid in orphans:
            try:
                os.kill(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
            except (ProcessLookupError, ChildProcessError):
                pass


def stop_group(process: subprocess.Popen, steps=STOP_STEPS) -> int | None:
    """Stop a Popen started with ``start_new_session=True`` and its process group: each signal of
    `steps` in turn to the whole group, until the leader has exited. Returns its returncode (None
    if it outlived every step)."""
    for sig, wait in steps:
        if process.poll() is not None:
            break
        signal_group(process.pid, sig)
        try:
            process.wait(timeout=wait)
        except subprocess.TimeoutExpired:
            continue
    return process.poll()


@dataclasses.dataclass(frozen=True)
class TreeMember:
    """One process of a supervised process's tree (SupervisedProcess.member), with the same questions."""

    pid: int

    def running(self) -> bool:
        return bool(command_line(self.pid))

    def cpu_seconds(self) -> float:
        return cpu_seconds(self.pid)
