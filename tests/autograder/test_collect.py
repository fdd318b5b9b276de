"""Submissions from an LMS download (a zip with Blackboard's file names) into submitted/, with
the submission time kept in timestamp.txt; what nbgrader would not grade is reported at once."""

from __future__ import annotations

import datetime
import sys
import zipfile

import pytest
from support import course as course_support
from support.imports import module_fixture
from traitlets.config import Config

from autograder import config, nbgrader_cli
from autograder.term import roster

collect = module_fixture("autograder.term.collect")  # it imports nbgrader


@pytest.mark.parametrize("zone, hour", [("UTC", 9), ("Europe/Berlin", 8)])
def test_times_in_file_names_are_read_in_the_lms_time_zone(collect, zone, hour):
    """'2025-03-16-09-30-00' is 09:30 (nbgrader's parser reads 09:00), kept as naive UTC."""
    settings = Config()
    settings.LmsFileNames.timezone = zone
    info = collect.LmsFileNames(config=settings).collect(
        "/downloads/x_y/pubsub/extracted/pubsub_bob_attempt_2025-03-16-09-30-00_pubsub (1).ipynb")
    assert info["student_id"] == "bob" and info["file_id"] == "pubsub (1).ipynb"
    assert info["timestamp"] == datetime.datetime(2025, 3, 16, hour, 30)


def test_other_files_and_names_are_skipped(collect):
    """Blackboard's receipts (.txt) and names without an attempt are not collected."""
    plugin = collect.LmsFileNames()
    assert plugin.collect("/d/pubsub_bob_attempt_2025-03-16-09-30-00.txt") is None
    assert plugin.collect("/d/pubsub.ipynb") is None


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    root = course_support.released_course(tmp_path_factory, tmp_path_factory.mktemp("course"), ["pubsub"])
    (root / "roster.csv").write_text("id\nalice\ncarol\n")
    roster.import_roster(root, root / "roster.csv")
    return root


def _download(course, folder, names: list[str]):
    path = folder / "gradebook_pubsub.zip"
    notebook = (course / "release" / "pubsub" / "pubsub.ipynb").read_bytes()
    with zipfile.ZipFile(path, "w") as archive:
        for name in names:
            archive.writestr(name, notebook)
    return path


@pytest.mark.slow
def test_collect_puts_each_attempt_in_submitted_with_its_time(collect, course, tmp_path):
    """alice's two attempts: the later one is kept with its time; carol's renamed notebook and
    dave (not in the roster) are reported with what to do."""
    zip_path = _download(course, tmp_path, [
        "pubsub_alice_attempt_2025-03-14-20-15-00_pubsub.ipynb",
        "pubsub_alice_attempt_2025-03-15-08-00-00_pubsub.ipynb",
        "pubsub_carol_attempt_2025-03-14-21-00-00_pubsub (1).ipynb",
        "pubsub_dave_attempt_2025-03-14-22-00-00_pubsub.ipynb",
    ])
    lines = collect.collect(course, "pubsub", [zip_path])
    assert (course / "submitted" / "alice" / "pubsub" / "timestamp.txt").read_text() == "2025-03-15 08:00:00"
    assert (course / "submitted" / "alice" / "pubsub" / "pubsub.ipynb").is_file()
    assert "alice: pubsub.ipynb (submitted 2025-03-15 08:00:00 UTC)" in lines
    text = "\n".join(lines)
    assert "'pubsub (1).ipynb', not 'pubsub.ipynb'" in text and "mv " in text
    assert "dave is not in the roster" in text


@pytest.mark.slow
def test_collect_without_a_release_or_matching_names_says_what_to_do(collect, course, tmp_path):
    """An assignment not released, and a download whose names match nothing, give the fix."""
    with pytest.raises(ValueError, match="has not been released.*python -m autograder release"):
        collect.collect(course, "brightness", [tmp_path / "x.zip"])
    zip_path = _download(course, tmp_path, ["alice-pubsub.ipynb"])
    with pytest.raises(ValueError, match="do not match"):
        collect.collect(course, "pubsub", [zip_path])
    with pytest.raises(FileNotFoundError, match="does not exist"):
        collect.collect(course, "pubsub", [tmp_path / "missing.zip"])


def test_a_collector_plugin_beside_the_course_config_is_used_as_by_the_command(tmp_path):
    """nbgrader zip_collect, run in the course folder, finds a plugin module kept there; the grader's
    in-process zip_collect finds it too, and leaves sys.path as it was."""
    course = tmp_path / "course"
    course.mkdir()
    settings = config.write_config(course)
    settings.write_text(settings.read_text() + 'c.ZipCollectApp.collector_plugin = "own_names.OwnNames"\n')
    (course / "own_names.py").write_text(
        "from nbgrader.plugins import FileNameCollectorPlugin\n\n\n"
        "class OwnNames(FileNameCollectorPlugin):\n"
        "    def collect(self, submitted_file):\n"
        "        student, name = submitted_file.rsplit('/', 1)[1].split('--')\n"
        "        return {'student_id': student, 'file_id': name, 'timestamp': '2025-03-15 08:00:00'}\n")
    inbox = course / "downloaded" / "a" / "archive"
    inbox.mkdir(parents=True)
    (inbox / "erin--a.ipynb").write_text("{}")
    path_before = list(sys.path)
    log = nbgrader_cli.zip_collect(course, "a")
    assert "Using file collector: OwnNames" in log
    assert (course / "submitted" / "erin" / "a" / "a.ipynb").read_text() == "{}"
    assert (course / "submitted" / "erin" / "a" / "timestamp.txt").read_text() == "2025-03-15 08:00:00"
    assert sys.path == path_before
