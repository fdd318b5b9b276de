"""What runs inside the sandbox in place of a grader program that the fork server runs
(autograder.grading.fork_server)::

    python -I -S fork_client.py SOCKET MODULE [ARG...]

It asks the fork server listening on SOCKET to run ``python -m MODULE ARG...`` in this process's
namespaces, with its environment, working directory, umask, resource limits and standard streams,
then stands for that run: a signal it gets (a stop of the sandbox) is passed on, and it ends as the
run ended (the same exit code, or killed by the same signal). Standard library only, started with
``-I -S`` like autograder/sandbox/sandbox_entry.py: a few milliseconds.
"""

import json
import os
import signal
import socket
import sys

#: What a stop sends, passed on to the run (autograder/sandbox/sandbox_entry.py forwards the same).
FORWARDED = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGQUIT, signal.SIGUSR1, signal.SIGUSR2)


def main(argv: list) -> int:
    if len(argv) < 2:
        print("usage: fork_client.py SOCKET MODULE [ARG...]", file=sys.stderr)
        return 2
    path, module, args = argv[0], argv[1], argv[2:]
    umask = os.umask(0)
    os.umask(umask)
    request = json.dumps({"module": module, "args": args, "env": dict(os.environ), "cwd": os.getcwd(),
                          "umask": umask}).encode()
    server = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    try:
        server.connect(path)
        socket.send_fds(server, [request], [0, 1, 2])
    except OSError as error:
        print(f"autograder: the grader's fork server at {path} is not there ({error.strerror}): "
              "grade again (the grader starts a new one)", file=sys.stderr)
        return 1
    for number in FORWARDED:
        signal.signal(number, lambda signum, _frame: server.send(f"signal {signum}".encode()))
    reply = b""
    while not reply:
        try:
            reply = server.recv(64)
        except InterruptedError:  # a signal was passed on; wait on
            continue
        if not reply:
            print("autograder: the grader's fork server ended before the run did", file=sys.stderr)
            return 1
    kind, number = reply.decode().split()
    if kind == "exit":
        return int(number)
    if int(number) not in (signal.SIGKILL, signal.SIGSTOP):  # those two have no handler to reset
        signal.signal(int(number), signal.SIG_DFL)
    os.kill(os.getpid(), int(number))
    return 128 + int(number)  # not reached


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
