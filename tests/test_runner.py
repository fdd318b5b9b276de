"""How a check runs from the notebook (course_lib/checks/runner.py): what a self-check says."""

from __future__ import annotations

from course_lib.checks import runner


def test_selfcheck_lists_what_to_fix_on_stderr_and_returns_nothing(tmp_path, monkeypatch, capsys):
    """Validate reads a cell's stderr as its error: a failed self-check puts its ✘ lines there, and
    the cell ends without a bare number."""
    module = tmp_path / "ros2_ws" / "src" / "brightness" / "brightness" / "brightness_node.py"
    module.parent.mkdir(parents=True)
    (module.parent / "__init__.py").write_text("")
    module.write_text("def average_brightness(image):\n    raise NotImplementedError()\n")
    monkeypatch.chdir(tmp_path)
    assert runner.selfcheck("brightness", "values") is None
    out, err = capsys.readouterr()
    assert "values: 0 of 4 points" in out
    assert err.startswith("Self-check values: 0 of 4 points. What to fix:\n")
    assert "✘ a colour (BGR) image: average_brightness failed: NotImplementedError" in err
    assert "replace `raise NotImplementedError()` with your code" in err
