"""Tests for course_lib.waiting: spin_until ends on the event, ends on the timeout, and is always bounded.

The polling tests run on a fake clock (its sleep moves time on), so they are exact and take no
real time; the spinning tests use real rclpy nodes and executors.
"""

import math

import pytest
import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor

from course_lib import waiting


class FakeClock:
    """time.monotonic and time.sleep of a clock that only moves when slept on."""

    def __init__(self):
        self.now = 100.0
        self.sleeps = []

    def monotonic(self):
        return self.now

    def sleep(self, seconds):
        self.sleeps.append(seconds)
        self.now += seconds


@pytest.fixture
def clock(monkeypatch):
    fake = FakeClock()
    monkeypatch.setattr(waiting, "time", fake)
    return fake


def counting(true_from: int):
    """A condition that is false for its first true_from - 1 checks, then true; .checks counts them."""
    def condition():
        condition.checks += 1
        return condition.checks >= true_from
    condition.checks = 0
    return condition


def test_ends_on_the_event_not_on_the_timeout(clock):
    condition = counting(true_from=3)
    assert waiting.spin_until(condition, timeout=10.0, poll=0.5) is True
    assert condition.checks == 3 and clock.sleeps == [0.5, 0.5]


def test_an_event_that_already_happened_returns_without_waiting(clock):
    assert waiting.spin_until(lambda: True, timeout=10.0) is True
    assert clock.sleeps == []


def test_ends_on_the_timeout_with_a_last_check(clock):
    condition = counting(true_from=10**9)
    assert waiting.spin_until(condition, timeout=1.0, poll=0.375) is False
    assert clock.now == 101.0, "it waited the whole timeout, and no longer"
    assert clock.sleeps == [0.375, 0.375, 0.25], "the last wait is cut to the time left"
    assert condition.checks == 5  # before each of the 3 waits, after the last one, and a last check


def test_the_condition_true_at_the_last_check_counts(clock):
    condition = counting(true_from=4)
    assert waiting.spin_until(condition, timeout=0.5, poll=0.25) is True
    assert clock.now == 100.5


@pytest.mark.parametrize("timeout", [None, -1.0, math.nan])
def test_every_wait_needs_a_timeout(timeout, clock):
    with pytest.raises(ValueError, match="timeout"):
        waiting.spin_until(lambda: False, timeout=timeout)


def test_an_unbounded_wait_must_be_asked_for_and_still_ends_on_the_event(clock):
    assert waiting.spin_until(counting(true_from=5), timeout=math.inf, poll=1.0) is True
    assert clock.sleeps == [1.0] * 4


def test_between_may_end_the_wait_early(clock):
    def stopped():
        raise RuntimeError("the thing waited on has stopped")

    with pytest.raises(RuntimeError, match="stopped"):
        waiting.spin_until(lambda: False, timeout=10.0, between=stopped)
    assert clock.sleeps == []


def test_bad_arguments_name_the_fix():
    with pytest.raises(ValueError, match="poll"):
        waiting.spin_until(lambda: True, timeout=1.0, poll=0)
    with pytest.raises(ValueError, match="not both"):
        waiting.spin_until(lambda: True, timeout=1.0, executor=object(), node=object())


@pytest.fixture
def ros_context(domain_id):
    context = Context()
    rclpy.init(context=context, domain_id=domain_id)
    try:
        yield context
    finally:
        context.try_shutdown()


def ticking_node(context, name):
    node = rclpy.create_node(name, context=context, enable_rosout=False, start_parameter_services=False)
    node.ticks = 0

    def tick():
        node.ticks += 1

    node.create_timer(0.01, tick)
    return node


def test_spinning_an_executor_runs_callbacks_until_the_event(ros_context):
    node = ticking_node(ros_context, "spin_until_executor")
    executor = SingleThreadedExecutor(context=ros_context)
    executor.add_node(node)
    try:
        assert waiting.spin_until(lambda: node.ticks >= 3, timeout=30.0, executor=executor) is True
        assert node.ticks == 3, "it stopped spinning at the event"
        assert waiting.spin_until(lambda: False, timeout=0.05, executor=executor) is False
    finally:
        executor.shutdown(timeout_sec=1.0)
        node.destroy_node()


def test_spinning_a_node_gives_it_an_executor_for_the_wait_only(ros_context):
    node = ticking_node(ros_context, "spin_until_node")
    try:
        assert waiting.spin_until(lambda: node.ticks >= 2, timeout=30.0, node=node) is True
        assert node.executor is None, "the node is free for another executor afterwards"
        spare = SingleThreadedExecutor(context=ros_context)
        spare.add_node(node)
        with pytest.raises(ValueError, match="pass executor="):
            waiting.spin_until(lambda: True, timeout=1.0, node=node)
        spare.shutdown(timeout_sec=1.0)
    finally:
        node.destroy_node()
