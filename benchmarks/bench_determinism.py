"""Whether the autograder gives every submission the same score on an idle machine and on a busy
one, round after round, and how long each grading takes under both loads.

Not a test: it takes minutes and loads the machine. It releases the assignments into a scratch
course, hands in a fixed set of submissions (the reference solutions and zoo edits of them: slow,
half-answering, stuck at import, looping or sleeping in crop_pictures; pillar's typical mistakes,
tests/zoo/pillar.py, and a pillar node that goes silent, which drive the simulated robot in
lock-step), grades the reference of each
chosen submission's assignment once to build and keep its packages (not counted), then grades
every submission again --rounds times on the idle machine and --rounds times with two
CPU-burning processes per core beside the grader (started here, killed at the end, also on Ctrl-C
or an error).

    .venv/bin/python benchmarks/bench_determinism.py [--rounds 2] [--only NAME ...] [--workers 1]

It prints each submission's score in every round, idle and loaded, and whether they are all the
same; then the seconds of each grading, the 1-minute load average at the start and end of each
round, and the worst case (the slowest submission) idle and loaded. Exit status 0 when every
submission got the same score in every round, 1 otherwise.
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the grader and tests.support run from the repository, uninstalled

from autograder.sandbox import namespaces  # noqa: E402
from autograder.term import grade, release  # noqa: E402
from course_lib.checks import assignments  # noqa: E402
from tests.support import zoo  # noqa: E402 (it builds submissions from the reference solutions)
from tests.support.zoo.brightness import CALLBACK  # noqa: E402
from tests.support.zoo.brightness import entries as brightness_entries  # noqa: E402
from tests.support.zoo.pillar import entries as pillar_entries  # noqa: E402

ASSIGNMENTS = list(assignments.ASSIGNMENTS)
#: The first statement of crop_pictures in the catdog_warp reference (readmarker/crop.py).
CROP_START = "    frame = _check_frame(frame_bgr)\n"
#: A pillar node that stops answering after 2 simulated seconds: the lock-step drive ends at the
#: wall-clock backstop (course_lib.checks.lock_step), and the score must not depend on the load.
GOES_SILENT = ("        self.cmd_pub.publish(twist)\n",
               "        if scan.header.stamp.sec < 2:\n            self.cmd_pub.publish(twist)\n")
EVERY_OTHER = ("        self.n = getattr(self, 'n', 0) + 1\n        if self.n % 2 == 0:\n"
               + CALLBACK.replace("        ", "            ", 1))


def submissions(course: Path) -> dict[str, tuple[str, list]]:
    """name -> (assignment, zoo edits of its reference solution)."""
    zoo_edits = {name: entry["edits"] for name, entry in brightness_entries(str(course)).items()}
    return {
        "brightness_reference": ("brightness", []),
        "pubsub_reference": ("pubsub", []),
        "catdog_warp_reference": ("catdog_warp", []),
        "python_loop": ("brightness", zoo_edits["python_loop"]),
        "slow_callback": ("brightness", zoo_edits["slow_callback"]),
        "every_other_frame": ("brightness", [(CALLBACK, EVERY_OTHER)]),
        "import_loop": ("brightness", zoo_edits["import_loop"]),
        "crop_never_returns": ("catdog_warp", [(CROP_START, "    while True:\n        pass\n" + CROP_START)]),
        "crop_sleeps": ("catdog_warp", [(CROP_START, "    import time; time.sleep(10**6)\n" + CROP_START)]),
        "pillar_reference": ("pillar", []),
        "pillar_goes_silent": ("pillar", [GOES_SILENT]),
        **{name: ("pillar", entry["edits"]) for name, entry in pillar_entries(str(course)).items() if entry["edits"]},
    }


def graded_round(course: Path, names: list[str], workers: int) -> dict:
    """Grade everything again: name -> (score, max score, seconds), and the load averages around it."""
    load_before = os.getloadavg()[0]
    results = grade.grade(course, workers=workers, force=True, progress=False)
    rows = {r.student: (r.score, r.max_score, r.seconds, r.steps) for r in results if r.student in names}
    return {"rows": rows, "load": (load_before, os.getloadavg()[0])}


def start_hogs(count: int) -> list[subprocess.Popen]:
    return [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(count)]


def stop_hogs(hogs: list[subprocess.Popen]) -> None:
    for hog in hogs:
        hog.kill()
    for hog in hogs:
        hog.wait()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rounds", type=int, default=2, help="rounds idle and rounds loaded (default 2)")
    parser.add_argument("--only", nargs="+", metavar="NAME", help="grade only these submissions")
    parser.add_argument("--workers", type=int, default=1, help="grading workers (default 1)")
    argv = sys.argv[1:] if argv is None else argv
    args = parser.parse_args(argv)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(1))  # so that the finally clauses run
    hog_count = 2 * os.cpu_count()
    rounds = {"idle": [], "loaded": []}
    with tempfile.TemporaryDirectory(prefix="bench-determinism-") as scratch:
        course = Path(scratch) / "course"
        release.release(course, ASSIGNMENTS)
        chosen = submissions(course)
        unknown = sorted(set(args.only or []) - set(chosen))
        if unknown:
            parser.error(f"no submission named {', '.join(unknown)}; the names: {', '.join(chosen)}")
        chosen = {name: chosen[name] for name in args.only or chosen}
        for assignment in sorted({assignment for assignment, _ in chosen.values()}):  # the builds every round reuses
            zoo.submit(course, "warmup", assignment)
        grade.grade(course, student="warmup", progress=False)
        shutil.rmtree(course / "submitted" / "warmup")
        for name, (assignment, edits) in chosen.items():
            zoo.submit(course, name, assignment, edits)
        names = list(chosen)
        for _ in range(args.rounds):
            rounds["idle"].append(graded_round(course, names, args.workers))
        hogs = start_hogs(hog_count)
        try:
            for _ in range(args.rounds):
                rounds["loaded"].append(graded_round(course, names, args.workers))
        finally:
            stop_hogs(hogs)
    return report(args, argv, names, rounds, hog_count)


def report(args, argv: list[str], names: list[str], rounds: dict, hog_count: int) -> int:
    print(f"Command: `{' '.join(['.venv/bin/python benchmarks/bench_determinism.py', *argv])}`")
    print(f"Python {platform.python_version()}, {platform.machine()}, {os.cpu_count()} cores, isolation "
          f"{namespaces.isolation()}, {args.workers} worker(s); loaded: {hog_count} busy processes beside the grader\n")
    columns = [(load, index) for load in ("idle", "loaded") for index in range(args.rounds)]
    header = "".join(f" {load} {index + 1} |" for load, index in columns)
    rule = "---:|" * len(columns)
    print(f"| submission |{header} scores |\n|---|{rule}---|")
    all_same = True
    for name in names:
        scores = [rounds[load][index]["rows"][name][:2] for load, index in columns]
        same = len(set(scores)) == 1
        all_same &= same
        cells = "".join(f" {score:g}/{most:g} |" for score, most in scores)
        print(f"| {name} |{cells} {'same' if same else 'DIFFERS'} |")
    print(f"\nseconds per grading\n\n| submission |{header}\n|---|{rule}")
    for name in names:
        print(f"| {name} |" + "".join(f" {rounds[load][index]['rows'][name][2]:.1f} |" for load, index in columns))
    loads = "".join(f" {rounds[load][index]['load'][0]:.1f} → {rounds[load][index]['load'][1]:.1f} |"
                    for load, index in columns)
    print(f"| 1-min load average, start → end |{loads}")
    for load in ("idle", "loaded"):
        worst = max((r["rows"][name][2], name) for r in rounds[load] for name in names)
        steps = next(r["rows"][worst[1]][3] for r in rounds[load] if r["rows"][worst[1]][2] == worst[0])
        shown = ", ".join(f"{step} {seconds:.1f}" for step, seconds in steps.items() if seconds >= 0.5)
        print(f"\nworst case {load}: {worst[0]:.1f} s ({worst[1]}; steps in s: {shown})", end="")
    print(f"\n\nevery score identical across all rounds and both loads: {'yes' if all_same else 'NO'}")
    return 0 if all_same else 1


if __name__ == "__main__":
    sys.exit(main())
