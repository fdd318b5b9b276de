"""What runs first inside the sandbox's namespaces (autograder.sandbox.namespaces.sandbox_command):

    python -I -S sandbox_entry.py HIDDEN_FOLDER... -- COMMAND [ARG...]

It brings loopback up, makes the mounts private to the namespace, puts an empty tmpfs on
/dev/shm and on each hidden folder, makes the interpreter reachable when it sits below a folder
others cannot enter, then runs COMMAND in a process-id namespace of its own. Mounts are mount(2)
calls through ctypes, as mount(8) would make them; loopback comes up by ioctl, as with ``ip link
set lo up``. It runs before every sandboxed process, so it imports only modules built into the
interpreter (no pathlib, no socket: each would add tens of milliseconds).

Why a process-id namespace: nothing COMMAND starts outlives it. Its first process (pid 1 there,
the "init" below) starts COMMAND; when COMMAND ends, init ends, and the kernel kills every other
process of the namespace (daemons, a node started with nohup, a check's helpers whose parent was
killed), whatever process group or session they moved to. Three processes take part:

- this script (the "outer" process, whose pid the caller knows) forwards the signals a stop
  sends (SIGINT, SIGTERM, ...) to init, waits for it, and ends as COMMAND ended: the same exit
  code, or killed by the same signal;
- init (pid 1 of the namespace, with /proc of the namespace mounted) forwards them to COMMAND's
  process group, reaps every orphan, and tells the outer process how COMMAND ended; it dies with
  the outer process (PR_SET_PDEATHSIG);
- COMMAND (pid 2) in a process group of its own, so that a signal to the caller's group reaches
  it once, through the outer process.
"""

import ctypes
import fcntl
import os
import signal
import struct
import sys
from _socket import AF_INET, SOCK_DGRAM, socket

MS_NOSUID, MS_NODEV, MS_NOEXEC = 0x2, 0x4, 0x8
MS_BIND, MS_MOVE, MS_REC, MS_PRIVATE = 0x1000, 0x2000, 0x4000, 0x40000
CLONE_NEWPID, PR_SET_PDEATHSIG = 0x20000000, 1
#: What a stop sends, passed on to COMMAND (SIGKILL needs no passing on: see run_as_init).
FORWARDED = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGQUIT, signal.SIGUSR1, signal.SIGUSR2)
SIOCGIFFLAGS, SIOCSIFFLAGS, IFF_UP = 0x8913, 0x8914, 0x1
IFREQ = "16sh22x"  # struct ifreq: the interface's name, its flags


def _libc():
    return ctypes.CDLL(None, use_errno=True)


def mount(source: str, target: str, fstype=None, flags: int = 0, options=None) -> None:
    """mount(2); raises OSError naming the source and the target."""
    if _libc().mount(source.encode(), target.encode(), fstype and fstype.encode(), flags,
                  options and options.encode()) != 0:
        error = ctypes.get_errno()
        raise OSError(error, f"the sandbox could not mount {source} on {target}: {os.strerror(error)}")


def loopback_up() -> None:
    """``ip link set lo up``: a new network namespace has its loopback interface down."""
    sock = socket(AF_INET, SOCK_DGRAM)
    try:
        flags = struct.unpack(IFREQ, fcntl.ioctl(sock, SIOCGIFFLAGS, struct.pack(IFREQ, b"lo", 0)))[1]
        fcntl.ioctl(sock, SIOCSIFFLAGS, struct.pack(IFREQ, b"lo", flags | IFF_UP))
    finally:
        sock.close()


def enter(hidden: list, env: dict) -> None:
    """Set up the namespaces this process was started in (see the module docstring). The
    interpreter is exposed when `env` has AUTOGRADER_EXPOSE, AUTOGRADER_BLOCKED and
    AUTOGRADER_STAGE (autograder.sandbox.namespaces.interpreter_exposure)."""
    loopback_up()
    mount("none", "/", flags=MS_REC | MS_PRIVATE)
    # No sticky bit: Fast DDS replaces a dead participant's shared-memory port by unlinking it, and
    # the student's uid must be able to do so for ports a (root) check process left behind.
    mount("autograder-shm", "/dev/shm", "tmpfs", options="size=2g,mode=0777")
    if env.get("AUTOGRADER_EXPOSE"):
        # The interpreter lives under a directory the kernel's uid cannot enter (a pyenv under /root):
        # hide that directory under a tmpfs and put the interpreter's prefix back at the same path.
        expose, stage = env["AUTOGRADER_EXPOSE"], env["AUTOGRADER_STAGE"]
        mount(expose, stage, flags=MS_BIND)
        mount("autograder-home", env["AUTOGRADER_BLOCKED"], "tmpfs", options="size=1m,mode=755")
        os.makedirs(expose, exist_ok=True)
        mount(stage, expose, flags=MS_MOVE)
    for folder in hidden:
        if os.path.isdir(folder):
            mount("autograder-hidden", folder, "tmpfs", options="size=1m,mode=755")


