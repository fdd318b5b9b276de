"""The check harness (course_lib/checks/harness.py): how verdicts read, and what a self-check says."""

from __future__ import annotations

from course_lib.checks import harness


def test_verdict_names_causes_first_then_their_consequences_then_what_passed():
    result = harness.Result("brightness", "node", 1.0, 7.0, 5, items=[
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


def test_selfcheck_lists_what_to_fix_on_stderr_and_returns_nothing(tmp_path, monkeypatch, capsys):
    """Validate reads a cell's stderr as its error: a failed self-check puts its ✘ lines there, and
    the cell ends without a bare number."""
    module = tmp_path / "ros2_ws" / "src" / "brightness" / "brightness" / "brightness_node.py"
    module.parent.mkdir(parents=True)
    (module.parent / "__init__.py").write_text("")
    module.write_text("def average_brightness(image):\n    raise NotImplementedError()\n")
    monkeypatch.chdir(tmp_path)
    assert harness.selfcheck("brightness", "values") is None
    out, err = capsys.readouterr()
    assert "values: 0 of 4 points" in out
    assert err.startswith("Self-check values: 0 of 4 points. What to fix:\n")
    assert "✘ a colour (BGR) image: average_brightness failed: NotImplementedError" in err
    assert "replace `raise NotImplementedError()` with your code" in err
