"""The brightness node check's throughput verdict (course_lib.checks.brightness_throughput.throughput_verdict):
processor time per frame against the yardstick's, never answers per second."""

from course_lib.checks.brightness_throughput import (
    THROUGHPUT_CPU_RATIO,
    THROUGHPUT_MIN_ANSWERS,
    THROUGHPUT_MIN_EVIDENCE_CPU,
    CpuCost,
    throughput_verdict,
)


def cost(seconds: float, frames: int) -> CpuCost:
    measured = CpuCost()
    measured.add(seconds, frames)
    return measured


YARDSTICK = cost(0.6, 60)  # 10 ms per frame


def test_a_node_as_cheap_as_the_yardstick_passes_however_few_frames_arrived_above_the_minimum():
    assert throughput_verdict(cost(0.6, 60), YARDSTICK) is True
    assert throughput_verdict(cost(0.1, THROUGHPUT_MIN_ANSWERS), YARDSTICK) is True


def test_a_node_that_costs_more_than_the_ratio_per_frame_fails():
    per_frame = 0.010 * THROUGHPUT_CPU_RATIO * 1.2
    assert throughput_verdict(cost(per_frame * 20, 20), YARDSTICK) is False
    assert throughput_verdict(cost(0.010 * THROUGHPUT_CPU_RATIO * 0.8 * 20, 20), YARDSTICK) is True


def test_a_slow_node_with_few_answers_fails_once_its_processor_time_shows_it():
    """A per-byte loop answers 2 frames in a burst and burns 2.5 s: no need for ten answers."""
    assert throughput_verdict(cost(2.5, 2), YARDSTICK) is False
    assert throughput_verdict(cost(2.5, 0), YARDSTICK) is False


def test_too_little_evidence_is_no_verdict():
    """Few frames arrived (a busy machine's transport), cheap: undecided, another burst."""
    assert throughput_verdict(cost(0.05, 3), YARDSTICK) is None
    assert throughput_verdict(cost(THROUGHPUT_MIN_EVIDENCE_CPU * 0.9, 0), YARDSTICK) is None
    assert throughput_verdict(cost(0.6, 60), cost(0.05, THROUGHPUT_MIN_ANSWERS - 1)) is None


def test_costs_add_up_over_bursts():
    total = cost(0.2, 4)
    total.add(0.3, 6)
    total.add(-0.01, 0)  # a process tree that lost a member reads less: never negative
    assert (total.seconds, total.frames) == (0.5, 10) and total.per_frame() == 0.05


def test_a_node_that_answers_but_never_right_is_told_to_fix_its_values_not_its_speed():
    """A node that publishes 0 for every frame has no right answer to count its speed by: the
    item fails, and says the values are wrong instead of "too slow ... a Python loop"."""
    from course_lib.checks.brightness_throughput import throughput_item

    passed, words = throughput_item(throughput_verdict(cost(0.54, 0), YARDSTICK), cost(0.54, 0), YARDSTICK, answered=30)
    assert not passed and "answered 30 frames of the bursts, none with the right brightness" in words, words
    assert "too slow" not in words and "Python loop" not in words, words
    # A node too slow to answer any frame in the bursts is slow, as before.
    passed, words = throughput_item(throughput_verdict(cost(2.5, 0), YARDSTICK), cost(2.5, 0), YARDSTICK, answered=0)
    assert not passed and words.startswith("too slow:"), words
    passed, words = throughput_item(True, cost(0.6, 60), YARDSTICK, answered=60)
    assert passed and "within" in words, words
