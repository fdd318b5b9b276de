"""Where one grading's processor time goes, by program and phase, beside the floor (issue #48).

Not a test: it prints what it measured. It releases every assignment into a scratch course, hands
in each reference solution (tests/support/zoo), grades them once to warm the caches (message packages,
workspace builds), then runs, per assignment, the instructor's command

    python -m autograder grade COURSE --assignment A --student S --force

and after it ``python -m autograder feedback`` for the same submission, and reads the processor
time of every process of each command's tree from /proc 20 times a second: each process's own
utime+stime, last read while it lived or was a zombie. The command's total comes from wait4 (every
descendant it waited for; it matches the machine's busy time in /proc/stat); what the samples
missed (processes that lived less than a period, the last period of the others) is its own row.
The grader's own process is split by thread and phase: its main thread before the first
sandboxed process (imports, course checks), while they run, and after the last (outputs,
gradebook, report, grades.csv); its worker thread (the submission's steps) and the early run's
thread (the workspace build copied from the cache, then waiting for its checks), told apart by the
order they start in. nbgrader's process is split at its kernel's start and end. The floor beside
it: the same kernel launcher running no cell, then the submission's cells alone (nbclient, the
grading's flags), and a process that imports rclpy (and one that also makes a node).

    .venv/bin/python benchmarks/bench_grading_split.py [--assignment A ...] [--period 0.05] [--before DIR]
                                                       [--rounds N] [--zoo ENTRY ...]

With ``--before DIR`` (a checkout of another commit, e.g. ``git worktree add DIR HEAD~3``) every
command also runs with DIR's grader and course_lib (PYTHONPATH=DIR) on the same submissions, the
two alternating per assignment, and each assignment gets a column "A (before)" beside "A": a change
measured side by side in one run. With ``--rounds N`` each column is graded N times (the columns
alternating in every round) and each row shows the median. ``--zoo ENTRY`` also hands in the brightness
zoo's submission ENTRY (tests/support/zoo/brightness.py, e.g. fork_bomb) and grades it as a column
"brightness: ENTRY" of its own (no floor: its cells are the student's, run nowhere but in the sandbox).

Per assignment (and tree) it prints CPU-seconds per row (rows that are 0 everywhere are left out), what the
samples saw, the command's wait4 total, the machine's busy time meanwhile, the wall time and the
load average before and after, then the floor.
"""

from __future__ import annotations

import argparse
import collections
import csv
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the grader and tests.support run from the repository, uninstalled

from bench_suite_cpu import TICKS, _program  # noqa: E402

from autograder.grading import fork_server  # noqa: E402
from autograder.sandbox import namespaces  # noqa: E402
from autograder.term import grade, release  # noqa: E402
from course_lib import contract  # noqa: E402
from course_lib.checks import assignments  # noqa: E402
from course_lib.supervision import process_tree  # noqa: E402
from tests.support import zoo  # noqa: E402 (it builds submissions from the reference solutions)
from tests.support.zoo import brightness as brightness_zoo  # noqa: E402

ASSIGNMENTS = list(assignments.ASSIGNMENTS)
GRADER = "grader main thread"
KERNEL, CHILDREN = "kernel: start + cells", "cells' child processes"
COLCON = "colcon build, or the copied build's setup scripts"
SUPERVISORS = "supervisors (one per sandboxed command and per node)"
NOTEBOOK, CHECKS = fork_server.NOTEBOOK_RUN, fork_server.CHECKS_RUN
AUTOGRADE = "nbgrader's autograde (its own Python, or forked from the fork server)"
FORK_SERVER = "fork server: its imports, once, and a handler per run (autograder.grading.fork_server)"
NOT_SAMPLED = "not sampled (short-lived processes, tails after the last sample, tick rounding)"
THREADS = ("grader, its worker thread (the steps: staging, reading scores, outputs, the result's gradebook)",
           "grader, the early run's thread (the build copied from the cache, then waiting for the checks)",
           "grader, its other threads and those that ended")
