"""The hub's grading service: graded feedback minutes after Submit (``python -m
coursehub.grading_service``, a JupyterHub-managed service: the hub starts it as root with itself,
restarts it when it dies, and stops it when the hub stops).

For the assignments the course's nbgrader_config.py names (``c.GradeOnSubmit.assignments``,
autograder.config), it

- looks at the exchange's inbound/ every second and queues each new, complete submission
  (coursehub.inbound; the queue coursehub.submit_queue is durable, so a submission that arrives
  while the service is down, or one it was grading when killed, is graded when it is back);
- grades the queue in arrival order, one submission per worker (coursehub.grading_job.grade;
  ``--workers``, else ``c.GradeOnSubmit.workers``, autograder.config), and the same files once:
  a worker given files another is grading waits for that grading and reuses it;
- writes and releases the feedback of what was graded (coursehub.grading_job.release), so that
  Fetch Feedback in the student's Assignments panel shows it;
- serves each student the state of their submissions (coursehub.grading_status), and publishes
  the attempts and due dates for the Submit of the students' servers (coursehub.limited_submit).

After the due date the instructor's usual collect, grade and feedback steps (coursehub.instructor)
find the service's results in the gradebook and the grader's records and give the final grades.
"""

from __future__ import annotations

import argparse
import itertools
import os
import sys
import threading
import time
import traceback
from pathlib import Path

from autograder import config
from autograder.term.release import assignments_in
from coursehub import course as course_settings
from coursehub import grading_job, inbound, limited_submit
from coursehub.submit_queue import SubmitQueue

#: Seconds before the feedback that could not be released is tried again, and how many tries a
#: submission's feedback gets before its row fails.
RETRY_SECONDS = 30.0
RELEASE_TRIES = 3
#: Seconds the feedback of a grading waits for the next one while the workers are busy.
BATCH_SECONDS = 2.0
#: Seconds between two publications of the rules for the students' servers (the due dates change
#: in the gradebook, which is not read every second).
PUBLISH_SECONDS = 30.0
#: At a stop, how long the gradings' runs still going may take to end before they are killed.
STOP_SECONDS = 5.0


def _log(text: str) -> None:
    print(f"coursehub.grading_service: {text}", file=sys.stderr, flush=True)


