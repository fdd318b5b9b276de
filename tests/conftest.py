"""Fixtures shared by the test modules: a browser, a marker for a test's own processes."""

import contextlib

import pytest

from browser_support import ChromiumUnavailable, launched_chromium
from process_support import marker, processes_with


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