def _forward(target, send) -> dict:
    """Pass each FORWARDED signal on to `target` with `send`; the dispositions it replaced."""
    def handler(number, frame):
        try:
            send(target, number)
        except OSError:  # the target has ended
            pass
    return {number: signal.signal(number, handler) for number in FORWARDED}


def run_as_init(command: list, dispositions: dict, status_fd: int, alive_fd: int) -> None:
    """Pid 1 of the new namespace: mount its /proc, start `command` (pid 2), pass signals on to
    it, reap orphans; write COMMAND's wait status to `status_fd`, then end (which ends the namespace)."""
    _libc().prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    os.set_blocking(alive_fd, False)
    try:
        if os.read(alive_fd, 1) == b"":  # the outer process ended before prctl took effect
            os._exit(1)
    except BlockingIOError:  # it is alive, and holds the pipe open
        pass
    os.setpgid(0, 0)  # out of the caller's group: a stop reaches COMMAND through the outer process only
    mount("proc", "/proc", "proc", flags=MS_NOSUID | MS_NODEV | MS_NOEXEC)
    child = os.fork()
    if child == 0:
        os.setpgid(0, 0)
        for number, disposition in dispositions.items():
            signal.signal(number, disposition)
        for number in (signal.SIGPIPE, signal.SIGXFSZ):  # Python ignores these; COMMAND gets the default
            signal.signal(number, signal.SIG_DFL)
        os.close(status_fd)
        os.close(alive_fd)
        try:
            os.execvp(command[0], command)
        except OSError as error:
            print(f"autograder sandbox: cannot run {command[0]}: {error.strerror}", file=sys.stderr)
            os._exit(127)
    try:
        os.setpgid(child, child)  # also here: a signal may come before the child has done it
    except OSError:
        pass
    _forward(child, os.killpg)
    while True:
        pid, status = os.wait()
        if pid == child:
            os.write(status_fd, str(status).encode())
            os._exit(0)


def run_in_pid_namespace(command: list) -> int:
    """The outer process: start init in a new process-id namespace (run_as_init) and end as
    COMMAND ended."""
    if _libc().unshare(CLONE_NEWPID) != 0:
        error = ctypes.get_errno()
        raise OSError(error, f"the sandbox could not make a process-id namespace: {os.strerror(error)}")
    status_read, status_write = os.pipe()
    alive_read, alive_write = os.pipe()
    dispositions = {number: signal.getsignal(number) for number in FORWARDED}
    init = os.fork()
    if init == 0:
        os.close(status_read)
        os.close(alive_write)
        try:
            run_as_init(command, dispositions, status_write, alive_read)
        finally:
            os._exit(1)
    os.close(status_write)
    os.close(alive_read)
    _forward(init, os.kill)
    os.waitpid(init, 0)
    text = os.read(status_read, 32).decode()
    status = int(text) if text else None
    if status is not None and os.WIFEXITED(status):
        return os.WEXITSTATUS(status)
    number = os.WTERMSIG(status) if status is not None else signal.SIGKILL  # no status: init was killed
    if number not in (signal.SIGKILL, signal.SIGSTOP):  # those two have no handler to reset
        signal.signal(number, signal.SIG_DFL)
    os.kill(os.getpid(), number)
    return 128 + number  # not reached


def main(argv: list) -> int:
    """Enter, then run the command (searched on PATH) in a process-id namespace of its own; its
    exit code (or its signal), 1 when a mount fails, 2 on bad arguments."""
    if "--" not in argv or argv.index("--") == len(argv) - 1:
        print("usage: sandbox_entry.py HIDDEN_FOLDER... -- COMMAND [ARG...]", file=sys.stderr)
        return 2
    split = argv.index("--")
    try:
        enter(argv[:split], dict(os.environ))
    except OSError as error:
        print(f"autograder sandbox: {error}", file=sys.stderr)
        return 1
    return run_in_pid_namespace(argv[split + 1:])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
