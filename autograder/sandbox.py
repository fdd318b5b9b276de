"""The sandbox every process of a submission runs in (and every server of the course's hub).

As root: ``unshare --net --mount``: a network namespace with only loopback (no connection leaves
the machine; DDS traffic stays in it), a private /dev/shm (Fast DDS shared memory), and the
course directory and the repository's instructor folders hidden under empty tmpfs mounts.

Two halves: :func:`sandbox_command` (the grader's side) wraps a command in ``unshare`` and this
file run as a script, ``python -I -S sandbox.py HIDDEN... -- COMMAND...``; inside the new
namespaces :func:`enter` brings loopback up and mounts (mount(2) through ctypes, as mount(8)
would), then :func:`main` execs the command. Limits (time, memory, processes) are not the
sandbox's job: course_lib.processes applies them to the sandboxed command.

Not root: ``unshare --user --map-root-user --net --mount`` when unprivileged user namespaces are
allowed (network and mounts isolated, but one uid for all workers: RLIMIT_NPROC is then shared by
the workers, and the student's processes run as the same user as the checks, which a determined
student could tamper with), else no namespaces at all (no network isolation; the run says so on
stderr and in the grading report's ``isolation`` column).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent

_ISOLATION: str | None = None


def isolation() -> str:
    """"root" (namespaces and per-worker uids), "userns" (namespaces, one uid) or "none"."""
    # Imported here, not at the top: the script run inside every sandbox starts faster without them.
    import shutil
    import subprocess

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
    unshare makes the namespaces, then this file, run as a script inside them (:func:`enter`),
    mounts what the sandbox hides and execs the command."""
    mode = isolation()
    if mode == "none":
        return command
    prefix = ["unshare", "--net", "--mount"] if mode == "root" else \
        ["unshare", "--user", "--map-root-user", "--net", "--mount"]
    # -I -S: the standard library only, nothing from the environment's PYTHON* variables.
    return prefix + [sys.executable, "-I", "-S", str(Path(__file__).resolve()),
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



# ---------------------------------------------------------------------------------------------
# Inside the namespaces: ``python -I -S sandbox.py HIDDEN... -- COMMAND...`` (see sandbox_command)
# ---------------------------------------------------------------------------------------------

_MS_BIND, _MS_MOVE, _MS_REC, _MS_PRIVATE = 0x1000, 0x2000, 0x4000, 0x40000
_SIOCGIFFLAGS, _SIOCSIFFLAGS, _IFF_UP = 0x8913, 0x8914, 0x1


def _mount(source: str, target: str, fstype: str | None = None, flags: int = 0, options: str | None = None) -> None:
    """mount(2), as mount(8) would call it; raises OSError naming the target."""
    import ctypes

    libc = ctypes.CDLL(None, use_errno=True)
    if libc.mount(source.encode(), target.encode(), fstype and fstype.encode(), flags,
                  options and options.encode()) != 0:
        error = ctypes.get_errno()
        raise OSError(error, f"the sandbox could not mount {source} on {target}: {os.strerror(error)}")


def _loopback_up() -> None:
    """``ip link set lo up``: a new network namespace has its loopback interface down."""
    import fcntl
    import socket
    import struct

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        request = struct.pack("16sh22x", b"lo", 0)  # struct ifreq: name, flags
        flags = struct.unpack("16sh22x", fcntl.ioctl(sock, _SIOCGIFFLAGS, request))[1]
        fcntl.ioctl(sock, _SIOCSIFFLAGS, struct.pack("16sh22x", b"lo", flags | _IFF_UP))


def enter(hidden: list[str], env: dict) -> None:
    """Set up the namespaces this process was started in: loopback up, mounts private to the
    namespace, a private /dev/shm, `hidden` folders under empty tmpfs mounts, and the
    interpreter made reachable when it sits below a folder others cannot enter (`env`'s
    AUTOGRADER_EXPOSE, AUTOGRADER_BLOCKED and AUTOGRADER_STAGE, from interpreter_exposure)."""
    _loopback_up()
    _mount("none", "/", flags=_MS_REC | _MS_PRIVATE)
    # No sticky bit: Fast DDS replaces a dead participant's shared-memory port by unlinking it, and
    # the student's uid must be able to do so for ports a (root) check process left behind.
    _mount("autograder-shm", "/dev/shm", "tmpfs", options="size=2g,mode=0777")
    if env.get("AUTOGRADER_EXPOSE"):
        # The interpreter lives under a directory the kernel's uid cannot enter (a pyenv under /root):
        # hide that directory under a tmpfs and put the interpreter's prefix back at the same path.
        expose, stage = env["AUTOGRADER_EXPOSE"], env["AUTOGRADER_STAGE"]
        _mount(expose, stage, flags=_MS_BIND)
        _mount("autograder-home", env["AUTOGRADER_BLOCKED"], "tmpfs", options="size=1m,mode=755")
        os.makedirs(expose, exist_ok=True)
        _mount(stage, expose, flags=_MS_MOVE)
    for folder in hidden:
        if os.path.isdir(folder):
            _mount("autograder-hidden", folder, "tmpfs", options="size=1m,mode=755")


def main(argv: list[str]) -> int:
    """``sandbox.py HIDDEN... -- COMMAND...``: enter, then exec COMMAND (searched on PATH)."""
    if "--" not in argv or argv.index("--") == len(argv) - 1:
        print("usage: sandbox.py HIDDEN_FOLDER... -- COMMAND [ARG...]", file=sys.stderr)
        return 2
    split = argv.index("--")
    try:
        enter(argv[:split], dict(os.environ))
    except OSError as error:
        print(f"autograder sandbox: {error}", file=sys.stderr)
        return 1
    command = argv[split + 1:]
    os.execvp(command[0], command)
    return 1  # not reached


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
