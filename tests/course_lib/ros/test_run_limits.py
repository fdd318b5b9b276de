"""Tests for course_lib.ros.run_limits: how long a wait may last live, under test and under grading."""

from course_lib.ros import run_limits


def test_time_limit_caps_only_under_test_or_grading(monkeypatch):
    """Live notebooks keep their durations; test and grading runs get separate, finite caps."""
    monkeypatch.delenv("COURSE_LIB_UNDER_TEST", raising=False)
    monkeypatch.delenv("COURSE_LIB_GRADING", raising=False)
    assert run_limits.time_limit(None) is None
    assert run_limits.time_limit(60.0) == 60.0
    monkeypatch.setenv("COURSE_LIB_UNDER_TEST", "1")
    assert run_limits.time_limit(None) == run_limits.TEST_TIME_LIMIT
    assert run_limits.time_limit(0.5) == 0.5
    monkeypatch.setenv("COURSE_LIB_UNDER_TEST", "0")
    monkeypatch.setenv("COURSE_LIB_GRADING", "1")
    assert run_limits.time_limit(None) == run_limits.GRADING_TIME_LIMIT
    assert run_limits.time_limit(60.0) == run_limits.GRADING_TIME_LIMIT


def test_an_answer_is_awaited_at_least_the_backstop_under_test_only(monkeypatch):
    """The answer of a server that was found ends its wait; under test a short limit would let a
    busy machine decide, so it is at least ANSWER_BACKSTOP there; live and under grading the wait
    keeps its own limit (a parameter client's 5 s and its hint, a grading's short waits)."""
    monkeypatch.delenv("COURSE_LIB_UNDER_TEST", raising=False)
    monkeypatch.delenv("COURSE_LIB_GRADING", raising=False)
    assert (run_limits.answer_limit(None), run_limits.answer_limit(5.0)) == (None, 5.0)
    monkeypatch.setenv("COURSE_LIB_UNDER_TEST", "1")
    assert run_limits.answer_limit(None) == run_limits.answer_limit(5.0) == run_limits.ANSWER_BACKSTOP
    assert run_limits.answer_limit(600.0) == 600.0
    monkeypatch.setenv("COURSE_LIB_GRADING", "1")
    assert run_limits.answer_limit(5.0) == 5.0
