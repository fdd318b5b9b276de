"""Start-up time of one sandboxed process: the grader's sandbox (autograder.sandbox.namespaces: unshare, then
its own Python entry doing the mounts) against bubblewrap making the same sandbox, and against
no sandbox; measured interleaved in one run.

    .venv/bin/python benchmarks/bench_sandbox.py [--runs 40]

Both sandboxes are first run on one probe that prints what a student's process sees (network
interfaces, a hidden folder, /dev/shm, the folder above the interpreter); the table says whether
they agree. Root gives the grader's full sandbox; bubblewrap comes from Debian
(``apt-get install bubblewrap``) and is left out when it is not installed.
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from autograder.sandbox import namespaces  # noqa: E402

PROBE = """
import os, socket, sys
blocked = os.environ.get("AUTOGRADER_BLOCKED")
print("interfaces", sorted(name for _, name in socket.if_nameindex()), "| hidden folder", os.listdir(sys.argv[1]),
      "| /dev/shm:", len(os.listdir("/dev/shm")), "files, mode", oct(os.stat("/dev/shm").st_mode & 0o7777),
      "|", blocked, "holds", blocked and sorted(os.listdir(blocked))[:5])
"""


def bubblewrap_command(command: list[str], hide: list[Path], env: dict) -> list[str]:
    """The sandbox of autograder.sandbox.namespaces made by bubblewrap (for comparison only)."""
    args = ["bwrap", "--dev-bind", "/", "/", "--unshare-net",
            "--perms", "0777", "--size", str(2 << 30), "--tmpfs", "/dev/shm"]
    if env.get("AUTOGRADER_EXPOSE"):
        args += ["--size", str(1 << 20), "--tmpfs", env["AUTOGRADER_BLOCKED"],
                 "--bind", env["AUTOGRADER_EXPOSE"], env["AUTOGRADER_EXPOSE"]]
    for folder in hide:
        if folder.is_dir():
            args += ["--size", str(1 << 20), "--tmpfs", str(folder)]
    return args + ["--", *command]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=40, help="runs of each way and command (default 40)")
    args = parser.parse_args()
    mode = namespaces.isolation()
    with tempfile.TemporaryDirectory(prefix="bench-sandbox-") as scratch:
        hidden = Path(scratch) / "course"
        hidden.mkdir()
        (hidden / "gradebook.db").write_text("hidden")
        (Path(scratch) / "stage").mkdir()
        env = dict(os.environ)
        if mode == "root":
            env.update(namespaces.interpreter_exposure(), AUTOGRADER_STAGE=str(Path(scratch) / "stage"))
        hide = [hidden, *namespaces.HIDDEN_FROM_STUDENTS]
        ways = {"no sandbox": lambda command: command,
                "autograder.sandbox.namespaces (unshare)": lambda command: namespaces.sandbox_command(command, hide)}
        if shutil.which("bwrap"):
            ways["bubblewrap"] = lambda command: bubblewrap_command(command, hide, env)
        views = {}
        for name, wrap in ways.items():
            done = subprocess.run(wrap([sys.executable, "-c", PROBE, str(hidden)]), env=env, capture_output=True,
                                  text=True)
            views[name] = done.stdout.strip() if done.returncode == 0 else f"failed: {done.stderr.strip()[-200:]}"
        commands = {"/bin/true": ["true"], "python -c pass": [sys.executable, "-c", "pass"]}
        times = {(way, label): [] for way in ways for label in commands}
        for _ in range(args.runs):
            for label, command in commands.items():
                for way, wrap in ways.items():
                    wrapped = wrap(command)
                    started = time.perf_counter()
                    subprocess.run(wrapped, env=env, check=True)
                    times[way, label].append(time.perf_counter() - started)
    print(f"{platform.node()}: {os.cpu_count()} CPUs, isolation {mode}, Python {platform.python_version()}, "
          f"median of {args.runs} interleaved runs")
    for name, view in views.items():
        print(f"  what a sandboxed process sees, {name}: {view}")
    sandboxes = [way for way in ways if way != "no sandbox"]
    if len(sandboxes) == 2:
        print(f"  the two sandboxes {'agree' if views[sandboxes[0]] == views[sandboxes[1]] else 'DIFFER'}")
    print()
    print("| way | " + " | ".join(f"{label} (ms)" for label in commands) + " | ratio to no sandbox (/bin/true) |")
    print("|---|" + "---:|" * (len(commands) + 1))
    floor = statistics.median(times["no sandbox", "/bin/true"])
    for way in ways:
        medians = [statistics.median(times[way, label]) for label in commands]
        print(f"| {way} | " + " | ".join(f"{m * 1000:.1f}" for m in medians) + f" | {medians[0] / floor:.1f}× |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