ROWS = [f"{GRADER}: start (imports, course checks)", f"{GRADER}: while sandboxed processes run",
        f"{GRADER}: after (outputs, gradebook, report, grades.csv)", *THREADS,
        "sandbox entry (unshare, outer + pid-1 init)", FORK_SERVER, f"{AUTOGRADE}: start (until its kernel starts)",
        f"{AUTOGRADE}: while the kernel runs", f"{AUTOGRADE}: after (gradebook, graded notebook)",
        KERNEL, CHILDREN, COLCON, "checks process", SUPERVISORS, NOT_SAMPLED]
BUSY = "the machine's busy CPU-s meanwhile (every process, the sampler's own included)"
FEEDBACK = "feedback command (python -m autograder feedback), whole tree"


def _thread_ticks(pid: int) -> dict[int, int]:
    """{thread id: its utime + stime} of the live threads of process `pid`."""
    ticks = {}
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{tid}/stat") as handle:
                fields = handle.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        ticks[int(tid)] = int(fields[11]) + int(fields[12])
    return ticks


def _own_ticks(fields: list[str]) -> int:
    return int(fields[11]) + int(fields[12])


class TreeSampler:
    """Processor ticks of a process tree by row (see the module docstring)."""

    def __init__(self, root: int):
        self.root = root
        self.known = {}    # (pid, start) -> [row, own ticks counted, parent key]
        self.rows = collections.Counter()
        self.main_counted = 0
        self.seen_child = self.kernel_seen = self.kernel_alive = self.sandbox_alive = False
        self.sandbox_seen = False
        self.threads = {}  # thread id -> [row, ticks counted]

    def _row(self, pid: int, parent_row: str | None) -> str:
        name = _program(pid)
        if parent_row in (KERNEL, CHILDREN):
            return CHILDREN
        if parent_row == COLCON or name.endswith(("colcon", "_local_setup_util_sh.py")):
            return COLCON
        if name in ("unshare", "python sandbox_entry.py"):
            return "sandbox entry (unshare, outer + pid-1 init)"
        if name in ("python -m nbgrader", f"python -m {NOTEBOOK}", fork_server.run_name(NOTEBOOK)):
            return "nbgrader"
        if name in ("fork-server", "fork-handler"):
            return FORK_SERVER
        if name == "python -m autograder.sandbox.kernel" or (name.startswith("python -c") and
                                                     "ipykernel" in " ".join(process_tree.command_line(pid))):
            return KERNEL
        if name in (f"python -m {CHECKS}", fork_server.run_name(CHECKS)):
            return "checks process"
        if name == "python supervisor.py":
            return SUPERVISORS
        if parent_row in ("checks process", SUPERVISORS) or name.startswith("python"):
            return f"node process: {name.removeprefix('python ')}"
        return f"other: {name}"

    def _add(self, row: str, ticks: int) -> None:
        if row == "nbgrader":
            row = (f"{AUTOGRADE}: start (until its kernel starts)" if not self.kernel_seen else
                   f"{AUTOGRADE}: while the kernel runs" if self.kernel_alive else
                   f"{AUTOGRADE}: after (gradebook, graded notebook)")
        self.rows[row] += ticks

    def sample(self) -> None:
        stats = {}
        for entry in os.listdir("/proc"):
            if entry.isdigit():
                try:
                    stats[int(entry)] = process_tree.stat_fields(int(entry))
                except (OSError, IndexError):
                    pass
        keys = {pid: (pid, int(f[19])) for pid, f in stats.items()}
        alive = set(keys.values())
        self._end(alive)
        for pid, fields in sorted(stats.items(), key=lambda item: int(item[1][19])):  # parents first
            key, parent = keys[pid], keys.get(int(fields[1]))
            if key not in self.known:
                if pid != self.root and parent not in self.known:
                    continue
                row = GRADER if pid == self.root else self._row(pid, self.known[parent][0])
                self.known[key] = [row, 0, parent]
                self.seen_child |= pid != self.root
            entry = self.known[key]
            entry[2] = parent if parent in self.known else entry[2]
            if entry[0] != GRADER and process_tree.command_line(pid):  # a zombie has none
                row = self._row(pid, self.known[entry[2]][0] if entry[2] in self.known else None)
                if row != entry[0] and entry[0] not in (COLCON, CHILDREN):
                    entry[0] = row  # it exec'd another program (unshare, sandbox_entry's COMMAND)
        rows = {entry[0] for key, entry in self.known.items() if key in alive}
        self.kernel_alive = KERNEL in rows
        self.kernel_seen |= self.kernel_alive
        self.sandbox_alive = bool(rows - {GRADER})
        self.sandbox_seen |= self.sandbox_alive
        for pid, fields in stats.items():
            entry = self.known.get(keys[pid])
            if entry is None:
                continue
            ticks = _own_ticks(fields)
            delta, entry[1] = ticks - entry[1], ticks
            if pid == self.root:
                self._grader(delta)
            elif delta > 0:
                self._add(entry[0], delta)

    def _grader(self, delta: int) -> None:
        """The grader's process: its main thread by phase, its other threads by the order they
        started in (autograder.term.grade's worker, then autograder.grading.early_checks' thread), and the
        time of threads that ended since the last sample."""
        try:
            threads = _thread_ticks(self.root)
        except OSError:
            threads = {}
        main = threads.pop(self.root, self.main_counted)
        main_delta, self.main_counted = main - self.main_counted, main
        for tid, ticks in sorted(threads.items()):
            if tid not in self.threads:
                self.threads[tid] = [THREADS[min(len(self.threads), len(THREADS) - 1)], 0]
            row, counted = self.threads[tid]
            self.rows[row] += ticks - counted
            self.threads[tid][1] = ticks
            delta -= ticks - counted
        phase = ("start (imports, course checks)" if not self.seen_child else
                 "while sandboxed processes run" if self.sandbox_alive or not self.sandbox_seen else
                 "after (outputs, gradebook, report, grades.csv)")
        self.rows[f"{GRADER}: {phase}"] += main_delta
        self.rows[THREADS[-1]] += delta - main_delta

    def _end(self, alive: set) -> None:
        """Forget the processes that ended (their own time was read while they lived or were zombies;
        what ran after the last sample shows in run_sampled's "not sampled")."""
        for key in [key for key in self.known if key not in alive]:
            del self.known[key]


