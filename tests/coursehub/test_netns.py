"""coursehub.netns: a pinned network namespace keeps meaning that namespace after its processes
end, although the kernel hands a freed namespace number to the next namespace it makes."""

from __future__ import annotations

import os
import subprocess
import time

import pytest

from coursehub.netns import PinnedNamespace

#: A process in a network namespace of its own (a user namespace too: no root needed).
IN_OWN_NAMESPACE = ["unshare", "--user", "--map-root-user", "--net"]


def _pinned(process: subprocess.Popen) -> PinnedNamespace:
    """The namespace of `process` once it has entered it (unshare does that before it runs the command)."""
    deadline = time.monotonic() + 60  # a backstop: unshare enters at once
    while (pinned := PinnedNamespace.of(process.pid)) is None:
        assert process.poll() is None and time.monotonic() < deadline, "unshare did not enter a namespace"
        time.sleep(0.01)
    return pinned


def _name(pid: int) -> str:
    return os.readlink(f"/proc/{pid}/ns/net")


def test_the_callers_own_namespace_is_not_pinned():
    assert PinnedNamespace.of(os.getpid()) is None


def test_a_pinned_namespace_holds_every_process_left_in_it():
    process = subprocess.Popen([*IN_OWN_NAMESPACE, "sh", "-c", "sleep 60 & echo $!; exec sleep 61"],
                               stdout=subprocess.PIPE, text=True)
    left = int(process.stdout.readline())
    try:
        with _pinned(process) as pinned:
            assert sorted(pinned.processes()) == sorted([process.pid, left])
    finally:
        subprocess.run(["kill", "-9", str(process.pid), str(left)])
        process.wait(60)


@pytest.mark.skipif(os.geteuid() != 0, reason="entering a namespace needs root")
def test_a_pinned_namespace_outlives_its_processes():
    """Held, the namespace still exists once its last process has ended: a process can enter it,
    and it is found there. (Let go, it would be gone and its number free for the next one.)"""
    server = subprocess.Popen([*IN_OWN_NAMESPACE, "sleep", "60"])
    with _pinned(server) as pinned:
        server.kill()
        server.wait(60)
        fd = pinned.fileno()
        entered = subprocess.Popen(["nsenter", f"--net=/proc/self/fd/{fd}", "sleep", "60"], pass_fds=(fd,))
        try:
            deadline = time.monotonic() + 60  # a backstop: nsenter enters at once
            while pinned.processes() != [entered.pid]:
                assert entered.poll() is None and time.monotonic() < deadline, pinned.processes()
                time.sleep(0.01)
        finally:
            entered.kill()
            entered.wait(60)


def test_a_new_namespace_never_takes_a_pinned_ones_place():
    """The server's namespace ends with its last process; the new namespaces made after (a grader's
    builds and checks) are never taken for it. Unpinned, the kernel gives its number to one of the
    next few it makes."""
    server = subprocess.Popen([*IN_OWN_NAMESPACE, "sleep", "60"])
    pinned = _pinned(server)
    try:
        name = _name(server.pid)
        server.kill()
        server.wait(60)
        assert pinned.processes() == []
        for _ in range(30):
            grading = subprocess.Popen([*IN_OWN_NAMESPACE, "sleep", "60"])
            try:
                with _pinned(grading):
                    assert _name(grading.pid) != name
                    assert pinned.processes() == []
            finally:
                grading.kill()
                grading.wait(60)
    finally:
        pinned.close()
