"""Lesson 06's exercise check (course_lib.selfcheck.mobile_robot): ``nearest_obstacle(scan)`` passes
when right, and each usual mistake is told what is wrong, on the simulated robot's seeded scans."""

from __future__ import annotations

import math

import numpy as np
import pytest

from course_lib import selfcheck
from course_lib.selfcheck.mobile_robot import check_scans, nearest_reading


def right(scan):
    ranges = np.asarray(scan.ranges, dtype=float)
    valid = np.isfinite(ranges) & (ranges >= scan.range_min) & (ranges <= scan.range_max)
    if not valid.any():
        return None
    beam = np.flatnonzero(valid)[np.argmin(ranges[valid])]
    return float(ranges[beam]), scan.angle_min + beam * scan.angle_increment


def finite_only(scan):
    ranges = np.asarray(scan.ranges, dtype=float)
    finite = np.isfinite(ranges)
    if not finite.any():
        return None
    beam = np.flatnonzero(finite)[np.argmin(ranges[finite])]
    return float(ranges[beam]), scan.angle_min + beam * scan.angle_increment


def plain_min(scan):
    ranges = list(scan.ranges)
    return min(ranges), scan.angle_min + ranges.index(min(ranges)) * scan.angle_increment


def with_angle(change):
    def answer(scan):
        found = right(scan)
        if found is None:
            return None
        distance, angle = found
        beam = round((angle - scan.angle_min) / scan.angle_increment)
        return distance, change(scan, angle, beam)
    return answer


def never_none(scan):
    return right(scan) or (math.inf, 0.0)


def stub(scan):
    raise NotImplementedError


def test_a_right_answer_passes():
    verdict = selfcheck.nearest_obstacle_exercise(right)
    assert verdict, verdict
    assert "in all 6 scans" in str(verdict)


@pytest.mark.parametrize(("answer", "words"), [
    (finite_only, "below range_min"),
    (plain_min, "the distance is NaN"),
    (with_angle(lambda scan, angle, beam: -angle), "the sign is wrong"),
    (with_angle(lambda scan, angle, beam: beam * scan.angle_increment), "add angle_min"),
    (with_angle(lambda scan, angle, beam: float(beam)), "that is the beam's index"),
    (with_angle(lambda scan, angle, beam: math.degrees(angle)), "in degrees"),
    (with_angle(lambda scan, angle, beam: angle + scan.angle_increment), "one beam off"),
    (lambda scan: tuple(reversed(right(scan))), "returned (angle, distance)"),
    (never_none, "return None"),
    (lambda scan: "near", "return a pair of numbers"),
], ids=["zero-and-minus-inf", "nan", "sign", "no-angle-min", "index", "degrees", "off-by-one", "swapped",
        "no-none", "no-pair"])
def test_each_usual_mistake_is_named(answer, words):
    verdict = selfcheck.nearest_obstacle_exercise(answer)
    assert not verdict
    assert words in str(verdict), verdict


def test_a_stub_a_raise_and_no_function_say_what_to_do():
    assert "Not done yet" in str(selfcheck.nearest_obstacle_exercise(stub))
    assert "Not done yet" in str(selfcheck.nearest_obstacle_exercise(None))
    assert "Pass the function itself" in str(selfcheck.nearest_obstacle_exercise(right(check_scans()[0].scan)))
    raised = str(selfcheck.nearest_obstacle_exercise(lambda scan: scan.rangez))
    assert "raised AttributeError" in raised and "array(" not in raised  # the scan is not printed


def test_the_scans_are_the_same_every_time_and_cover_both_sides_and_behind():
    first, second = check_scans(), check_scans()
    for a, b in zip(first, second, strict=True):
        assert np.array_equal(a.scan.ranges, b.scan.ranges, equal_nan=True), a.words
    angles = [nearest_reading(each.scan)[1] for each in first[:3]]
    assert angles[0] > 0.2 and angles[1] < -0.2 and angles[2] > math.pi / 2  # left, right, behind on the left
    assert nearest_reading(first[-1].scan) is None
