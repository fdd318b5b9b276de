"""How a check runs from the notebook (course_lib/checks/runner.py): what a self-check says."""

from __future__ import annotations

from course_lib.checks import runner


def _brightness_module(tmp_path, monkeypatch, body: str) -> None:
    module = tmp_path / "ros2_ws" / "src" / "brightness" / "brightness" / "brightness_node.py"
    module.parent.mkdir(parents=True)
    (module.parent / "__init__.py").write_text("")
    module.write_text(body)
    monkeypatch.chdir(tmp_path)


def test_a_failed_selfcheck_prints_its_verdict_once_on_stderr_and_returns_nothing(tmp_path, monkeypatch, capsys):
    """Validate reads a cell's stderr as its error: a failed self-check writes its verdict there, once
    (not a second time on stdout), and the cell ends without a bare number."""
    _brightness_module(tmp_path, monkeypatch, "def average_brightness(image):\n    raise NotImplementedError()\n")
    assert runner.selfcheck("brightness", "values") is None
    out, err = capsys.readouterr()
    assert out == ""
    assert err.startswith("[self-check · seed 2024] average_brightness returns") and err.count("0 of 4 points") == 1
    assert err.count("✘ a colour (BGR) image: average_brightness failed: NotImplementedError") == 1
    assert "replace `raise NotImplementedError()` with your code" in err


def test_a_passed_selfcheck_prints_its_verdict_once_on_stdout(tmp_path, monkeypatch, capsys):
    _brightness_module(tmp_path, monkeypatch, "import numpy as np\n\n\ndef average_brightness(image):\n"
                                              "    return int(image.sum(dtype=np.uint64) // image.size)\n")
    assert runner.selfcheck("brightness", "values") is None
    out, err = capsys.readouterr()
    assert err == "" and out.count("values: 4 of 4 points") == 1 and "✘" not in out, out