def _busy_ticks() -> int:
    """The machine's busy processor ticks so far (/proc/stat: all but idle and iowait)."""
    with open("/proc/stat") as handle:
        values = [int(v) for v in handle.readline().split()[1:]]
    return sum(values) - values[3] - values[4]


def run_sampled(command: list[str], env: dict, period: float, cwd=None) -> tuple[collections.Counter, float, float]:
    """Run `command`, sampling its tree; (seconds per row, wait4 total, wall)."""
    started, busy = time.monotonic(), _busy_ticks()
    proc = subprocess.Popen(command, env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    sampler = TreeSampler(proc.pid)
    while True:
        sampler.sample()
        pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
        if pid:
            break
        time.sleep(period)
    wall = time.monotonic() - started
    rows_busy = (_busy_ticks() - busy) / TICKS
    error = proc.stderr.read().decode(errors="replace")
    proc.stderr.close()
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise RuntimeError(f"{command[:4]} ended with {proc.returncode}:\n{error[-2000:]}")
    total = usage.ru_utime + usage.ru_stime
    rows = collections.Counter({row: ticks / TICKS for row, ticks in sampler.rows.items()})
    rows[NOT_SAMPLED] = max(0.0, total - sum(rows.values()))
    rows[BUSY] = rows_busy
    return rows, total, wall


FLOOR_DRIVER = """
import sys, nbformat, nbclient
nb = nbformat.read(sys.argv[1], 4) if sys.argv[1] != '-' else nbformat.v4.new_notebook()
nb.metadata['kernelspec'] = {'name': 'python3', 'display_name': 'Python 3', 'language': 'python'}
nbclient.NotebookClient(nb, kernel_name='python3', timeout=120, allow_errors=True,
                        resources={'metadata': {'path': sys.argv[2]}}).execute()
"""
NODE_FLOOR = ("import rclpy; rclpy.init(); node = rclpy.create_node('floor'); node.destroy_node(); "
              "rclpy.try_shutdown()")


def floor(course: Path, assignment: str, scratch: Path, env: dict, period: float, name: str = "") -> dict:
    """The floor's rows: the grading's kernel launcher running no cell, then the submission's cells
    (nbclient in a process of its own, the grading's flags, in a copy of the submitted folder)."""
    work = scratch / f"floor-{name or assignment}"
    subprocess.run(["cp", "-a", str(course / "submitted" / "student0" / assignment), str(work)], check=True)
    notebook = work / f"{assignment}.ipynb"
    kernels = scratch / "jupyter" / "kernels" / "python3"
    kernels.mkdir(parents=True, exist_ok=True)
    (kernels / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "autograder.sandbox.kernel", "{connection_file}"], "language": "python",
        "display_name": "Python 3 (the grader's launcher)"}))
    env = {**env, "JUPYTER_PATH": str(scratch / "jupyter"), "COURSE_LIB_GRADING": "1",
           contract.CHECKS_OUTSIDE_ENV: "1"}
    env.pop("COURSE_LIB_UNDER_TEST", None)
    rows = {}
    for name, path in (("empty", "-"), ("cells", str(notebook))):
        split, total, wall = run_sampled([sys.executable, "-c", FLOOR_DRIVER, path, str(work)], env, period, cwd=work)
        rows[name] = (split, total, wall)
    return rows


