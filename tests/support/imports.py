"""Modules that tests import when they run, not when pytest collects them.

Every xdist worker collects every test module, so a module-level import is paid once per worker:
nbgrader's plugins and nbconvert cost 0.5-1.5 CPU-s each. A test module that needs such a module
declares a fixture for it instead::

    collect = module_fixture("autograder.term.collect")

    def test_something(collect):
        collect.collect(...)
"""

from __future__ import annotations

import importlib

import pytest


def module_fixture(name: str):
    """A module-scoped fixture that gives the module `name`, imported the first time a test asks."""

    @pytest.fixture(scope="module")
    def module():
        return importlib.import_module(name)

    module.__doc__ = f"{name}, imported when a test first needs it (see tests/support/imports.py)."
    return module
