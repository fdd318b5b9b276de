"""The course's nbgrader_config.py: the autograder rewrites its header and keeps the instructor's
settings below the marker; a file it did not write is not overwritten."""

from __future__ import annotations

import pytest

from autograder import config


def test_new_file_has_the_header_and_commented_examples(tmp_path):
    text = config.write_config(tmp_path).read_text()
    assert text.startswith(config.CONFIG_HEADER) and "# c.LatePenalty.per_day" in text


def test_instructors_settings_are_kept_and_read(tmp_path):
    """Settings added below the marker survive a rewrite and reach the loaded configuration."""
    path = config.write_config(tmp_path)
    path.write_text(path.read_text().replace(config.CONFIG_HEADER, "# an older header\n" + config.MARKER + "\n")
                    + "c.LatePenalty.per_day = {'pubsub': 0.1}\n")
    config.write_config(tmp_path)
    assert path.read_text().startswith(config.CONFIG_HEADER)
    loaded = config.load(tmp_path)
    assert loaded.LatePenalty.per_day == {"pubsub": 0.1}
    assert loaded.CourseDirectory.root == str(tmp_path.resolve())


def test_file_of_an_earlier_version_is_replaced(tmp_path):
    (tmp_path / "nbgrader_config.py").write_text(config._OLD_TEMPLATE)
    assert config.MARKER in config.write_config(tmp_path).read_text()


def test_file_not_written_by_the_autograder_is_left_alone(tmp_path):
    """A hand-written nbgrader_config.py stops the command with the way out, and is unchanged."""
    path = tmp_path / "nbgrader_config.py"
    path.write_text("c = get_config()\nc.CourseDirectory.course_id = 'mine'\n")
    with pytest.raises(ValueError, match="not written by the autograder.*copy your settings below the line"):
        config.write_config(tmp_path)
    assert "course_id = 'mine'" in path.read_text()


def _rules(tmp_path, line: str):
    path = config.write_config(tmp_path)
    path.write_text(path.read_text() + line + "\n")
    return config.submit_rules(config.load(tmp_path), ["brightness", "pubsub"])


def test_grading_on_submission_is_set_per_assignment(tmp_path):
    rules = _rules(tmp_path, "c.GradeOnSubmit.assignments = "
                             "{'brightness': {'attempts': 3, 'reasons_before_due': False}, 'pubsub': {}}")
    assert rules == {"brightness": config.SubmitRules(attempts=3, reasons_before_due=False),
                     "pubsub": config.SubmitRules(attempts=None, reasons_before_due=True)}


def test_without_rules_no_assignment_is_graded_on_submission(tmp_path):
    assert _rules(tmp_path, "") == {}


@pytest.mark.parametrize("line, fix", [
    ("c.GradeOnSubmit.assignments = {'brightnes': {}}", "'brightnes' is no assignment of the course"),
    ("c.GradeOnSubmit.assignments = {'pubsub': {'tries': 2}}",
     "has tries: the settings are attempts, reasons_before_due"),
    ("c.GradeOnSubmit.assignments = {'pubsub': {'attempts': 0}}", "a whole number of at least 1"),
    ("c.GradeOnSubmit.assignments = {'pubsub': {'reasons_before_due': 'no'}}", "must be True or False"),
])
def test_a_mistake_in_the_rules_names_the_fix(tmp_path, line, fix):
    with pytest.raises(ValueError, match=fix):
        _rules(tmp_path, line)


def test_the_grading_service_grades_one_submission_at_a_time_unless_told(tmp_path):
    path = config.write_config(tmp_path)
    assert config.submit_workers(config.load(tmp_path)) == config.SUBMIT_WORKERS == 1
    path.write_text(path.read_text() + "c.GradeOnSubmit.workers = 2\n")
    assert config.submit_workers(config.load(tmp_path)) == 2


@pytest.mark.parametrize("value", ["0", "'2'", "True"])
def test_a_wrong_number_of_workers_names_the_fix(tmp_path, value):
    path = config.write_config(tmp_path)
    path.write_text(path.read_text() + f"c.GradeOnSubmit.workers = {value}\n")
    with pytest.raises(ValueError, match="GradeOnSubmit.workers .* give a whole number of at least 1"):
        config.submit_workers(config.load(tmp_path))
