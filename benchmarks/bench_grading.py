"""How long the autograder takes per submission, cold and with the builds kept, before and after
the early build and checks, and what a second worker buys, in one run.

Not a test: the times depend on the machine and on what else runs, so this prints them instead
of asserting them. It releases the three assignments into a scratch course, hands in the
reference solution of each for --students students, then grades the whole class five times with
the real nbgrader CLI, everything graded again each time: with one worker and nothing kept (cold:
each assignment's first submission builds its message package and its workspace); with one
worker, the message packages kept, every workspace built by colcon and the steps one after another
(AUTOGRADER_EARLY_CHECKS=0 and AUTOGRADER_REUSE_BUILDS=0: "sequential", the grader before
autograder.grading.early_checks); the same with the build and checks overlapping the notebook's run
("built"); the same with the build of an identical workspace copied ("early", the default: a class
whose package.xml, setup.py and setup.cfg are the release's builds once); and with --workers
workers.

    .venv/bin/python benchmarks/bench_grading.py [--students 2] [--workers 2]

Per assignment it prints the seconds per submission: the first submission of the cold run, and
the mean of each run; then the mean seconds of each pipeline step in the three cached one-worker
runs (GradeResult.steps: nbgrader's notebook run, the early build and checks beside it, the colcon
build of the workspace and the grader's own run of the hidden checks after it, and the rest),
then the wall time of each run, the ratios of the sequential run to the early ones, and the
ratio of the two early runs, which is the speed-up of the extra workers on this machine.
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the grader and tests.support run from the repository, uninstalled

from autograder.builds import caches  # noqa: E402
from autograder.grading import pipeline  # noqa: E402
from autograder.sandbox import namespaces  # noqa: E402
from autograder.term import grade, release  # noqa: E402
from course_lib import contract  # noqa: E402
from course_lib.checks import assignments  # noqa: E402
from tests.support import zoo  # noqa: E402 (it builds submissions from the reference solutions)

ASSIGNMENTS = list(assignments.ASSIGNMENTS)
#: The steps shown on their own (autograder.grading.pipeline.STEPS); the others are summed as "other".
SHOWN_STEPS = ["run_notebook", "early_build_and_checks", "build_workspace", "run_hidden_checks"]


def timed_grade(course: Path, workers: int, early: bool = True, reuse: bool = True) -> tuple[float, list]:
    os.environ[contract.EARLY_CHECKS_ENV] = "1" if early else "0"
    os.environ[contract.REUSE_BUILDS_ENV] = "1" if reuse else "0"
    started = time.monotonic()
    results = grade.grade(course, workers=workers, force=True, progress=False)
    return time.monotonic() - started, results


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--students", type=int, default=2, help="reference submissions per assignment")
    parser.add_argument("--workers", type=int, default=2, help="workers of the second run")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="bench-grading-") as scratch:
        course = Path(scratch) / "course"
        release.release(course, ASSIGNMENTS)
        for index in range(args.students):
            for assignment in ASSIGNMENTS:
                zoo.submit(course, f"student{index}", assignment)
        shutil.rmtree(caches.cache_of(course).root, ignore_errors=True)
        shutil.rmtree(caches.builds_of(course).root, ignore_errors=True)
        runs = {"cold": timed_grade(course, 1), "sequential": timed_grade(course, 1, early=False, reuse=False),
                "built": timed_grade(course, 1, reuse=False), "early": timed_grade(course, 1),
                "workers": timed_grade(course, args.workers)}
    print(f"{platform.node()}: {os.cpu_count()} CPUs, isolation {namespaces.isolation()}, "
          f"{args.students} reference submissions per assignment\n")
    columns = {"cold": "mean, cold", "sequential": "cached, sequential", "built": "cached, early, built",
               "early": "cached, early", "workers": f"early, {args.workers} workers"}
    print(f"{'assignment':<14}{'first, cold':>12}" + "".join(f"{title:>21}" for title in columns.values())
          + f"{'scores':>12}")
    for assignment in ASSIGNMENTS:
        cells = [f"{[r.seconds for r in runs['cold'][1] if r.assignment == assignment][0]:.1f}"]
        for run in columns:
            seconds = [r.seconds for r in runs[run][1] if r.assignment == assignment]
            cells.append(f"{statistics.mean(seconds):.1f}")
        scores = {f"{r.score:g}/{r.max_score:g}" for _, results in runs.values() for r in results
                  if r.assignment == assignment}
        print(f"{assignment:<14}{cells[0]:>12}" + "".join(f"{cell:>21}" for cell in cells[1:])
              + f"{','.join(sorted(scores)):>12}")
    early_used = sum(bool(r.checked_early) for r in runs["early"][1])
    print(f"\nthe early build and checks counted for {early_used} of {len(runs['early'][1])} submissions")
    reused = {run: sum(r.build_reused for r in runs[run][1]) for run in ("built", "early")}
    print(f"workspace builds copied from an identical one: {reused['built']} of {len(runs['built'][1])} in the "
          f"built run ({contract.REUSE_BUILDS_ENV}=0), {reused['early']} of {len(runs['early'][1])} in the early run")
    print(f"\nseconds per step, mean of the cached runs with 1 worker (budget {pipeline.GRADING_SECONDS:g} s idle, "
          f"per submission):")
    print(f"{'assignment':<14}{'run':<12}" + "".join(f"{name:>23}" for name in [*SHOWN_STEPS, "other"]))
    for assignment in ASSIGNMENTS:
        for run in ("sequential", "built", "early"):
            results = [r for r in runs[run][1] if r.assignment == assignment]
            means = [statistics.mean(r.steps.get(name, 0.0) for r in results) for name in SHOWN_STEPS]
            other = statistics.mean(sum(v for k, v in r.steps.items() if k not in SHOWN_STEPS) for r in results)
            print(f"{assignment:<14}{run:<12}" + "".join(f"{value:>23.1f}" for value in [*means, other]))
    before, built, one, many = runs["sequential"][0], runs["built"][0], runs["early"][0], runs["workers"][0]
    print(f"\nwall time: {runs['cold'][0]:.0f} s cold, {before:.0f} s cached sequential, {built:.0f} s cached early "
          f"built by colcon, {one:.0f} s cached early (1 worker): {before / built:.2f}x, {before / one:.2f}x")
    count = len(runs["early"][1])
    print(f"\n{count} submissions: {one:.0f} s with 1 worker, {many:.0f} s with {args.workers} workers: "
          f"speed-up {one / many:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
