"""Fixtures shared by the test modules: a browser, a marker for a test's own processes, a
package for launch files; and the last resort against a test stuck in native code."""

import contextlib
import faulthandler
import os
import tempfile

import pytest
from support.browser import ChromiumUnavailable, launched_chromium
from support.launch_demo import make_prefix
from support.process import marker, processes_with

from autograder import answers
from course_lib.ros2cli import daemon

# The tests run graded checks (runner.execute(..., mode="graded")) as the grader does: the grader
# hands its checks the answer keys through the contract (course_lib.checks.answers).
os.environ.update(answers.environment())
# A ros2 daemon that a test's `ros2` command starts ends with this worker at the latest, and in a
# reserved ROS domain as soon as the reservation ends (course_lib.ros2cli.daemon).
os.environ[daemon.OWNER_ENV] = str(os.getpid())


#: Seconds after pytest-timeout's limit at which a test still running ends its worker process.
HARD_STOP_AFTER = 60


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    """pytest-timeout interrupts a test through a signal, which Python handles only between
    bytecodes: a test stuck in native code holding the GIL (Fast DDS 2.14 can deadlock while a
    DDS participant is destroyed) would hold its worker, and the whole run, forever. Past the
    limit plus HARD_STOP_AFTER, faulthandler's own thread prints every thread's stack and ends the
    worker; xdist reports the test as failed and goes on with a new worker."""
    marker = item.get_closest_marker("timeout")
    limit = float(marker.args[0]) if marker and marker.args else float(item.config.getini("timeout") or 0)
    if limit > 0:
        faulthandler.dump_traceback_later(limit + HARD_STOP_AFTER, exit=True)
    try:
        yield
    finally:
        faulthandler.cancel_dump_traceback_later()


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    """A headless Chromium context with a fresh profile; skips the module when Chromium is unavailable."""
    with contextlib.ExitStack() as stack:
        try:
            context = stack.enter_context(launched_chromium(tmp_path_factory.mktemp("chromium-profile")))
        except ChromiumUnavailable as why:
            pytest.skip(f"browser tests need Chromium: {why}")
        yield context


@pytest.fixture
def token():
    """A unique marker for the test's processes; survivors of a failed test are killed."""
    value = marker()
    yield value
    for leftover in processes_with(value):
        leftover.kill()


@pytest.fixture(scope="module")
def demo_prefix(tmp_path_factory):
    """A prefix with package demo (executables talker and listener, share/demo/config/params.yaml),
    on AMENT_PREFIX_PATH for the module."""
    prefix = make_prefix(tmp_path_factory.mktemp("prefix"), "demo",
                         {"talker": "#!/bin/sh\n", "listener": "#!/bin/sh\n"},
                         {"config/params.yaml": "/**:\n  ros__parameters:\n    gain: 2\n"})
    saved = os.environ.get("AMENT_PREFIX_PATH")
    os.environ["AMENT_PREFIX_PATH"] = f"{prefix}{os.pathsep}{saved or ''}"
    yield prefix
    os.environ["AMENT_PREFIX_PATH"] = saved or ""


@pytest.fixture
def launch_files_in_tmp_path(tmp_path, monkeypatch):
    """The parameter files a launch writes go to the test's own folder."""
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
