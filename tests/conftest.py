"""Fixtures shared by the browser test modules."""

import contextlib

import pytest

from browser_support import ChromiumUnavailable, launched_chromium


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    """A headless Chromium context with a fresh profile; skips the module when Chromium is unavailable."""
    with contextlib.ExitStack() as stack:
        try:
            context = stack.enter_context(launched_chromium(tmp_path_factory.mktemp("chromium-profile")))
        except ChromiumUnavailable as why:
            pytest.skip(f"browser tests need Chromium: {why}")
        yield context
