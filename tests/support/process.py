"""Helpers of the process tests: find a test's own processes by a unique marker in their command
line (psutil), so that a test only sees the processes it started itself."""

import shlex
import subprocess
import sys
import time
import uuid

import psutil


def marker() -> str:
    """A token that appears only in the command lines of one test's processes."""
    return f"course-lib-test-{uuid.uuid4().hex}"


def processes_with(token: str, uid: int | None = None) -> list[psutil.Process]:
    """The live processes whose command line carries `token` (and that run as `uid`, if given)."""
    found = []
    for process in psutil.process_iter(["cmdline", "status", "uids"]):
        try:
            if process.info["status"] != psutil.STATUS_ZOMBIE and any(
                    token in part for part in process.info["cmdline"] or ()) and (
                    uid is None or (process.info["uids"] and process.info["uids"].real == uid)):
                found.append(process)
        except (psutil.NoSuchProcess, psutil.AccessDenied):
            pass
    return found


def wait_until(condition, timeout: float = 60.0) -> bool:
    """Poll `condition` until it holds or `timeout` passes; return its last value. The timeout is
    a backstop for a condition that never comes: a busy machine may take seconds for what an
    idle one does at once (start a Python process, reap a killed one)."""
    deadline = time.monotonic() + timeout
    while not (result := condition()) and time.monotonic() < deadline:
        time.sleep(0.05)
    return result


def in_background_of_a_script(command: list[str], output, env: dict) -> tuple[subprocess.Popen, int]:
    """``COMMAND > OUTPUT 2>&1 &`` in a non-interactive sh, which then waits for it: (the shell,
    the command's pid). Such a command inherits SIGINT (and SIGQUIT) ignored (POSIX)."""
    output.touch()  # the background job opens it a moment after sh has said its pid
    script = f"{shlex.join(command)} > {shlex.quote(str(output))} 2>&1 &\necho $!\nwait $!\n"
    shell = subprocess.Popen(["sh", "-c", script], stdout=subprocess.PIPE, text=True,
                             env=env)
    return shell, int(shell.stdout.readline())


def sleeper(token: str, seconds: int = 100) -> list[str]:
    """A python child that sleeps and carries `token` in its command line."""
    return [sys.executable, "-c", f"import time; print('ready', flush=True); time.sleep({seconds})", token]


def sleeper_script(token: str) -> str:
    """A shell line that runs a sleeping python carrying `token` (python -S starts fast)."""
    return f"{sys.executable} -S -c 'import time; time.sleep(100)' {token}"


def sleepers(token: str) -> list[psutil.Process]:
    return [p for p in processes_with(token) if p.info["cmdline"][-1] == token]