class Service:
    """The threads of the service: one looks at inbound/, `workers` grade, one releases feedback."""

    def __init__(self, course, workers: int = config.SUBMIT_WORKERS, poll_seconds: float = config.SUBMIT_POLL_SECONDS,
                 rules_file: Path | None = None):
        """`rules_file`: where the students' servers read the attempts and due dates
        (coursehub.limited_submit); None: not published."""
        self.course, self.workers, self.poll_seconds, self.rules_file = course, workers, poll_seconds, rules_file
        self.queue = SubmitQueue(course.course_dir)
        self.stopping = threading.Event()
        self.queued = threading.Semaphore(0)  # one release per row queued (and per recovered row)
        self.graded = threading.Event()
        self._rules, self._rules_read, self._rules_lock = {}, None, threading.Lock()
        self._contents, self._contents_lock = {}, threading.Lock()
        self._retry: dict[int, tuple[float, int]] = {}  # row id -> (when to release again, tries so far)
        self._students, self._roster_read = list(getattr(course, "students", [])), None

    def start(self) -> None:
        from autograder.grading import work_folders

        swept = work_folders.sweep()  # what the gradings of a killed service (or grade run) left
        if swept:
            _log(f"removed {len(swept)} work folder(s) of gradings cut short: {', '.join(map(str, swept))}")
        recovered = self.queue.recover()
        if recovered:
            _log(f"{recovered} submission(s) whose grading was cut short are queued again")
        for _ in range(len([r for r in self.queue.all() if r.state == "queued"])):
            self.queued.release()
        self.graded.set()  # feedback left unreleased by a stop is released now
        threads = [threading.Thread(target=self._look, name="grading-inbound", daemon=True),
                   threading.Thread(target=self._release, name="grading-feedback", daemon=True)]
        threads += [threading.Thread(target=self._grade, args=(n,), name=f"grading-worker-{n}", daemon=True)
                    for n in range(self.workers)]
        for thread in threads:
            thread.start()

    def rules(self) -> dict[str, config.SubmitRules]:
        """The assignments graded on submission, read again when nbgrader_config.py changes."""
        path = self.course.course_dir / "nbgrader_config.py"
        with self._rules_lock:  # the threads ask at once at the start: read and publish once
            stamp = path.stat().st_mtime_ns
            if stamp != self._rules_read:
                try:
                    self._rules = config.submit_rules(config.load(self.course.course_dir),
                                                      assignments_in(self.course.course_dir))
                except ValueError as error:
                    _log(f"{error} Grading on submission waits until it is corrected.")
                    self._rules = {}
                self._rules_read = stamp
                self.publish()
            return self._rules

    def publish(self) -> None:
        """The attempts and due dates for the students' servers' Submit (coursehub.limited_submit)."""
        if self.rules_file is not None:
            due = {name: grading_job.duedate(self.course.course_dir, name) for name in self._rules}
            limited_submit.write_rules(self.rules_file, {
                name: {"attempts": rule.attempts, "duedate": f"{due[name]} UTC" if due[name] else None}
                for name, rule in self._rules.items()})

    def students(self) -> dict[str, int]:
        """The roster's accounts and their uids: a submission counts for the student who owns it.
        The roster is read again when course.json changes (create-course run again to add students)."""
        import pwd

        roster = set(self.roster())
        return {entry.pw_name: entry.pw_uid for entry in pwd.getpwall() if entry.pw_name in roster}

    def roster(self) -> list[str]:
        settings = Path(getattr(self.course, "hub_dir", "")) / "course.json"
        with self._rules_lock:
            try:
                stamp = settings.stat().st_mtime_ns
            except OSError:  # a course without a hub directory (a benchmark's): its students as given
                return list(getattr(self.course, "students", []))
            if stamp != self._roster_read:
                self._students, self._roster_read = course_settings.load(settings.parent).students, stamp
            return self._students

    def look_once(self) -> int:
        """Queue the new complete submissions of assignments graded on submission, and refuse the
        entries of inbound/ that are no submission of their owner's (coursehub.inbound.look), each
        with its reason for the student who made it; return how many were looked at."""
        rules = self.rules()
        folder = inbound.inbound(self.course.exchange, self.course.course_id)
        entries = [e for e in inbound.new_entries(folder, self.queue.known(), self.students())
                   if e.refused or e.assignment in rules]
        for entry in entries:
            rule = rules.get(entry.assignment, config.SubmitRules())
            row = self.queue.add(entry.name, entry.student, entry.assignment, entry.submitted, rule.attempts,
                                 grading_job.duedate(self.course.course_dir, entry.assignment) if not entry.refused
                                 else None, refused=entry.refused)
            if row.state == "refused":
                inbound.set_aside(entry.path, row.id, self.course.course_dir)
                _log(f"refused {entry.name!r} (owner {entry.student}): {row.message}")
            else:
                self.queued.release()
        return len(entries)

    def _look(self) -> None:
        published = time.monotonic()
        while not self.stopping.is_set():
            try:
                self.look_once()
                if time.monotonic() - published > PUBLISH_SECONDS:
                    self.publish()
                    published = time.monotonic()
            except Exception:  # noqa: BLE001 - logged; the next look tries again
                _log(f"could not read the inbound submissions:\n{traceback.format_exc()}")
            self.stopping.wait(self.poll_seconds)

    def one_at_a_time(self, content: str) -> threading.Lock:
        """The lock of one content: held while a worker grades it, so that another worker given the
        same files waits and reuses that grading instead of grading them again."""
        with self._contents_lock:
            return self._contents.setdefault(content, threading.Lock())

    def _grade(self, worker: int) -> None:
        while not self.stopping.is_set():
            if not self.queued.acquire(timeout=self.poll_seconds):
                continue
            row = self.queue.claim(worker)
            if row is None:  # superseded meanwhile
                continue
            try:
                grading_job.grade(self.course, self.queue, row, self.students().get(row.student), self.one_at_a_time)
            except Exception:  # noqa: BLE001 - not the student's fault: the instructor's grade run takes it
                _log(f"could not grade {row.entry!r}:\n{traceback.format_exc()}")
                self.queue.failed(row.id, "the grading service ran into an error; your instructor will grade it.")
            self.graded.set()

    def _release(self) -> None:
        while not self.stopping.is_set():
            if not self.graded.wait(self.poll_seconds) and not self._retries_due():
                continue
            self.graded.clear()
            # Quick gradings in a row (the same content handed in by many) make one batch: a batch
            # costs about a second of processor time whatever its size. A lone one waits not.
            deadline = time.monotonic() + BATCH_SECONDS
            while self.queue.busy() and time.monotonic() < deadline and not self.stopping.is_set():
                self.stopping.wait(0.2)
            self.release_once()

    def _retries_due(self) -> bool:
        now = time.monotonic()
        return any(when <= now for when, _tries in self._retry.values())

    def release_once(self) -> None:
        """Release the feedback of the graded rows, one assignment at a time. A row whose feedback
        cannot be written or released fails alone: it is tried again RETRY_SECONDS later, and after
        RELEASE_TRIES tries it is 'failed' with its reason on its student's page; the others go on."""
        now = time.monotonic()
        rows = [r for r in self.queue.waiting_for_feedback() if self._retry.get(r.id, (0.0, 0))[0] <= now]
        for assignment, group in itertools.groupby(sorted(rows, key=lambda r: r.assignment),
                                                   key=lambda r: r.assignment):
            group = list(group)
            try:
                rules = self.rules().get(assignment, config.SubmitRules())
                due = grading_job.duedate(self.course.course_dir, assignment)
                failures = grading_job.release(self.course, assignment, group, grading_job.scores_only(rules, due))
            except Exception:  # noqa: BLE001 - the whole assignment's: each of its rows is tried again
                failures = {row.id: traceback.format_exc() for row in group}
            self.queue.released([r.id for r in group if r.id not in failures])
            for row in group:
                if row.id in failures:
                    self._release_failed(row, failures[row.id])
                else:
                    self._retry.pop(row.id, None)

    def _release_failed(self, row, error: str) -> None:
        tries = self._retry.get(row.id, (0.0, 0))[1] + 1
        _log(f"could not release the feedback of {row.entry!r} (try {tries} of {RELEASE_TRIES}):\n{error}")
        if tries < RELEASE_TRIES:
            self._retry[row.id] = (time.monotonic() + RETRY_SECONDS, tries)
            return
        self._retry.pop(row.id, None)
        self.queue.failed(row.id, "it was graded, but its feedback page could not be written; your instructor has the "
                                  "details.")


