"""Where the test suite's processor time goes: per test file, per test and per program.

Not a test: it runs pytest (by default as `make test` does) and reads every process's processor
time from /proc twice a second. A process counts for the xdist worker it descends from, and its
time for the test that worker runs at that moment (this file is also the pytest plugin that says
which test that is). The time of a child that ended counts too: the kernel adds it to its
parent's (utime+stime of the children it waited for), and what the sampler had counted of the
child already is taken off again. The suite is CPU-bound on 2 cores (its wall time is about half
its processor time), so this is the list of what to make cheaper.

    .venv/bin/python benchmarks/bench_suite_cpu.py [--top 25] [-- PYTEST_ARGS ...]

With PYTEST_ARGS it runs `pytest PYTEST_ARGS` instead (say `-n 0 tests/course_lib/launch/test_launch.py`). It prints
the machine's processor time during the run, the part it could attribute to the suite's processes,
and the largest shares by test file, by test and by program (python by its module or script,
chromium by its process type). Exit status: pytest's.
"""

from __future__ import annotations

import argparse
import collections
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from course_lib.supervision import process_tree  # noqa: E402

#: The folder in which the plugin writes, per worker process (file name: its pid), the test it runs.
CURRENT_ENV = "BENCH_SUITE_CPU_DIR"
BETWEEN = "(between tests)"
REPO = Path(__file__).resolve().parent.parent
MAKE_TEST_ARGS = ["-n", "4", "--dist", "loadfile", "--no-loadscope-reorder"]
PERIOD = 0.5
TICKS = os.sysconf("SC_CLK_TCK")


# --- the pytest plugin (pytest -p bench_suite_cpu) ---------------------------------------------

def _say_current(test: str) -> None:
    folder = os.environ.get(CURRENT_ENV)
    if folder:
        scratch = Path(folder) / f"{os.getpid()}.new"
        scratch.write_text(test)
        scratch.replace(scratch.with_suffix(""))


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    """Runs where the test runs (an xdist worker, or pytest itself with -n 0)."""
    _say_current(item.nodeid)
    yield
    _say_current(BETWEEN)


# --- the sampler -------------------------------------------------------------------------------

def _stat(pid: int) -> tuple[int, int, int]:
    """(parent pid, processor ticks with those of the children it waited for, start time)."""
    fields = process_tree.stat_fields(pid)
    return int(fields[1]), sum(int(v) for v in fields[11:15]), int(fields[19])


def _busy_ticks() -> int:
    with open("/proc/stat") as handle:
        values = [int(v) for v in handle.readline().split()[1:]]
    return sum(values) - values[3] - values[4]  # all but idle and iowait


def _program(pid: int) -> str:
    """What a process is: python by its module (-m) or script, chromium by its --type."""
    try:
        with open(f"/proc/{pid}/comm") as handle:
            name = handle.read().strip()
    except OSError:
        return "(gone)"
    argv = process_tree.command_line(pid)
    if name.startswith("python"):
        for flag, value in zip(argv, argv[1:], strict=False):
            if flag == "-m":
                return f"python -m {value}"
            if flag == "-c":
                entry = value.split("sys.argv[0] = '", 1)[-1].split("'", 1)[0] if "sys.argv[0] = '" in value else ""
                return f"python {entry}" if entry else "python -c (xdist worker or inline code)"
        script = next((a for a in argv[1:] if not a.startswith("-")), "")
        return f"python {Path(script).name}" if script else "python"
    if name == "chromium":
        kind = next((a for a in argv if a.startswith("--type=")), "")
        return f"chromium {kind.removeprefix('--type=') or 'browser'}"
    return name