def load() -> str:
    return open("/proc/loadavg").read().split()[0]


def _score(course: Path, assignment: str, student: str = "student0") -> str:
    """The student's score of `assignment` in the course's grades.csv (written by every grade command)."""
    with open(course / "grades.csv", newline="") as handle:
        for row in csv.DictReader(handle):
            if row["assignment"] == assignment and row["student_id"] == student:
                return f"{float(row['raw_score']):g}/{float(row['max_score']):g}"
    return "?"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--assignment", action="append", choices=ASSIGNMENTS, help="default: all")
    parser.add_argument("--period", type=float, default=0.05, help="seconds between samples of /proc")
    parser.add_argument("--before", type=Path, help="a checkout of another commit, measured beside this one")
    parser.add_argument("--rounds", type=int, default=1, help="gradings per column; each row shows their median")
    parser.add_argument("--zoo", action="append", default=[], help="a brightness zoo entry graded beside them")
    args = parser.parse_args(argv)
    chosen = args.assignment or ASSIGNMENTS
    # (column, assignment, student): the references, then the zoo's entries
    subjects = [(a, a, "student0") for a in chosen] + [(f"brightness: {e}", "brightness", e) for e in args.zoo]
    trees = {"": ROOT, **({" (before)": args.before.resolve()} if args.before else {})}
    envs = {}
    for suffix, tree in trees.items():
        envs[suffix] = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tree), os.environ.get("PYTHONPATH", "")])}
        envs[suffix].pop("COURSE_LIB_UNDER_TEST", None)
    env = envs[""]
    runs, floors, loads, scores = collections.defaultdict(list), {}, {}, {}
    cli = [sys.executable, "-m", "autograder"]
    with tempfile.TemporaryDirectory(prefix="bench-grading-split-") as scratch:
        course = Path(scratch) / "course"
        release.release(course, sorted({assignment for _, assignment, _ in subjects}))
        zoo_entries = brightness_zoo.entries(str(course))
        for _, assignment, student in subjects:
            zoo.submit(course, student, assignment, zoo_entries[student]["edits"] if student in args.zoo else ())
        grade.grade(course, progress=False, force=True)  # the caches every grading below reuses
        for suffix in trees:  # the other tree's caches, if its builds key them otherwise
            if suffix:
                subprocess.run([*cli, "grade", str(course), "--force"], env=envs[suffix], check=True,
                               stdout=subprocess.DEVNULL, cwd=trees[suffix])
        for _ in range(args.rounds):
            for label, assignment, student in subjects:
                for suffix in sorted(trees, reverse=True):  # the other tree first, then this one
                    # In the tree's own folder: `python -m` puts the working folder before PYTHONPATH.
                    column, env, tree = label + suffix, envs[suffix], trees[suffix]
                    before = load()
                    split, total, wall = run_sampled([*cli, "grade", str(course), "--assignment", assignment,
                                                      "--student", student, "--force"], env, args.period, tree)
                    scores[column] = scores.get(column, set()) | {_score(course, assignment, student)}
                    feedback, feedback_total, _ = run_sampled([*cli, "feedback", str(course), "--assignment",
                                                               assignment, "--student", student], env, args.period,
                                                              tree)
                    split[FEEDBACK] = feedback_total
                    runs[column].append((split, total, wall, feedback_total))
                    if column not in floors and student == "student0":
                        floors[column] = floor(course, assignment, Path(scratch), env, args.period, column)
                    loads[column] = loads.get(column, f"{before} → ").split("→")[0] + f"→ {load()}"
        nodes = {name: run_sampled([sys.executable, "-c", code], env, args.period)[1]
                 for name, code in (("import rclpy", "import rclpy"), ("rclpy: init, a node, shutdown", NODE_FLOOR))}
    columns = [label + suffix for label, _, _ in subjects for suffix in sorted(trees, reverse=True)]
    measured = {column: _median(runs[column]) for column in columns}
    scores = {column: ", ".join(sorted(found)) for column, found in scores.items()}
    report(columns, measured, floors, nodes, scores, loads)
    if args.rounds > 1:
        print(f"\neach row: the median of {args.rounds} rounds (so the rows need not add up to the total's median)")
    if args.before:
        print(f"\n(before): {args.before.resolve()}; without: {ROOT}")
    return 0


