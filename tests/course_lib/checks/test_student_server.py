"""One student process serving many calls (course_lib/checks/student_server.py, through
Context.call as the checks use it): one import, a time limit per call, a hung function named
and not called again, answers kept across a crash."""

from __future__ import annotations

import numpy as np
import pytest

from course_lib.checks import context, student_server
from course_lib.checks.context import Context, StudentError
from course_lib.checks.registry import get_check
from course_lib.checks.student_server import ProcessorTime, StudentServers

MODULE = """
import os, time
def average_brightness(image):
    if image.size == 7:
        time.sleep(100)
    if image.size == 5:
        os._exit(3)
    if image.size == 11:  # computes 0.3 s, then answers
        start = time.process_time()
        while time.process_time() - start < 0.3:
            pass
    if image.size == 13:  # computes forever
        while True:
            pass
    return os.getpid()
"""


def _context(tmp_path, code: str, servers=None) -> Context:
    module = tmp_path / "ros2_ws" / "src" / "brightness" / "brightness" / "brightness_node.py"
    module.parent.mkdir(parents=True, exist_ok=True)
    (module.parent / "__init__.py").write_text("")
    module.write_text(code)
    out = tmp_path / "out"
    out.mkdir(exist_ok=True)
    return Context(get_check("brightness", "values"), 1, tmp_path, out, servers=servers)


def test_calls_share_one_process_and_a_hung_function_is_named_and_not_called_again(tmp_path):
    servers = StudentServers(60)
    ctx = _context(tmp_path, MODULE, servers)
    try:
        images = [np.zeros(3), np.zeros(4), np.zeros(7), np.zeros(3)]
        first, second, hung, later = ctx.call("average_brightness", [((i,), {}) for i in images], timeout=3,
                                              labels=["'one'", "'two'", "'the slow one'", "'four'"])
        assert first.ok and second.ok and first.value == second.value  # one process, imported once
        assert "average_brightness on 'the slow one' did not return within 3 s, waiting rather than computing" \
            in hung.error
        assert later.error.startswith("not run: average_brightness on 'the slow one' earlier did not return within 3 s")
        again = _context(tmp_path / "next", MODULE, servers)  # a later check of the same grading
        assert again.call("average_brightness", [((images[0],), {})])[0].error.startswith("not run: ")
    finally:
        ctx.close()
        servers.close()


def test_a_call_that_computes_is_judged_by_its_processor_time_not_the_clock(tmp_path, monkeypatch):
    """Processor time decides for code that computes: 0.3 s of it within a budget of 1 s answers
    (however long a busy machine makes that in wall time: the wall-clock backstop is far off), an
    endless loop is stopped when it has used the budget, and the feedback names the budget."""
    monkeypatch.setattr(context, "CALL_CPU_SECONDS", 1.0)
    ctx = _context(tmp_path, MODULE)
    try:
        computes, loops, later = ctx.call("average_brightness", [((np.zeros(n),), {}) for n in (11, 13, 3)],
                                          timeout=120, labels=["'the long one'", "'the endless one'", "'three'"])
        assert computes.ok, computes.error
        assert "average_brightness on 'the endless one' used 1 s of processor time without returning" in loops.error
        assert later.error.startswith("not run: average_brightness on 'the endless one' earlier used 1 s of processor")
    finally:
        ctx.close()


def test_a_call_that_waits_is_not_stopped_by_the_processor_budget(tmp_path, monkeypatch):
    """sleep() uses no processor time: only the wall-clock backstop ends it."""
    monkeypatch.setattr(context, "CALL_CPU_SECONDS", 0.2)
    ctx = _context(tmp_path, MODULE)
    try:
        (hung,) = ctx.call("average_brightness", [((np.zeros(7),), {})], timeout=3)
        assert "did not return within 3 s, waiting rather than computing" in hung.error
    finally:
        ctx.close()


def test_after_a_crash_the_next_call_runs_in_a_fresh_process(tmp_path):
    ctx = _context(tmp_path, MODULE)
    try:
        before, crash, after = ctx.call("average_brightness", [((np.zeros(n),), {}) for n in (3, 5, 3)])
        assert before.ok and after.ok and before.value != after.value
        assert "average_brightness on input 2 ended the process (exit code 3)" in crash.error
    finally:
        ctx.close()


@pytest.mark.parametrize("code, reason", [
    ("while True:\n    pass\n", "used 1 s of processor time without finishing"),
    ("import time\ntime.sleep(100)\n", "did not finish within 3 s, waiting rather than computing")])
def test_an_import_that_never_ends_is_marked_for_later_checks(tmp_path, monkeypatch, code, reason):
    """An import that computes forever ends at its processor budget, one that waits at the
    wall-clock backstop; either is marked, and later checks fail at once with the fix."""
    monkeypatch.setattr(context, "IMPORT_CPU_SECONDS", 1.0)
    monkeypatch.setattr(context, "IMPORT_TIMEOUT", 3.0 if "sleep" in code else 120.0)
    ctx = _context(tmp_path, code)
    try:
        try:
            ctx.call("average_brightness", [((np.zeros(3),), {})])
            raise AssertionError("the import did not fail")
        except StudentError as error:
            assert reason in str(error) and "put it in main()" in str(error)
        assert (tmp_path / context.IMPORT_HANG_MARK).exists()
        with pytest.raises(StudentError, match="did not finish in an earlier check"):
            ctx.require_module()
    finally:
        ctx.close()


class _Clock:
    """student_server's monotonic clock, moved on by the test: ProcessorTime's window passes at once."""

    def __init__(self):
        self.now = 1000.0

    def monotonic(self) -> float:
        return self.now


@pytest.fixture
def clock(monkeypatch):
    fake = _Clock()
    monkeypatch.setattr(student_server, "time", fake)
    return fake


class _Using:
    """A stand-in for a NodeProcess whose tree uses `share` of a core from now on (by `clock`)."""

    def __init__(self, share: float, clock: _Clock):
        self.share, self.clock, self.start = share, clock, clock.monotonic()

    def cpu_seconds(self) -> float:
        return self.share * (self.clock.monotonic() - self.start)


@pytest.mark.parametrize("share, waits", [(0.0, True), (0.01, True), (0.1, False), (1.0, False)])
def test_a_process_waits_when_it_uses_next_to_no_processor_time(share, waits, clock):
    """A process that gets a tenth of a core (ten busy processes per core) still computes; an idle
    rclpy node's hundredth of one is waiting. Nothing is said before a whole window was seen."""
    spent = ProcessorTime(_Using(share, clock), budget=None)
    assert not spent.waiting()
    clock.now += ProcessorTime.WAITING_WINDOW - 0.1
    assert not spent.waiting(), "less than a whole window seen"
    clock.now += 0.3
    assert spent.waiting() == waits and not spent.used_up()


class _Ended(_Using):
    """A stand-in for a NodeProcess that computed and has just ended: its tree's time reads 0."""

    def cpu_seconds(self) -> float:
        return 0.0 if self.clock.monotonic() - self.start > ProcessorTime.WAITING_WINDOW else super().cpu_seconds()


def test_a_process_that_has_just_ended_is_not_waiting(clock):
    """Its processor time reads 0 once it is gone, while its supervisor may not have said so yet: a
    self-check took a node that computed and then crashed for one waiting without an answer."""
    computed = _Ended(1.0, clock)
    clock.now += 0.5  # it has computed for a while when the wait on it starts
    spent = ProcessorTime(computed, budget=None)
    clock.now += ProcessorTime.WAITING_WINDOW
    assert not spent.waiting()
