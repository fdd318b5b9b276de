"""The sandbox every process of a submission runs in (and every server of the course's hub).

As root: ``unshare --net --mount``: a network namespace with only loopback (no connection leaves
the machine; DDS traffic stays in it), a private /dev/shm (Fast DDS shared memory), and the
course directory and the repository's instructor folders hidden under empty tmpfs mounts.

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

REPO = Path(__file__).resolve().parent.parent

_ISOLATION: str | None = None


def isolation() -> str:
    """"root" (namespaces and per-worker uids), "userns" (namespaces, one uid) or "none"."""
    global _ISOLATION
    if _ISOLATION is None:
        if os.geteuid() == 0 and shutil.which("unshare") and shutil.which("ip"):
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


_SANDBOX_SCRIPT = r'''
set -e
ip link set lo up
mount --make-rprivate /
# No sticky bit: Fast DDS replaces a dead participant's shared-memory port by unlinking it, and
# the student's uid must be able to do so for ports a (root) check process left behind.
mount -t tmpfs -o size=2g,mode=0777 autograder-shm /dev/shm
if [ -n "$AUTOGRADER_EXPOSE" ]; then
  # The interpreter lives under a directory the kernel's uid cannot enter (a pyenv under /root):
  # hide that directory under a tmpfs and put the interpreter's prefix back at the same path.
  mount --bind "$AUTOGRADER_EXPOSE" "$AUTOGRADER_STAGE"
  mount -t tmpfs -o size=1m,mode=755 autograder-home "$AUTOGRADER_BLOCKED"
  mkdir -p "$AUTOGRADER_EXPOSE"
  mount --move "$AUTOGRADER_STAGE" "$AUTOGRADER_EXPOSE"
fi
for hidden in "$@"; do
  case "$hidden" in --) shift; break;; esac
  [ -d "$hidden" ] && mount -t tmpfs -o size=1m,mode=755 autograder-hidden "$hidden"
  shift
done
exec "$@"
'''


def sandbox_command(command: list[str], hide: list[Path]) -> list[str]:
    """Wrap a command so that it runs in a network + mount namespace (see the module docstring)."""
    mode = isolation()
    if mode == "none":
        return command
    prefix = ["unshare", "--net", "--mount"] if mode == "root" else \
        ["unshare", "--user", "--map-root-user", "--net", "--mount"]
    return prefix + ["sh", "-c", _SANDBOX_SCRIPT, "autograder-sandbox",
                     *[str(p) for p in hide], "--", *command]


def interpreter_exposure() -> dict:
    """When this interpreter's prefix sits below a directory others cannot enter (e.g. /root),
    the sandbox variables that make it reachable for the kernel's uid; else {}."""
    prefix = Path(sys.base_prefix).resolve()
    for ancestor in reversed(prefix.parents):
        if ancestor != Path("/") and not os.stat(ancestor).st_mode & 0o001:
            return {"AUTOGRADER_EXPOSE": str(prefix), "AUTOGRADER_BLOCKED": str(ancestor)}
    return {}


def run_sandboxed(command: list[str], hide: list[Path], name: str, domain_id: int, env: dict, cwd: Path, limits):
    """Run a command in the sandbox (sandbox_command) to its end or its wall time; return the
    stopped course_lib.processes.NodeProcess (its log, returncode, describe_exit())."""
    from course_lib import processes

    proc = processes.NodeProcess(sandbox_command(command, hide), name=name, domain_id=domain_id, env=env, cwd=cwd,
                                 limits=limits)
    proc.start()
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

