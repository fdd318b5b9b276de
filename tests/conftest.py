"""Fixtures shared by the test modules: a browser, a marker for a test's own processes, a
package for launch files."""

import contextlib
import os
import tempfile

import pytest
from browser_support import ChromiumUnavailable, launched_chromium
from launch_demo import make_prefix
from process_support import marker, processes_with

from autograder import answers

# The tests run graded checks (runner.execute(..., mode="graded")) as the grader does: the grader
# hands its checks the answer keys through the contract (course_lib.checks.answers).
os.environ.update(answers.environment())


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
