"""Late penalties per assignment (a fraction per started day, capped), through nbgrader's plugin
interface; a typo in the settings and a malformed due date get errors that name the fix."""

from __future__ import annotations

import pytest
from support.imports import module_fixture
from traitlets.config import Config

late = module_fixture("autograder.term.late")  # it imports nbgrader
DAY = 24 * 3600.0


def _plugin(late, settings: dict, assignment: str):
    """The plugin as nbgrader's AssignLatePenalties creates it: its parent holds the assignment."""
    from nbgrader.preprocessors import AssignLatePenalties

    config = Config()
    for key, value in settings.items():
        setattr(config.LatePenalty, key, value)
    preprocessor = AssignLatePenalties(config=config)
    preprocessor.assignment_id = assignment
    return late.LatePenalty(parent=preprocessor)


@pytest.mark.parametrize("seconds, fraction", [(0, 0.0), (1, 0.1), (DAY, 0.1), (DAY + 1, 0.2),
                                               (10 * DAY, 0.5)])
def test_fraction_per_started_day_up_to_the_maximum(late, seconds, fraction):
    """0.1 per started day, never more than 0.5."""
    assert late.DAY == DAY
    assert late.fraction(0.1, 0.5, seconds) == pytest.approx(fraction)


def test_penalty_is_per_assignment(late):
    """The assignment named in per_day gets its rate; another falls back to nbgrader's method (none)."""
    settings = {"per_day": {"pubsub": 0.25}, "maximum": 1.0}
    assert _plugin(late, settings, "pubsub").late_submission_penalty("s", 8.0, 2 * DAY) == pytest.approx(4.0)
    assert _plugin(late, settings, "brightness").late_submission_penalty("s", 8.0, 2 * DAY) is None


def test_unknown_assignment_in_the_settings_is_an_error(late):
    """per_day naming no assignment of the course (a typo) is refused with the names to use."""
    config = Config()
    config.LatePenalty.per_day = {"pubsb": 0.1}
    with pytest.raises(ValueError, match="names pubsb, which is no assignment of the course .*pubsub"):
        late.check_settings(config, ["brightness", "pubsub"])
    late.check_settings(Config(), ["pubsub"])


def test_malformed_due_date_shows_the_form_to_use(late, tmp_path):
    """A due date that is no date is refused with an example, and nothing is written."""
    with pytest.raises(ValueError, match="not a date and time.*2025-03-14 23:59 Europe/Berlin"):
        late.set_duedate(tmp_path, "pubsub", "next friday-ish")
    assert not (tmp_path / "gradebook.db").exists()
