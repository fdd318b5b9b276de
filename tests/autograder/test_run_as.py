"""Tests for autograder.sandbox.run_as: the grader runs a command as another uid, and only root may."""

import os
import signal
import sys

import pytest
from support.process import processes_with, wait_until

from autograder.sandbox import run_as
from course_lib.ros.processes import NodeProcess

needs_root = pytest.mark.skipif(os.geteuid() != 0, reason="dropping to another user needs root")

NOBODY = 65534


@needs_root
def test_child_runs_as_the_limits_user_with_a_process_limit():
    """As root, run_as makes RLIMIT_NPROC bite: the child cannot fork past it."""
    import pwd

    nobody = pwd.getpwnam("nobody")
    script = "id -u; for i in 1 2 3 4 5 6 7 8; do sleep 1 & done; wait; echo done"
    process = NodeProcess(run_as.command("nobody", ["sh", "-c", script], max_processes=4), cwd="/").start()
    process.wait(timeout=60)
    lines = process.log.splitlines()
    assert lines[0] == str(nobody.pw_uid)
    assert "fork" in process.log.lower() or "resource temporarily unavailable" in process.log.lower(), process.log


@needs_root
def test_child_runs_as_a_bare_uid_without_a_passwd_entry():
    """The user may be a number with no account behind it: the child gets that uid and gid, and a
    HOME it owns, removed after it."""
    import pwd

    uid = 61999
    with pytest.raises(KeyError):
        pwd.getpwuid(uid)
    home = run_as.home_for(uid)
    process = NodeProcess(run_as.command(uid, ["sh", "-c", "id -u; id -g; touch \"$HOME/written\" && echo home-ok"]),
                          cwd="/", env={"HOME": home}, private_dirs=[home]).start()
    process.wait(timeout=30)
    assert process.log.split() == [str(uid), str(uid), "home-ok"], process.log
    assert not os.path.exists(home)


def test_an_unknown_user_name_is_refused_with_the_fix():
    with pytest.raises(ValueError, match="does not exist on this machine; use an existing unprivileged account"):
        run_as.command("course-lib-no-such-user", ["true"])


def test_max_processes_must_be_positive():
    with pytest.raises(ValueError, match="max_processes is 0: use a positive number"):
        run_as.command(NOBODY, ["true"], max_processes=0)


def _in_a_child_as_nobody(function) -> tuple[int, str]:
    """Run function() in a forked child that runs as nobody (when root): its exit code, its stderr."""
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:
        try:
            os.close(read)
            sys.stderr = os.fdopen(write, "w")  # what the child says, for the test
            if os.geteuid() == 0:
                os.setgroups([])
                os.setgid(NOBODY)
                os.setuid(NOBODY)
            code = function()
            sys.stderr.flush()
        except BaseException:  # the test fails on the exit code; nothing may escape the fork
            code = 99
        os._exit(code)
    os.close(write)
    with os.fdopen(read) as errors:
        said = errors.read()
    _, status = os.waitpid(pid, 0)
    return os.waitstatus_to_exitcode(status), said


def test_switching_user_is_refused_when_not_root():
    """Not root: the wrapper refuses to switch (it says why), and no home is made for another user."""
    def refused_home() -> int:
        try:
            run_as.home_for(61998)
        except PermissionError as error:
            return 0 if "needs the caller to run as root" in str(error) else 2
        return 1

    assert _in_a_child_as_nobody(refused_home)[0] == 0
    code, said = _in_a_child_as_nobody(lambda: run_as.main(["61998", "61998", "0", "--", "true"]))
    assert code == run_as.EXIT_NOT_EXECUTABLE
    assert "switching to uid 61998 needs root" in said


@needs_root
def test_a_program_the_user_cannot_execute_is_named_with_the_fix(tmp_path):
    script = tmp_path / "private.sh"
    script.write_text("#!/bin/sh\necho ran\n")
    script.chmod(0o700)  # root's only
    process = NodeProcess(run_as.command(NOBODY, [str(script)]), cwd="/").start()
    assert process.wait(timeout=30) == run_as.EXIT_NOT_EXECUTABLE
    assert "needs read and execute access" in process.log and "ran" not in process.log


@needs_root
def test_the_child_still_dies_with_its_supervisor(token):
    """Switching uid clears PR_SET_PDEATHSIG; the wrapper arms it again, so a killed supervisor
    leaves no process of the student behind."""
    # A shell, not this interpreter: nobody cannot run a virtual environment whose Python lies
    # under /root. The token is the shell's $0; its `sleep 1` children end within a second of it.
    command = run_as.command(NOBODY, ["sh", "-c", "while :; do sleep 1; done", token])
    process = NodeProcess(command, cwd="/").start()
    # The child, as nobody, once the wrapper has exec'd it: the wrapper carries the token too, as
    # root until it switches and as nobody until it execs (before it arms the death signal).
    assert wait_until(lambda: [p for p in processes_with(token, uid=NOBODY) if p.info["cmdline"][0] == "sh"],
                      timeout=60), process.log
    os.kill(process._supervisor.pid, signal.SIGKILL)
    assert wait_until(lambda: not processes_with(token), timeout=30), processes_with(token)
    process.stop()


@needs_root
def test_give_tree_hands_every_file_folder_and_link_to_the_uid(tmp_path):
    (tmp_path / "a" / "b").mkdir(parents=True)
    (tmp_path / "a" / "b" / "file").write_text("x")
    (tmp_path / "a" / "link").symlink_to("/etc/hostname")
    run_as.give_tree(tmp_path / "a", 61990)
    for path in (tmp_path / "a", tmp_path / "a" / "b", tmp_path / "a" / "b" / "file", tmp_path / "a" / "link"):
        assert os.lstat(path).st_uid == 61990 and os.lstat(path).st_gid == 61990, path
    assert os.stat("/etc/hostname").st_uid == 0  # the link's target is not the student's
