"""The sandbox every process of a submission runs in (and every server of the course's hub).

As root: ``unshare --net --mount``: a network namespace with only loopback (no connection leaves
the machine; DDS traffic stays in it), a private /dev/shm (Fast DDS shared memory), and the
course directory and the repository's instructor folders hidden under empty tmpfs mounts.

:func:`sandbox_command` wraps a command in ``unshare`` and autograder/sandbox/sandbox_entry.py, which
runs first inside the new namespaces: it brings loopback up, makes the mounts and execs the
command. Limits (time, memory, processes) are not the sandbox's job: course_lib.ros.processes applies
them to the sandboxed command (:func:`run_sandboxed`).

Not root: ``unshare --user --map-root-user --net --mount`` when unprivileged user namespaces are
allowed (network and mounts isolated, but one uid for all workers: RLIMIT_NPROC is then shared by
the workers, and the student's processes run as the same user as the checks, which a determined
student could tamper with), else no namespaces at all (no network isolation; the run says so on
stderr and in the grading report's ``isolation`` column).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

from course_lib import contract

REPO = Path(__file__).resolve().parents[2]
#: The script that runs first inside the namespaces (see sandbox_command).
ENTRY = Path(__file__).resolve().parent / "sandbox_entry.py"

_ISOLATION: str | None = None


def isolation() -> str:
    """"root" (namespaces and per-worker uids), "userns" (namespaces, one uid) or "none"."""
    global _ISOLATION
    if _ISOLATION is None:
        if os.geteuid() == 0 and shutil.which("unshare"):
            _ISOLATION = "root"
        elif shutil.which("unshare") and subprocess.run(
                ["unshare", "--user", "--map-root-user", "--net", "--mount", "true"],
                capture_output=True).returncode == 0:
            _ISOLATION = "userns"
        else:
            _ISOLATION = "none"
            print("autograder: no namespaces available (not root, no user namespaces): submissions run "
                  "WITHOUT network isolation and can see the course directory", file=sys.stderr)
    return _ISOLATION


def sandbox_command(command: list[str], hide: list[Path]) -> list[str]:
    """Wrap a command so that it runs in a network + mount namespace (see the module docstring):
    unshare makes the namespaces, autograder/sandbox/sandbox_entry.py sets them up and execs the command."""
    mode = isolation()
    if mode == "none":
        return command
    prefix = ["unshare", "--net", "--mount"] if mode == "root" else \
        ["unshare", "--user", "--map-root-user", "--net", "--mount"]
    # -I -S: the standard library only, nothing from the environment's PYTHON* variables.
    return prefix + [sys.executable, "-I", "-S", str(ENTRY),
                     *[str(p) for p in hide], "--", *command]


def interpreter_exposure() -> dict:
    """When this interpreter's prefix sits below a directory others cannot enter (e.g. /root),
    the sandbox variables that make it reachable for the kernel's uid; else {}."""
    prefix = Path(sys.base_prefix).resolve()
    for ancestor in reversed(prefix.parents):
        if ancestor != Path("/") and not os.stat(ancestor).st_mode & 0o001:
            return {contract.EXPOSE_ENV: str(prefix), contract.BLOCKED_ENV: str(ancestor)}
    return {}


def run_sandboxed(command: list[str], hide: list[Path], name: str, domain_id: int, env: dict, cwd: Path, limits,
                  on_start=None):
    """Run a command in the sandbox (sandbox_command) to its end or its wall time; return the
    stopped course_lib.ros.processes.NodeProcess (its log, returncode, describe_exit()). `on_start`
    gets the process once it runs (another thread may stop it)."""
    from course_lib.ros import processes

    proc = processes.NodeProcess(sandbox_command(command, hide), name=name, domain_id=domain_id, env=env, cwd=cwd,
                                 limits=limits)
    proc.start()
    if on_start is not None:
        on_start(proc)
    try:
        proc.wait(limits.wall_seconds + 30)
    except TimeoutError:
        pass
    finally:
        proc.stop(timeout=5)
    return proc


#: Folders of the repository that a submission's processes never see (empty tmpfs over each):
#: the reference solutions and the instructor's side (the grader, its answer keys, the tests).
HIDDEN_FROM_STUDENTS = [REPO / "assignments", REPO / "autograder", REPO / "tests", REPO / "benchmarks"]


