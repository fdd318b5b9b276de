"""How long the last student of a deadline burst waits for feedback, for a class and a machine:
a simulation of the grading queue from one grading's measured cost, checked against a burst
graded here (issue #48).

Not a test: it prints what it simulated and measured.

    .venv/bin/python benchmarks/bench_capacity.py [--measure N] [--workers W] [--assignment A]

The model: a grading needs `cpu` processor-seconds and, alone on an idle machine, takes `wall`
seconds (so it keeps at most cpu/wall cores busy); W workers grade at once and share the machine's
cores equally; submissions wait in arrival order (the hub's queue, autograder.submit_queue). With
--measure N it first grades one submission alone (cpu from wait4, wall), then N distinct
submissions arriving together with W workers (``python -m autograder grade --workers W``), and
prints each one's measured finish beside the simulated one; then the table for classes and
machines from the measured cost, every submission of the class arriving at once (the worst burst).
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the grader and tests.support run from the repository, uninstalled


def simulate(arrivals: list[float], cores: float, workers: int, cpu: float, wall: float,
             step: float = 0.05) -> list[float]:
    """When each submission's grading ends (seconds, in arrival order), under the model above."""
    order = sorted(range(len(arrivals)), key=lambda i: arrivals[i])
    waiting, running, finish = list(order), {}, [0.0] * len(arrivals)
    peak = cpu / wall  # the cores one grading keeps busy alone
    now = 0.0
    while waiting or running:
        while waiting and arrivals[waiting[0]] <= now and len(running) < workers:
            running[waiting.pop(0)] = cpu
        if running:
            rate = min(peak, cores / len(running))
            for index in list(running):
                running[index] -= rate * step
                if running[index] <= 1e-9:
                    del running[index]
                    finish[index] = now + step
        now += step
    return finish


def _one(course: Path, student: str, assignment: str, env: dict) -> tuple[float, float]:
    """(processor seconds of the grade command's whole tree, wall seconds) for one submission."""
    started = time.monotonic()
    proc = subprocess.Popen([sys.executable, "-m", "autograder", "grade", str(course), "--assignment", assignment,
                             "--student", student, "--force"], env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    _pid, status, usage = os.wait4(proc.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"grading {student} failed")
    return usage.ru_utime + usage.ru_stime, time.monotonic() - started


def _burst(course: Path, assignment: str, workers: int, env: dict) -> list[float]:
    """Each submission's finish, seconds after the grade command's first grading started."""
    proc = subprocess.run([sys.executable, "-m", "autograder", "grade", str(course), "--assignment", assignment,
                           "--workers", str(workers), "--force"], env=env, capture_output=True, text=True, check=True)
    return sorted(float(seconds) for seconds in re.findall(r"s, (\d+) s elapsed\)", proc.stderr))


def table(cpu: float, wall: float) -> None:
    print(f"\nThe last feedback of a burst (every submission at once), one grading {cpu:.1f} CPU-s / {wall:.1f} s:\n")
    machines = (2, 4, 8, 16, 32, 64)
    print("| students | " + " | ".join(f"{cores} cores" for cores in machines) + " |")
    print("|---:|" + "---:|" * len(machines))
    for students in (30, 100, 200, 400):
        cells = []
        for cores in machines:
            last = max(simulate([0.0] * students, cores, cores, cpu, wall))
            cells.append(f"{last / 60:.1f} min" if last >= 120 else f"{last:.0f} s")
        print(f"| {students} | " + " | ".join(cells) + " |")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--measure", type=int, default=0, help="grade N distinct submissions together (0: no)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--assignment", default="brightness")
    parser.add_argument("--cpu", type=float, help="CPU-s of one grading, when not measured")
    parser.add_argument("--wall", type=float, help="seconds of one grading alone, when not measured")
    args = parser.parse_args(argv)
    cpu, wall = args.cpu, args.wall
    if args.measure:
        from autograder.term import grade, release
        from tests.support import zoo

        env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
        with tempfile.TemporaryDirectory(prefix="bench-capacity-") as scratch:
            course = Path(scratch) / "course"
            release.release(course, [args.assignment])
            for number in range(args.measure):
                def mark(nb, number=number):  # distinct content: a comment in the first file written
                    cell = next(c for c in nb.cells if c.source.startswith("%%writefile"))
                    cell.source += f"\n# submission {number}\n"
                zoo.submit(course, f"student{number}", args.assignment, edits=[mark])
            grade.grade(course, progress=False, force=True)  # warm caches, as a term's service has them
            load = open("/proc/loadavg").read().split()[0]
            cpu, wall = _one(course, "student0", args.assignment, env)
            measured = _burst(course, args.assignment, args.workers, env)
            load_after = open("/proc/loadavg").read().split()[0]
        simulated = sorted(simulate([0.0] * args.measure, os.cpu_count(), args.workers, cpu, wall))
        print(f"{args.assignment}: one grading alone {cpu:.2f} CPU-s, {wall:.1f} s; {args.measure} together with "
              f"{args.workers} workers on {os.cpu_count()} cores (1-min load {load} -> {load_after}):\n")
        print("| submission | measured finish (s) | simulated (s) |\n|---:|---:|---:|")
        for number, (got, model) in enumerate(zip(measured, simulated, strict=False), start=1):
            print(f"| {number} | {got:.0f} | {model:.0f} |")
    if cpu is None or wall is None:
        parser.error("give --measure N, or --cpu and --wall")
    table(cpu, wall)
    return 0


if __name__ == "__main__":
    sys.exit(main())