def _run_until_stopped(loop) -> None:
    """Run tornado's loop until SIGINT or SIGTERM. The kernel hands a process's signal to any of
    its threads: one that a grading thread took left the main thread asleep in the loop's select,
    and Python's handler (KeyboardInterrupt) ran only when something else woke it, for ever in a
    quiet service (test_work_folders' stop waited 60 s in 1 of 5 runs). asyncio's handlers wake
    the loop through its self-pipe whichever thread takes the signal; afterwards either signal
    raises KeyboardInterrupt again."""
    import signal

    stops = (signal.SIGINT, signal.SIGTERM)
    for number in stops:
        loop.asyncio_loop.add_signal_handler(number, loop.stop)
    try:
        loop.start()
    finally:
        for number in stops:
            loop.asyncio_loop.remove_signal_handler(number)
            signal.signal(number, signal.default_int_handler)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m coursehub.grading_service", description=__doc__.split("\n")[0])
    parser.add_argument("--hub-dir", type=Path, default=Path(os.environ.get(course_settings.HUB_DIR_ENV,
                                                                           course_settings.DEFAULT_HUB_DIR)))
    parser.add_argument("--workers", type=int, help="submissions graded at the same time (default: "
                        f"c.GradeOnSubmit.workers in the course's nbgrader_config.py, else {config.SUBMIT_WORKERS})")
    args = parser.parse_args(argv)
    import signal

    from tornado import ioloop

    from autograder.grading import fork_server, work_folders
    from coursehub import grading_status

    course = course_settings.load(args.hub_dir)
    workers = args.workers
    if workers is None:
        try:
            workers = config.submit_workers(config.load(course.course_dir))
        except ValueError as error:  # the hub would restart a service that stops, again and again
            _log(f"{error} Grading with {config.SUBMIT_WORKERS} worker(s) until it is corrected and the service "
                 "restarted.")
            workers = config.SUBMIT_WORKERS
    service = Service(course, workers=max(1, workers), rules_file=course.submit_rules)
    # The hub stops its services with SIGINT, then SIGTERM: either ends the loop below, also where
    # SIGINT came ignored (a service started with & by a script), as ros2 launch does.
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, signal.default_int_handler)
    # Before the service's threads: the gradings' sandboxed programs are forked from it.
    with fork_server.serving(wait=STOP_SECONDS):
        try:
            service.start()
            prefix = os.environ.get("JUPYTERHUB_SERVICE_PREFIX", f"/{course_settings.GRADING_PAGE}")
            grading_status.application(service.queue, prefix).listen(course.grading_port, "127.0.0.1")
            _log(f"grading {', '.join(service.rules()) or 'nothing yet (c.GradeOnSubmit.assignments)'} on "
                 f"submission with {service.workers} worker(s); status at {prefix} (127.0.0.1:{course.grading_port})")
            _run_until_stopped(ioloop.IOLoop.current())
        except KeyboardInterrupt:  # a signal before the loop ran
            pass
        service.stopping.set()
    # The gradings cut short (queued again at the next start) leave no work folder: the process
    # becomes their remover when its worker threads hold any (autograder.grading.work_folders),
    # after the fork server ended (the remover would not end it).
    work_folders.end_gradings()
    return 0


if __name__ == "__main__":
    sys.exit(main())
