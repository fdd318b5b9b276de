"""How long a student waits from Submit to feedback with the hub's grading service: one submission
on an idle service, and --at-once distinct submissions arriving together.

Not a test: the times depend on the machine and on what else runs, so this prints them instead
of asserting them. It releases brightness into a scratch course with grading on submission
(c.GradeOnSubmit), starts the service's threads (coursehub.grading_service.Service: the same
queue, grader and feedback release as on the hub, without the hub), and drops submissions into a
scratch exchange's inbound/ as nbgrader's submit leaves them: the reference solution, each with a
comment of its own in the student's module so that no two have the same content (the service
grades a content once). A submission's wait is from its folder being complete in inbound/ to its
feedback page being in the exchange's feedback/, where Fetch Feedback finds it (a second or two
of the browser's Submit and Fetch Feedback not included).

    sudo .venv/bin/python benchmarks/bench_submit.py [--at-once 30] [--workers 1]

Root grades in the full sandbox, as the hub's service does.
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import secrets
import shutil
import statistics
import sys
import tempfile
import time
import types
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the grader and tests.support run from the repository, uninstalled

import nbformat  # noqa: E402

from autograder.config import COURSE_ID  # noqa: E402
from autograder.term import release  # noqa: E402
from coursehub.grading_service import Service  # noqa: E402
from tests.support import zoo  # noqa: E402 (it builds submissions from the reference solutions)
from tests.support.zoo.brightness import SUM  # noqa: E402

ASSIGNMENT = "brightness"


def drop(inbound: Path, course: Path, student: str, n: int) -> str:
    """A distinct reference submission of `student` in inbound/, as nbgrader's submit leaves it."""
    stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M:%S.%f %Z")
    folder = inbound / f"{student}+{ASSIGNMENT}+{stamp}+{secrets.token_hex(4)}"
    folder.mkdir(parents=True)
    notebook = zoo.edited_notebook(course, ASSIGNMENT, [(SUM, f"{SUM}  # submission {n}")], student)
    nbformat.write(notebook, folder / f"{ASSIGNMENT}.ipynb")
    (folder / "timestamp.txt").write_text(stamp)
    (folder / "submission_secret.txt").write_text(secrets.token_hex(64))
    os.chmod(folder, 0o777)
    return folder.name


def wait_released(service: Service, entries: dict[str, float], timeout: float) -> dict[str, float]:
    """Seconds from each entry's drop to its feedback's release."""
    waited, deadline = {}, time.monotonic() + timeout
    while len(waited) < len(entries):
        for row in service.queue.all():
            if row.entry in entries and row.entry not in waited and row.state in ("released", "failed"):
                waited[row.entry] = time.monotonic() - entries[row.entry]
                if row.state == "failed":
                    print(f"  {row.entry}: failed: {row.message}", file=sys.stderr)
        if time.monotonic() > deadline:
            raise TimeoutError(f"{len(entries) - len(waited)} submissions not graded after {timeout:.0f} s")
        time.sleep(0.1)
    return waited


def processor_seconds() -> float:
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--at-once", type=int, default=30, help="distinct submissions arriving together")
    parser.add_argument("--workers", type=int, default=1, help="the service's workers")
    args = parser.parse_args(argv)
    scratch = Path(tempfile.mkdtemp(prefix="bench-submit-"))
    try:
        course_dir = scratch / "course"
        release.release(course_dir, [ASSIGNMENT])
        with open(course_dir / "nbgrader_config.py", "a") as handle:
            handle.write(f"c.GradeOnSubmit.assignments = {{{ASSIGNMENT!r}: {{}}}}\n")
        inbound = scratch / "exchange" / COURSE_ID / "inbound"
        inbound.mkdir(parents=True)
        import pwd

        course = types.SimpleNamespace(course_dir=course_dir, exchange=scratch / "exchange", course_id=COURSE_ID,
                                       instructor=pwd.getpwuid(os.geteuid()).pw_name)
        service = Service(course, workers=args.workers, poll_seconds=1.0)
        # The benchmark's students are names, not accounts: each folder is this process's (the
        # service takes a submission only from the uid its roster gives the student).
        names = ["first", "idle", *(f"s{n:02d}" for n in range(args.at_once))]
        service.students = lambda: dict.fromkeys(names, os.geteuid())
        service.start()
        rows = []
        for label, student in (("first after start (builds, imports)", "first"), ("one, idle", "idle")):
            cpu, dropped = processor_seconds(), time.monotonic()
            entry = drop(inbound, course_dir, student, len(rows))
            wait = wait_released(service, {entry: dropped}, 600)[entry]
            rows.append((label, f"{wait:.1f} s", f"{processor_seconds() - cpu:.1f}"))
        cpu, entries = processor_seconds(), {}
        for n in range(args.at_once):
            entries[drop(inbound, course_dir, f"s{n:02d}", 100 + n)] = time.monotonic()
        waits = sorted(wait_released(service, entries, 600 + 120 * args.at_once).values())
        spent = processor_seconds() - cpu
        rows.append((f"{args.at_once} at once: first / median / last", " / ".join(
            f"{w:.0f} s" for w in (waits[0], statistics.median(waits), waits[-1])), f"{spent:.0f}"))
        rows.append((f"{args.at_once} at once: per submission", f"{waits[-1] / args.at_once:.1f} s",
                     f"{spent / args.at_once:.1f}"))
        service.stopping.set()
        print(f"\nPython {platform.python_version()}, {os.cpu_count()} cores, load average "
              f"{os.getloadavg()[0]:.1f}, {args.workers} worker(s), {'root' if os.geteuid() == 0 else 'not root'}\n")
        print("| what | Submit to feedback | CPU-s |\n|---|---:|---:|")
        for row in rows:
            print("| " + " | ".join(row) + " |")
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
