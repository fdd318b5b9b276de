"""The script that runs first in the sandbox (autograder/sandbox/sandbox_entry.py): what it says when it
cannot do its job. What it sets up is tested through the sandbox, in tests/autograder/test_sandbox.py."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from autograder.sandbox import namespaces


@pytest.mark.skipif(namespaces.isolation() == "none", reason="no namespaces here (not root, no user namespaces)")
def test_a_mount_that_fails_names_its_target_and_runs_nothing(tmp_path):
    """A mount the sandbox cannot make (here: the interpreter's stage folder is missing) is reported
    with its target, and the command does not run."""
    expose, stage = tmp_path / "prefix", tmp_path / "no-stage"
    expose.mkdir()
    command = namespaces.sandbox_command(["touch", str(tmp_path / "ran")], [])
    done = subprocess.run(command, capture_output=True, text=True, timeout=60,
                          env={**os.environ, "AUTOGRADER_EXPOSE": str(expose), "AUTOGRADER_STAGE": str(stage),
                               "AUTOGRADER_BLOCKED": str(tmp_path / "closed")})
    assert done.returncode == 1, done.stderr
    assert f"autograder sandbox: [Errno 2] the sandbox could not mount {expose} on {stage}" in done.stderr
    assert not (tmp_path / "ran").exists()


def test_the_script_without_a_command_says_how_to_call_it():
    """``sandbox_entry.py`` without ``-- COMMAND`` prints its usage and exits 2 (before any mount)."""
    done = subprocess.run([sys.executable, "-I", "-S", str(namespaces.ENTRY), "/tmp"], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 2 and "usage: sandbox_entry.py HIDDEN_FOLDER... -- COMMAND" in done.stderr
