"""The grader's run of a graded notebook's hidden checks, outside the student's kernel:
``python -m autograder.grading.hidden_checks_process ASSIGNMENT CHECK... --workdir DIR --out DIR`` (started by
autograder.grading.hidden_checks).

The checks of a submission share one set of student processes that serve calls
(course_lib.checks.student_server), and, when the grader gave the submission a network namespace
and a ROS domain of its own (autograder.sandbox.namespaces), run at the same time, each in a ROS domain of
its own. ``AUTOGRADER_CHECKS_SECONDS`` bounds the time of all of them together: when it runs out,
the checks that did not finish are recorded as failed with what they were waiting on.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import shutil
import sys
import tempfile
import threading
import time
from pathlib import Path

from autograder import answers
from autograder.sandbox.student_uid import StudentUid
from course_lib import contract
from course_lib.checks.check_process import run_in_this_process, write_json
from course_lib.checks.context import number_from_environment
from course_lib.checks.registry import get_check
from course_lib.checks.result import Result
from course_lib.checks.runner import embed_images, fresh_seed
from course_lib.checks.student_server import StudentServers
from course_lib.ros import type_support_lock

#: Set by the grader: the wall time, in seconds, that all checks of the submission together may use.

#: Seconds of that time kept for writing the verdicts of checks cut short and stopping processes.
MARGIN = 1.0


def budget_from_environment() -> float | None:
    """AUTOGRADER_CHECKS_SECONDS as a number of seconds, or None (no bound but the checks' own)."""
    return number_from_environment(contract.CHECKS_SECONDS_ENV)


def own_domains() -> int | None:
    """The ROS domain the grader reserved for the submission when its checks run in a network
    namespace of their own (autograder.sandbox.namespaces: then every domain is theirs), else None."""
    from course_lib.ros import rosenv

    domain = os.environ.get("ROS_DOMAIN_ID")
    return int(domain) if rosenv.under_grading() and domain and _only_loopback() else None


def _only_loopback() -> bool:
    """True in a network namespace of our own: this process sees no network device but lo."""
    try:
        lines = Path("/proc/net/dev").read_text().splitlines()[2:]
    except OSError:
        return False
    return [line.split(":", 1)[0].strip() for line in lines] == ["lo"]


def run_outside(assignment: str, names: list[str], workdir, out: Path, budget: float | None = None) -> None:
    """The grader's run of a graded notebook's checks: each with a fresh seed and the answer key,
    in this process (one interpreter start-up for all of them; the student's code they call runs
    in processes of its own, bounded in time, as the grader's student uid when it set one:
    autograder.sandbox.student_uid), each result in out/<name>.json.

    Args:
        budget: seconds for all checks together (default AUTOGRADER_CHECKS_SECONDS; None: no bound).
    """
    os.environ[contract.ANSWERS_ENV] = "graded"
    os.environ.update(answers.environment())
    budget = budget if budget is not None else budget_from_environment()
    started = time.monotonic()
    deadline = None if budget is None else started + max(1.0, budget - MARGIN)
    run = _Run(assignment, Path(workdir).resolve(), out, deadline,
               StudentServers(budget or sum(get_check(assignment, name).timeout for name in names)))
    type_support_lock.install()  # the checks run side by side in threads: one imports a type's support
    base = own_domains()
    if base is None:  # one domain: one check at a time
        workers = [threading.Thread(target=lambda: [run.check(name) for name in names], daemon=True)]
    else:
        workers = [threading.Thread(target=run.check, args=(name, *_domains(base, index)), daemon=True)
                   for index, name in enumerate(names)]
    for worker in workers:
        worker.start()
    for worker in workers:
        worker.join(None if deadline is None else max(0.0, deadline - time.monotonic()))
    if deadline is None or all(name in run.finished for name in names):
        run.servers.close()
        return
    run.time_is_up(names, budget)
    from course_lib.ros import processes

    processes.stop_all(timeout=0.5)
    run.servers.close()
    sys.stdout.flush()
    os._exit(0)  # the checks still running are threads of this process: end them with it


def _domains(base: int, index: int) -> tuple[int, int]:
    """The two ROS domains of the index-th check (Context's domain_id and second_domain_id; the
    submission's own namespace has all 233)."""
    return (base + 2 * index) % 233, (base + 2 * index + 1) % 233


class _Run:
    """The checks of one submission: which run, which finished, their results."""

    def __init__(self, assignment: str, workdir: Path, out: Path, deadline: float | None, servers: StudentServers):
        self.assignment, self.workdir, self.out = assignment, workdir, out
        self.deadline, self.servers = deadline, servers
        self.students = StudentUid.from_environment()
        self.lock = threading.Lock()
        self.running: dict[str, tuple] = {}  # name -> (Context, seed)
        self.finished: set[str] = set()

    def check(self, name: str, domain_id: int | None = None, second_domain_id: int | None = None) -> None:
        spec = get_check(self.assignment, name)
        scratch = Path(tempfile.mkdtemp(prefix=f"autograder-{name}-"))
        started, seed = time.monotonic(), fresh_seed()
        try:
            result = run_in_this_process(self.assignment, name, seed, self.workdir, scratch, self.students,
                                         on_start=lambda ctx: self.running.__setitem__(name, (ctx, seed)),
                                         servers=self.servers, deadline=self.deadline, domain_id=domain_id,
                                         second_domain_id=second_domain_id)
            embed_images(result, scratch)
        finally:
            shutil.rmtree(scratch, ignore_errors=True)
        result.points = max(0.0, min(result.points, spec.points))
        result.seconds = round(time.monotonic() - started, 2)
        self._write(name, result)

    def _write(self, name: str, result: Result) -> None:
        with self.lock:
            if name in self.finished:
                return
            self.finished.add(name)
            write_json(self.out / f"{name}.json", dataclasses.asdict(result))

    def time_is_up(self, names: list[str], budget: float) -> None:
        """Record each check that did not finish as failed, saying what it was waiting on; it earns
        nothing (what it found until then is kept in its verdict)."""
        for name in names:
            spec = get_check(self.assignment, name)
            ctx, seed = self.running.get(name, (None, 0))
            if ctx is None:
                reason = f"not run: the grading time of {budget:g} s ran out before this check started"
                items = []
            else:
                reason = f"the grading time of {budget:g} s ran out while {ctx.doing}"
                items = list(ctx.items)
            items.append({"ok": False, "message": reason, "weight": 1.0})
            seconds = round(time.monotonic() - ctx._started, 2) if ctx is not None else 0.0
            self._write(name, Result(self.assignment, name, 0.0, spec.points, seed, items,
                                     list(ctx.notes) if ctx is not None else [], [], reason, seconds))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m autograder.grading.hidden_checks_process",
                                     description="Run the hidden checks of a graded notebook's module (the grader).")
    parser.add_argument("assignment")
    parser.add_argument("checks", nargs="+")
    parser.add_argument("--workdir", required=True)
    parser.add_argument("--out", required=True)
    args = parser.parse_args(argv)
    import cv2

    from course_lib.imaging import frame_memory

    # The checks run side by side in threads and draw their scenes there: OpenCV's own worker
    # threads would only add to the processor time on the cores they already share; and each
    # scene's arrays reuse the memory of the last one's.
    cv2.setNumThreads(1)
    frame_memory.keep_freed_frames()
    run_outside(args.assignment, args.checks, args.workdir, Path(args.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
