"""A check's Result (course_lib/checks/result.py): how its verdict reads."""

from __future__ import annotations

from course_lib.checks.result import Result


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
