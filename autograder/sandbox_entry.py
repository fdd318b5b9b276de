"""What runs first inside the sandbox's namespaces (autograder.sandbox.sandbox_command):

    python -I -S sandbox_entry.py HIDDEN_FOLDER... -- COMMAND [ARG...]

It brings loopback up, makes the mounts private to the namespace, puts an empty tmpfs on
/dev/shm and on each hidden folder, makes the interpreter reachable when it sits below a folder
others cannot enter, then execs COMMAND. Mounts are mount(2) calls through ctypes, as mount(8)
would make them; loopback comes up by ioctl, as with ``ip link set lo up``. It runs before every
sandboxed process, so it imports only modules built into the interpreter (no pathlib, no socket:
each would add tens of milliseconds).
"""

import ctypes
import fcntl
import os
import struct
import sys
from _socket import AF_INET, SOCK_DGRAM, socket

MS_BIND, MS_MOVE, MS_REC, MS_PRIVATE = 0x1000, 0x2000, 0x4000, 0x40000
SIOCGIFFLAGS, SIOCSIFFLAGS, IFF_UP = 0x8913, 0x8914, 0x1
IFREQ = "16sh22x"  # struct ifreq: the interface's name, its flags


def mount(source: str, target: str, fstype=None, flags: int = 0, options=None) -> None:
    """mount(2); raises OSError naming the source and the target."""
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.mount(source.encode(), target.encode(), fstype and fstype.encode(), flags,
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
    AUTOGRADER_STAGE (autograder.sandbox.interpreter_exposure)."""
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


def main(argv: list) -> int:
    """Enter, then exec the command (searched on PATH); 1 when a mount fails, 2 on bad arguments."""
    if "--" not in argv or argv.index("--") == len(argv) - 1:
        print("usage: sandbox_entry.py HIDDEN_FOLDER... -- COMMAND [ARG...]", file=sys.stderr)
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