class Sampler:
    """Attributes the processor time of the workers' process trees to the test each worker runs."""

    def __init__(self, current: Path):
        self.current = current
        self.owner = {}  # (pid, start) -> worker pid
        self.counted = {}  # (pid, start) -> ticks counted so far
        self.parent = {}  # (pid, start) -> (parent pid, start) at the last sample
        self.program = {}
        self.deducted = collections.Counter()
        self.by_test = collections.Counter()
        self.by_program = collections.Counter()
        self.samples = 0

    def sample(self) -> None:
        tests = {}
        for entry in os.listdir(self.current):
            if entry.isdigit():
                try:
                    tests[int(entry)] = (self.current / entry).read_text()
                except OSError:
                    pass
        processes = {}
        for entry in os.listdir("/proc"):
            if entry.isdigit():
                try:
                    processes[int(entry)] = _stat(int(entry))
                except (OSError, ValueError, IndexError):
                    pass
        alive = {(pid, info[2]) for pid, info in processes.items()}
        self._hand_up_the_ended(alive)
        for pid, (ppid, ticks, start) in processes.items():
            key = (pid, start)
            self.parent[key] = (ppid, processes[ppid][2]) if ppid in processes else None
            if key not in self.owner:
                worker = self._worker_of(pid, processes, tests)
                if worker is None:
                    continue
                self.owner[key] = worker
                # A worker counts from now; a process born since the last sample, from its start.
                self.counted[key] = ticks if (pid in tests or self.samples == 0) else 0
                self.program[key] = _program(pid)
                if self.counted[key]:
                    continue
            if key not in self.counted:
                continue
            delta = ticks - self.counted[key] - self.deducted.pop(key, 0)
            self.counted[key] = ticks
            if delta > 0:
                test = tests.get(self.owner[key], BETWEEN)
                self.by_test[test] += delta / TICKS
                self.by_program[self.program[key]] += delta / TICKS
        self.samples += 1

    def _hand_up_the_ended(self, alive: set) -> None:
        """A process that ended was reaped by its parent, whose children's time now holds all of
        its time: what was counted of it (and of its own ended children) is taken off the parent's
        next delta, so nothing is counted twice."""
        self.deducted = collections.Counter()
        ended = {key: ticks for key, ticks in self.counted.items() if key not in alive}

        def depth(key, hops=0):
            up = self.parent.get(key)
            return 0 if up not in ended or hops > 64 else 1 + depth(up, hops + 1)

        for key in sorted(ended, key=depth, reverse=True):  # children before their parents
            up = self.parent.get(key)
            if up in ended:
                ended[up] += ended[key]
            elif up in alive:
                self.deducted[up] += ended[key]
        for key in ended:
            for table in (self.counted, self.parent, self.owner, self.program):
                table.pop(key, None)

    @staticmethod
    def _worker_of(pid: int, processes: dict, tests: dict) -> int | None:
        for _ in range(64):
            if pid in tests:
                return pid
            if pid not in processes or pid <= 1:
                return None
            pid = processes[pid][0]
        return None


def _report(sampler: Sampler, busy_seconds: float, wall: float, top: int) -> None:
    attributed = sum(sampler.by_test.values())
    by_file = collections.Counter()
    for test, seconds in sampler.by_test.items():
        by_file[test.split("::", 1)[0]] += seconds
    print(f"\n{wall:.0f} s wall; the machine's processors were busy {busy_seconds:.0f} CPU-s, of which "
          f"{attributed:.0f} in the suite's processes ({100 * attributed / max(busy_seconds, 1e-9):.0f} %)")
    for title, table in (("test file", by_file), ("test (a module's fixtures count for its first test)",
                                                  sampler.by_test), ("program", sampler.by_program)):
        print(f"\nCPU-s by {title}:")
        for name, seconds in table.most_common(top):
            print(f"{seconds:8.1f}  {100 * seconds / max(attributed, 1e-9):4.1f} %  {name}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n", 1)[0])
    parser.add_argument("--top", type=int, default=25, help="rows per table")
    parser.add_argument("pytest_args", nargs="*", help=f"after --: pytest's arguments (default: {MAKE_TEST_ARGS})")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bench-suite-cpu-") as current:
        env = dict(os.environ, **{CURRENT_ENV: current})
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(Path(__file__).parent), env.get("PYTHONPATH")]))
        env.pop("PYTHONDONTWRITEBYTECODE", None)  # as make test runs pytest
        command = [sys.executable, "-m", "pytest", "-p", Path(__file__).stem, *(args.pytest_args or MAKE_TEST_ARGS)]
        sampler = Sampler(Path(current))
        busy, started = _busy_ticks(), time.monotonic()
        with subprocess.Popen(command, cwd=REPO, env=env) as pytest:
            while pytest.poll() is None:
                sampler.sample()
                time.sleep(PERIOD)
            sampler.sample()
        _report(sampler, (_busy_ticks() - busy) / TICKS, time.monotonic() - started, args.top)
        return pytest.returncode


if __name__ == "__main__":
    sys.exit(main())