def _median(runs: list[tuple]) -> tuple:
    """(split, total, wall, feedback total) of several gradings: the median of each row and number."""
    rows = {row for split, *_ in runs for row in split}
    split = collections.Counter({row: statistics.median(run[0].get(row, 0.0) for run in runs) for row in rows})
    return (split, *(statistics.median(run[index] for run in runs) for index in (1, 2, 3)))


def _driver(split: dict) -> float:
    """The floor's driver process (the sampled tree's root, rows of the grader's process)."""
    return sum(seconds for row, seconds in split.items() if row.startswith("grader"))


def report(chosen, measured, floors, nodes, scores, loads) -> None:
    print(f"{platform.node()}: Python {platform.python_version()}, {os.cpu_count()} cores, isolation "
          f"{namespaces.isolation()}; CPU-seconds sampled from /proc (each process's own utime+stime)\n")
    rows = [r for r in ROWS if any(measured[a][0].get(r, 0) for a in chosen)]
    rows += sorted({r for a in chosen for r in measured[a][0] if r not in ROWS and r not in (FEEDBACK, BUSY)})
    print("| CPU-s | " + " | ".join(chosen) + " |\n|---|" + "---:|" * len(chosen))
    for row in [*rows, FEEDBACK]:
        print(f"| {row} | " + " | ".join(f"{measured[a][0].get(row, 0):.2f}" for a in chosen) + " |")
    lines = {"**grade command, wait4 total**": [f"**{measured[a][1]:.2f}**" for a in chosen],
             "seen by the samples (grade command)": [
                 f"{sum(v for r, v in measured[a][0].items() if r not in (FEEDBACK, BUSY, NOT_SAMPLED)):.2f}"
                 for a in chosen],
             "grade + feedback": [f"{measured[a][1] + measured[a][3]:.2f}" for a in chosen],
             BUSY: [f"{measured[a][0][BUSY]:.2f}" for a in chosen],
             "wall time of the grade command (s)": [f"{measured[a][2]:.1f}" for a in chosen],
             "1-min load average, before → after": [loads[a] for a in chosen],
             "score": [scores.get(a, "?") for a in chosen]}
    for title, run in (("no cell", "empty"), ("the submission's cells", "cells")):
        lines[f"floor, {title}: kernel (the grader's launcher)"] = [
            f"{floors[a][run][0][KERNEL]:.2f}" if a in floors else "" for a in chosen]
        lines[f"floor, {title}: the cells' child processes"] = [
            f"{floors[a][run][0][CHILDREN]:.2f}" if a in floors else "" for a in chosen]
        lines[f"floor, {title}: nbclient driver process"] = [
            f"{_driver(floors[a][run][0]):.2f}" if a in floors else "" for a in chosen]
    for row, cells in lines.items():
        print(f"| {row} | " + " | ".join(cells) + " |")
    print("\nfloor, one process each: " + ", ".join(f"{name} {seconds:.2f} CPU-s" for name, seconds in nodes.items()))


if __name__ == "__main__":
    sys.exit(main())
