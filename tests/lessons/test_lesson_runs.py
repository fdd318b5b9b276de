"""support.lesson_runs: the course's checks of a lesson as nbmake executed it (conftest.py applies them)."""

import base64

import cv2
import nbformat
import numpy as np
import pytest
from support import lesson_runs


def executed(outputs_per_cell):
    return nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("pass", outputs=outputs)
                                           for outputs in outputs_per_cell])


def image_output(mime, encoded):
    return nbformat.v4.new_output("display_data", data={mime: encoded, "text/plain": "<Figure>"})


def png():
    ok, encoded = cv2.imencode(".png", np.full((4, 6, 3), 200, np.uint8))
    assert ok
    return base64.b64encode(encoded.tobytes()).decode()


def test_a_lesson_whose_images_decode_passes_and_a_broken_image_is_named_by_its_cell():
    good = image_output("image/png", png())
    assert lesson_runs.problems("02_images_and_brightness.ipynb", executed([[good]])) == []
    broken = image_output("image/png", base64.b64encode(b"these bytes are no PNG").decode())
    assert lesson_runs.problems("02_images_and_brightness.ipynb", executed([[good], [], [broken]])) == [
        "code cell 2: its image/png output does not decode (a broken image)"]


@pytest.mark.parametrize("lesson", sorted(lesson_runs.PROGRESS_LINES))
def test_a_long_call_must_leave_its_progress_line_with_its_time(lesson):
    line = lesson_runs.PROGRESS_LINES[lesson] + "6 s"
    shown = nbformat.v4.new_output("display_data", data={"text/plain": line})
    assert lesson_runs.problems(lesson, executed([[], [shown]])) == []
    printed = nbformat.v4.new_output("stream", name="stdout", text="built\n")
    assert "progress line" in lesson_runs.problems(lesson, executed([[printed]]))[0]


def test_every_lesson_is_run_by_nbmake_and_judged_here():
    """The lessons nbmake collects are the lessons: pyproject's testpaths hold notebooks/, and no
    lesson is skipped or left out of is_lesson."""
    import tomllib

    from course_lib import contract

    options = tomllib.loads((contract.ROOT / "pyproject.toml").read_text())["tool"]["pytest"]["ini_options"]
    assert "notebooks" in options["testpaths"] and "--nbmake" in options["addopts"]
    assert sorted(path.name for path in lesson_runs.LESSONS.glob("*.ipynb")) != []
    assert set(lesson_runs.PROGRESS_LINES) <= {path.name for path in lesson_runs.LESSONS.glob("*.ipynb")}
