"""A check's Result (course_lib/checks/result.py): how its verdict reads."""

from __future__ import annotations

from pathlib import Path

import pytest

from course_lib.checks.result import Result, earned_points, points_text, round_points, verdict_text


def test_verdict_names_causes_first_then_their_consequences_then_what_passed():
    result = Result("brightness", "node", 1.0, 7.0, 5, items=[
        {"ok": True, "message": "a node runs", "weight": 0.0},
        {"ok": False, "message": "the subscription is reliable", "weight": 1.0},
        {"ok": True, "message": "publishes /brightness", "weight": 1.0},
        {"ok": False, "message": "bgr8 frames: no answer, because of the QoS", "weight": 1.0, "consequence": True},
    ])
    assert result.verdict_lines() == [
        "node: 1 of 7 points",
        "  ✘ the subscription is reliable",
        "    ↳ ✘ bgr8 frames: no answer, because of the QoS",
        "  ✔ a node runs",
        "  ✔ publishes /brightness",
    ]


@pytest.mark.parametrize("value, given", [(6.125, 6.13), (2.675, 2.68), (4.375, 4.38), (2.25, 2.25), (7, 7.0),
                                          (7 * 2 / 3, 4.67), (0.004, 0.0)])
def test_points_are_given_to_two_decimals_rounded_half_up(value, given):
    """What nbgrader's feedback page shows (two decimals) is what the grader gives and records."""
    assert round_points(value) == given


def test_a_check_earns_its_share_of_points_as_the_grader_rounds_them():
    """7 points, 7 of 8 items passed: 6.13, in the points and in the verdict alike."""
    items = [{"ok": True, "message": f"item {i}", "weight": 1.0} for i in range(7)]
    items.append({"ok": False, "message": "the last item", "weight": 1.0})
    points = earned_points(7, items, failed=False)
    assert points == 6.13 and points_text(points) == "6.13"
    assert Result("brightness", "node", points, 7.0, 5, items=items).verdict_lines()[0] == "node: 6.13 of 7 points"
    assert earned_points(7, items[-1:], failed=True) == 0.0 and earned_points(7, [], failed=False) == 0.0
    assert earned_points(7, items, failed=True) == 6.13  # an error after items passed keeps their points


def test_a_check_that_drew_from_its_seed_shows_it_and_how_to_reproduce_the_grade():
    """A check that read its rng (its scenes, frames, values) is reproduced with its seed; the header
    and the AUTOGRADER_SEED line say which. A check that drew nothing shows neither (the quiz's)."""
    from course_lib.checks.context import Context
    from course_lib.checks.registry import get_check

    ctx = Context(get_check("brightness", "values"), 41, Path("."), Path("."))
    assert not ctx.seeded
    ctx.rng.integers(0, 10)
    assert ctx.seeded
    drawn = verdict_text(Result("brightness", "values", 4.0, 4.0, 41, seeded=ctx.seeded), graded=True)
    assert drawn.startswith("[graded · seed 41] ") and drawn.endswith("(reproduce with AUTOGRADER_SEED=41)")
    not_drawn = verdict_text(Result("brightness", "values", 4.0, 4.0, 41, seeded=False), graded=False)
    assert not_drawn.startswith("[self-check] ") and "41" not in not_drawn
