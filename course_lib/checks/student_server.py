"""One student process that serves many calls (:class:`StudentServer`), and the servers of a
grading (:class:`StudentServers`).

A check calls the student's code in a process of the student (course_lib.checks.student): it
imports the student's module once (numpy, cv2, rclpy: most of a process's start-up) and then
answers one request after the other, each with its own time limit. A request that does not
return in time ends that process (the next request starts a fresh one), and the function it
called is not called again in this grading: later calls of it answer at once that it hung
before. Answers given before a hang or crash are kept (each is written as soon as it is done).

In a self-check the servers live as long as the check; at grading (autograder.grading.hidden_checks_process)
all checks of a submission share them.
"""

from __future__ import annotations

import collections
import shutil
import sys
import tempfile
import threading
import time
from pathlib import Path

from course_lib import waiting
from course_lib.checks.student_calls import last_lines, read_answer, write_request


class ServerError(Exception):
    """A request got no answer; str() says why (for the feedback)."""

    def __init__(self, message: str, timed_out: bool):
        super().__init__(message)
        self.timed_out = timed_out
        #: How it failed, without the process's last output ("used 5 s of processor time ...").
        self.reason = message.split(". Last output:", 1)[0]


class StudentServer:
    """A student process that answers requests one at a time (see the module docstring).

    Args:
        students: how the process starts (course_lib.checks.student_processes.StudentProcesses).
        cwd: its working directory (the student's module is imported from there).
        env: variables on top of the student's (a sourced workspace), or None.
        wall_seconds: the longest the process may live.
    """

    def __init__(self, students, cwd: Path, env: dict | None, wall_seconds: float):
        self.students, self.cwd, self.env, self.wall_seconds = students, Path(cwd), env, wall_seconds
        self.lock = threading.Lock()
        self.proc = None
        self.imported: dict[str, str | None] = {}  # module -> None (imported) or why it did not import
        self._job: Path | None = None
        self._number = 0

    def _start(self, domain_id: int) -> None:
        self._job = Path(tempfile.mkdtemp(prefix="autograder-student-"))
        self._job.chmod(0o755)  # the student's uid reads the requests ...
        (self._job / "in").mkdir(mode=0o755)
        (self._job / "out").mkdir(mode=0o700)
        self.students.give(self._job / "out")  # ... and writes its answers
        self._number = 0
        self.imported = {}
        self.proc = self.students.start([sys.executable, "-m", "course_lib.checks.student", "serve", str(self._job)],
                                        name=f"student-calls-{id(self):x}", cwd=self.cwd, domain_id=domain_id,
                                        wall_seconds=self.wall_seconds, env=self.env)

    def request(self, request: dict, arrays: dict | None, timeout: float, domain_id: int,
                cpu_seconds: float | None = None, waiting_after: float | None = None) -> dict:
        """Send one request and wait for its answer ({"value", "pytype"} or {"error"} or
        {"endpoints"}), starting the process first when none runs.

        Args:
            timeout: wall-clock seconds at most: the last backstop.
            cpu_seconds: processor seconds the request may use (the process's whole tree; None:
                no bound). What decides that computing code does not return: unlike wall time, it
                does not grow when the machine is busy.
            waiting_after: after this many seconds (default `timeout`) a process that waits
                (ProcessorTime.waiting: sleep, spin, input) rather than computes is not waited for
                any longer; one that still computes, slowly on a busy machine, is.

        Raises:
            ServerError: no answer: the process ended (timed_out False) or its processor time,
                its wait or the backstop ran out, or its processes reached their limit, now or after
                the call before (timed_out True; the process is then stopped).
        """
        if self.proc is not None and not self.proc.running() and self.proc.exit_reason == "max_processes":
            # Its earlier call answered, then its processes filled the user's limit (a fork bomb):
            # that, not this call, was the last thing it did; another process would do it again.
            why = self.proc.describe_exit()
            self.stop()
            raise ServerError(f"was not run: the process that served the call before it was {why}", True)
        if self.proc is None or not self.proc.running():
            self.stop()
            self._start(domain_id)
        number, self._number = self._number, self._number + 1
        start_of_log = len(self.proc.log)
        outbox, proc = self._job / "out", self.proc
        spent = ProcessorTime(proc, cpu_seconds)
        waiting_after = timeout if waiting_after is None else min(waiting_after, timeout)
        write_request(self._job / "in", number, request, arrays)
        waiting.spin_until(lambda: (outbox / f"{number}.json").exists() or not proc.running()
                           or spent.gives_up(waiting_after), timeout, poll=0.005)
        answer = read_answer(outbox, number)
        if answer is not None:
            return answer
        timed_out, waited = proc.running(), spent.waiting()  # (read before the stop: then its time reads 0)
        self.stop(grace=0.1)  # a hung call is not waited for
        output = last_lines(proc.log[start_of_log:] if len(proc.log) > start_of_log else proc.log, 4)
        if spent.exceeded:
            raise ServerError(f"used {cpu_seconds:g} s of processor time without returning (an endless loop?). "
                              f"Last output:\n{output}", True)
        if timed_out:  # the limit it had, not the seconds it took: those grow with the machine's load
            how = ", waiting rather than computing (a sleep(), spin() or input()?)" if waited else ""
            limit = waiting_after if waited else timeout
            raise ServerError(f"did not return within {limit:.3g} s{how}. Last output:\n{output}", True)
        raise ServerError(f"ended the process ({proc.describe_exit()}) before returning. Last output:\n{output}",
                          proc.exit_reason == "max_processes")  # a fork bomb is not called again

    def stop(self, grace: float = 1.0) -> None:
        """Stop the process (SIGINT, SIGKILL after `grace` seconds) and remove its job folder."""
        if self.proc is not None:
            self.proc.stop(timeout=grace)
            self.proc = None
        if self._job is not None:
            shutil.rmtree(self._job, ignore_errors=True)
            self._job = None


