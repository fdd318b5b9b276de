"""Submit in a student's server, past the attempts the hub's grading service grades before the due
date (coursehub.limited_submit): refused with the reason, before anything reaches inbound/."""

from __future__ import annotations

import json

import pytest
from traitlets.config import Config

# nbgrader is imported by the tests, not at collection: each xdist worker collects every module.
COURSE = "course101"


def _submit(tmp_path, rules: dict, earlier: list[str]):
    """nbgrader's submit of `ann`'s brightness with the published `rules` and her `earlier` submission times."""
    from nbgrader.auth import Authenticator
    from nbgrader.coursedir import CourseDirectory

    from coursehub.limited_submit import LimitedSubmit

    inbound = tmp_path / "exchange" / COURSE / "inbound"
    inbound.mkdir(parents=True, exist_ok=True)
    inbound.chmod(0o777)
    for folder in (tmp_path / "work" / "brightness", tmp_path / "exchange" / COURSE / "outbound" / "brightness"):
        folder.mkdir(parents=True, exist_ok=True)  # the student's copy, and the release it is checked against
        (folder / "brightness.ipynb").write_text("{}")
    for stamp in earlier:
        (tmp_path / "cache" / COURSE / f"ann+brightness+{stamp}").mkdir(parents=True, exist_ok=True)
    (tmp_path / "rules.json").write_text(json.dumps(rules))
    c = Config()
    c.CourseDirectory.course_id, c.CourseDirectory.assignment_id = COURSE, "brightness"
    c.CourseDirectory.student_id = "ann"
    c.Exchange.root, c.Exchange.cache = str(tmp_path / "exchange"), str(tmp_path / "cache")
    c.Exchange.assignment_dir = str(tmp_path / "work")
    c.LimitedSubmit.rules_file = str(tmp_path / "rules.json")
    LimitedSubmit(coursedir=CourseDirectory(config=c), authenticator=Authenticator(config=c), config=c).start()
    return sorted(p.name.split("+")[0] for p in inbound.iterdir())


def test_a_submission_past_the_attempts_is_refused_with_the_reason(tmp_path):
    from nbgrader.exchange import ExchangeError

    rules = {"brightness": {"attempts": 2, "duedate": "2999-01-01 00:00:00 UTC"}}
    with pytest.raises(ExchangeError, match="brightness allows 2 graded submissions before the due date "
                                            r"\(2999-01-01 00:00 UTC\), and you have made 2.*\n"
                                            r"Your submissions and their scores: /services/grading/ on the hub"):
        _submit(tmp_path, rules, ["2026-03-01 10:00:00.000000 UTC", "2026-03-01 11:00:00.000000 UTC"])
    assert not list((tmp_path / "exchange" / COURSE / "inbound").iterdir())


@pytest.mark.parametrize("rules", [
    {"brightness": {"attempts": 3, "duedate": None}},                      # one left
    {"brightness": {"attempts": 2, "duedate": "2026-01-01 00:00:00 UTC"}},  # after the due date
    {"pubsub": {"attempts": 1, "duedate": None}},                          # not this assignment
])
def test_a_submission_within_the_rules_goes_to_inbound(tmp_path, rules):
    assert _submit(tmp_path, rules, ["2026-03-01 10:00:00.000000 UTC", "2026-03-01 11:00:00.000000 UTC"]) == ["ann"]
