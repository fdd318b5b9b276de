"""Run a command as another (unprivileged) user: the grader's switch to a student's uid.

:func:`command` wraps a command line so that it runs as `user` (a name, or a bare uid that needs no
passwd entry) with no supplementary groups and at most `max_processes` processes and threads::

    proc = processes.NodeProcess(run_as.command(61003, ["python", "-m", "pubsub_nodes"], max_processes=384),
                                 env={"HOME": str(home)}, private_dirs=[home])

The wrapper is this file, run as a script by a fresh ``python -I -S`` (standard library only, no
site-packages, so it starts in a few milliseconds). It is started by the supervisor of a
course_lib.ros.processes.NodeProcess, as root, after the supervisor put it in the node's process
group and set its resource limits; it then

- drops to the uid and gid (setgroups, setgid, setuid; the kernel refuses it unless root),
- sets RLIMIT_NPROC after the switch (the kernel counts it per user and does not enforce it for
  root; set before, a user already at the limit would fail the exec),
- arms PR_SET_PDEATHSIG again (a change of credentials clears it), so it still dies with its
  supervisor, and execs the command. The command's exit code, signals and output are its own.

Everything here is the grader's: course_lib never imports it (students' environments may lack it).
"""

from __future__ import annotations

import errno
import os
import signal
import sys
import tempfile

_PR_SET_PDEATHSIG = 1

#: What the wrapper exits with when the command cannot be executed (the shell's codes).
EXIT_NOT_FOUND = 127
EXIT_NOT_EXECUTABLE = 126


def command(user: str | int, command: list[str], max_processes: int | None = None) -> list[str]:
    """The command line that runs `command` as `user` (see the module docstring).

    Raises:
        ValueError: no such user name, or max_processes is not positive.
    """
    uid, gid = ids_of(user)
    if max_processes is not None and not max_processes > 0:
        raise ValueError(f"max_processes is {max_processes!r}: use a positive number, or None for no limit")
    return [sys.executable, "-I", "-S", os.path.abspath(__file__), str(uid), str(gid), str(max_processes or 0),
            "--", *[os.fspath(part) for part in command]]


def ids_of(user: str | int) -> tuple[int, int]:
    """(uid, gid) of a user name, or of a bare uid (no passwd entry needed; it is its own group).

    Raises:
        ValueError: no user of that name, with the fix.
    """
    import pwd

    if isinstance(user, int):
        return user, user
    try:
        entry = pwd.getpwnam(user)
    except KeyError:
        raise ValueError(f"user {user!r} does not exist on this machine; use an existing unprivileged "
                         "account such as 'nobody', or a bare uid such as 61000") from None
    return entry.pw_uid, entry.pw_gid


def home_for(user: str | int) -> str:
    """A fresh home directory owned by `user`, for a child that runs as that user (ROS writes its
    logs under HOME); the caller removes it (NodeProcess's private_dirs).

    Raises:
        PermissionError: the caller is not root (only root can give a folder to another user).
    """
    uid, gid = ids_of(user)
    if os.geteuid() != 0 and uid != os.geteuid():
        raise PermissionError(f"running as user {user!r} needs the caller to run as root; "
                              "leave the user out when not running as root")
    home = tempfile.mkdtemp(prefix="autograder-home-")
    os.chown(home, uid, gid)
    return home


def give_tree(path, uid: int) -> None:
    """Make `uid` (and its group of the same number) own a folder the grader created and all in it,
    links themselves included, so the student's processes can write there."""
    os.chown(path, uid, uid)
    for directory, dirs, files in os.walk(path):
        for name in dirs + files:
            os.lchown(os.path.join(directory, name), uid, uid)


def become(uid: int, gid: int, max_processes: int | None = None) -> None:
    """Switch this process to uid and gid with no supplementary groups, then bound the processes
    and threads of that uid (RLIMIT_NPROC): the wrapper's step, and the grading kernel's
    (autograder.sandbox.kernel).

    Raises:
        PermissionError: this process is not root.
    """
    import resource

    os.setgroups([])
    os.setgid(gid)
    os.setuid(uid)
    if max_processes:
        resource.setrlimit(resource.RLIMIT_NPROC, (max_processes, max_processes))


def main(argv: list[str]) -> int:
    """The wrapper: argv is [uid, gid, max_processes (0: none), "--", command...]."""
    import ctypes

    uid, gid, nproc = (int(value) for value in argv[:3])
    program = argv[4:]
    parent = os.getppid()
    try:
        become(uid, gid, nproc)
    except PermissionError:
        sys.stderr.write(f"autograder.sandbox.run_as: switching to uid {uid} needs root, and this process runs as uid "
                         f"{os.geteuid()}; leave the user out when not running as root\n")
        return EXIT_NOT_EXECUTABLE
    ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent:  # the supervisor died before prctl took effect
        os.kill(os.getpid(), signal.SIGKILL)
    try:
        os.execvp(program[0], program)
    except OSError as error:
        if error.errno == errno.ENOENT:
            sys.stderr.write(f"Cannot run {program[0]!r}: no such file or program on PATH\n")
            return EXIT_NOT_FOUND
        sys.stderr.write(f"Cannot run {program[0]!r} as uid {uid}: {error.strerror}; that user needs read and "
                         "execute access to it, to the interpreter it runs and to every directory above them "
                         "(a virtual environment under /root is not)\n")
        return EXIT_NOT_EXECUTABLE
    return EXIT_NOT_EXECUTABLE  # not reached


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
