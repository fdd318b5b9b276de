"""nbgrader's own autograde (the CLI in the course directory, the formgrader's Autograde button)
refuses with the course's command and changes nothing; under the course's grader it runs."""

from __future__ import annotations

import shutil
import subprocess
import sys

import pytest
from support import course as course_support
from support.imports import module_fixture

from autograder import config
from course_lib import contract

guard = module_fixture("autograder.sandbox.guard")  # it imports nbconvert


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    """pubsub released, and alice's submission graded (as the grader leaves it: an autograded
    notebook and her scores in the gradebook)."""
    from autograder.results import gradebook

    root = course_support.released_course(tmp_path_factory, tmp_path_factory.mktemp("course"), ["pubsub"])
    for folder in ("submitted", "autograded"):
        (root / folder / "alice" / "pubsub").mkdir(parents=True)
        shutil.copy(root / "release" / "pubsub" / "pubsub.ipynb", root / folder / "alice" / "pubsub")
    gradebook.record(root, "alice", "pubsub", {("pubsub", "check_publisher"): 5.0}, None, config.load(root))
    return root


def _state(course):
    return ((course / "autograded" / "alice" / "pubsub" / "pubsub.ipynb").read_bytes(),
            (course / "gradebook.db").read_bytes())


@pytest.mark.slow
def test_nbgrader_autograde_in_the_course_directory_refuses(course):
    """`nbgrader autograde pubsub --force` exits non-zero, names `python -m autograder grade`, and
    leaves the autograded notebook and the gradebook as they were."""
    before = _state(course)
    done = subprocess.run([sys.executable, "-m", "nbgrader", "autograde", "pubsub", "--force"], cwd=course,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode != 0
    assert f"python -m autograder grade {course.resolve()} --assignment pubsub" in done.stdout + done.stderr
    assert _state(course) == before


@pytest.mark.slow
def test_formgrader_autograde_button_refuses(course):
    """The formgrader's button (nbgrader's API in the server) fails with the command, changes nothing."""
    from nbgrader.apps.api import NbGraderAPI

    before = _state(course)
    result = NbGraderAPI(config=config.load(course)).autograde("pubsub", "alice")
    assert not result["success"]
    assert f"python -m autograder grade {course.resolve()} --student alice --assignment pubsub" in result["log"]
    assert _state(course) == before


def test_exporter_works_under_the_graders_flag(guard, monkeypatch):
    """With the flag the grader sets for its sandboxed run, nbgrader gets a working exporter."""
    monkeypatch.setenv(contract.CHECKS_OUTSIDE_ENV, "1")
    assert guard.GraderOnlyExporter().file_extension == ".ipynb"
    monkeypatch.delenv(contract.CHECKS_OUTSIDE_ENV)
    with pytest.raises(Exception, match="python -m autograder grade"):
        guard.GraderOnlyExporter()