class ProcessorTime:
    """The processor time a process (a NodeProcess: its whole tree) uses while something waits on
    it: whether it has used up `budget` seconds since this was made (or since it started, with
    `since_start`; None: never), and whether it is waiting (next to no processor time over the last
    WAITING_WINDOW seconds: asleep, blocked in spin() or input()). Read from /proc at most every
    CHECK_EVERY seconds."""

    CHECK_EVERY = 0.05
    #: Below this share of a core over WAITING_WINDOW seconds a process waits rather than starves:
    #: a runnable process still gets a tenth of a core on a machine loaded ten processes per core,
    #: and an rclpy node that waits in spin() uses about a hundredth.
    WAITING_SHARE = 0.03
    WAITING_WINDOW = 2.0

    def __init__(self, proc, budget: float | None = None, since_start: bool = False):
        self.proc, self.budget = proc, budget
        now, used = time.monotonic(), proc.cpu_seconds()
        self.created = now
        self.start = 0.0 if since_start else used
        self.samples = collections.deque([(now, used)])
        self.exceeded = False
        self._next = now + self.CHECK_EVERY

    def _sample(self) -> None:
        now = time.monotonic()
        if now < self._next:
            return
        self._next = now + self.CHECK_EVERY
        used = self.proc.cpu_seconds()
        self.samples.append((now, used))
        while len(self.samples) > 2 and self.samples[1][0] <= now - self.WAITING_WINDOW:
            self.samples.popleft()
        self.exceeded = self.budget is not None and used - self.start >= self.budget

    def used_up(self) -> bool:
        self._sample()
        return self.exceeded

    def waiting(self) -> bool:
        self._sample()
        (first, used_first), (last, used_last) = self.samples[0], self.samples[-1]
        span = last - first
        if used_last == 0.0 < used_first:
            return False  # it has just ended (its time reads 0 once it is gone): the caller sees it end
        return span >= self.WAITING_WINDOW and used_last - used_first < self.WAITING_SHARE * span

    def waits_after(self, seconds: float) -> bool:
        """True once `seconds` have passed since this was made and the process is waiting."""
        return time.monotonic() - self.created >= seconds and self.waiting()

    def gives_up(self, seconds: float) -> bool:
        """True once the budget is used up, or the process waits after `seconds` (waits_after)."""
        return self.used_up() or self.waits_after(seconds)


class StudentServers:
    """The student servers of a grading (or of one self-check), one per working directory and
    environment, and the functions that hung in it: {function: why}."""

    def __init__(self, wall_seconds: float = 600.0):
        self.wall_seconds = wall_seconds
        self.hung: dict[str, str] = {}
        self._servers: dict[tuple, StudentServer] = {}
        self._lock = threading.Lock()
        self._started = time.monotonic()

    def server(self, students, cwd: Path, env: dict | None) -> StudentServer:
        # The checks of a grading may each have a ROS domain: the server serves them all.
        key = (str(cwd), tuple(sorted(((k, v) for k, v in (env or {}).items() if k != "ROS_DOMAIN_ID"), key=str)))
        with self._lock:
            if key not in self._servers:
                left = self.wall_seconds - (time.monotonic() - self._started)
                self._servers[key] = StudentServer(students, cwd, env, max(5.0, left + 5))
            return self._servers[key]

    def processes(self) -> list:
        """The running processes of the servers (a check's clean-up must leave them running)."""
        return [server.proc for server in self._servers.values() if server.proc is not None]

    def close(self) -> None:
        for server in self._servers.values():
            server.stop()
