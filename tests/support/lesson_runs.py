"""The lessons under nbmake: what the course checks in a lesson nbmake ran, beside nbmake's own checks.

nbmake (pyproject.toml's addopts) runs every lesson of notebooks/ top to bottom in a kernel, as a
student's CI would, and fails at the first cell that raises. conftest.py gives each run a ROS
domain of its own (:func:`own_domain`), keeps the notebook it
executed, writes it to artifacts/lessons/<lesson>.ipynb (open it to see what the run showed), and
fails the run with nbmake's own failure when :func:`problems` finds something a student would see:

- an image output that does not decode (JupyterLab would show a broken image);
- a lesson's long call whose progress line (course_lib.progress) did not end with what it took.

What only a browser can show (the text's rendering, the live views) is tests/browser/'s.
"""

from __future__ import annotations

import base64
import contextlib
from pathlib import Path

import cv2
import numpy as np

from course_lib import contract

LESSONS = contract.ROOT / "notebooks"

#: Where conftest.py writes each lesson as nbmake executed it.
EXECUTED = contract.ROOT / "artifacts" / "lessons"

#: What the lessons' long calls leave under their cells (course_lib.progress): the build of lesson
#: 00 and the self-check of lesson 01 each say how long they took.
PROGRESS_LINES = {"00_setup_and_workspace.ipynb": "colcon build in ros2_ws: finished after ",
                  "01_publisher_subscriber.ipynb": "self-check: running your publisher: finished after "}

#: The bitmap image types a lesson's outputs may hold (OpenCV decodes each).
BITMAPS = ("image/png", "image/jpeg")


def is_lesson(item) -> bool:
    """True for nbmake's run of a lesson (a notebook under notebooks/, not a lesson's scratch copy)."""
    return getattr(item, "nbmake", False) and item.path.parent == LESSONS


@contextlib.contextmanager
def own_domain():
    """A ROS domain reserved for one lesson's run: its kernel (started by nbmake in this block)
    inherits ROS_DOMAIN_ID. The run's own domain is shared by the tests of every worker: a lesson's
    nodes there showed up in another test's `ros2 node list` (lesson 02b's /dark_fraction)."""
    import os

    from course_lib.ros import rosenv

    before = os.environ.get("ROS_DOMAIN_ID")
    with rosenv.reserve_domain_id() as reservation:
        os.environ["ROS_DOMAIN_ID"] = str(reservation.domain_id)
        try:
            yield reservation.domain_id
        finally:
            if before is None:
                os.environ.pop("ROS_DOMAIN_ID", None)
            else:
                os.environ["ROS_DOMAIN_ID"] = before


@contextlib.contextmanager
def keeping_executed(item):
    """While nbmake runs `item`, keep the notebook it executes; at the end (passed or failed) write
    it to EXECUTED. Yields a list that holds the executed notebook once nbmake's run returned."""
    from nbmake import pytest_items

    kept = []
    plain = pytest_items.NotebookRun

    class KeepingRun(plain):
        def execute(self):
            result = super().execute()
            kept.append(result.nb)
            return result

    pytest_items.NotebookRun = KeepingRun
    try:
        yield kept
    finally:
        pytest_items.NotebookRun = plain
        if kept:
            import nbformat

            EXECUTED.mkdir(parents=True, exist_ok=True)
            nbformat.write(kept[0], str(EXECUTED / item.path.name))


def problems(lesson: str, notebook) -> list[str]:
    """What a student would see wrong in `notebook`, the lesson named `lesson` as nbmake executed it
    (no cell raised), each naming its cell."""
    found = []
    texts = []
    code_cells = [cell for cell in notebook.cells if cell.cell_type == "code"]
    for number, cell in enumerate(code_cells):
        for output in cell.get("outputs", []):
            data = output.get("data", {})
            texts.append(output.get("text", "") + data.get("text/plain", ""))
            for mime in BITMAPS:
                if mime in data and not _decodes(data[mime]):
                    found.append(f"code cell {number}: its {mime} output does not decode (a broken image)")
    wanted = PROGRESS_LINES.get(lesson)
    if wanted and not any(wanted in text for text in texts):
        found.append(f"no output says {wanted!r}: the long call's progress line did not end with its time")
    return found


def _decodes(encoded) -> bool:
    if isinstance(encoded, list):
        encoded = "".join(encoded)
    try:
        raw = base64.b64decode(encoded, validate=False)
    except ValueError:
        return False
    return cv2.imdecode(np.frombuffer(raw, np.uint8), cv2.IMREAD_UNCHANGED) is not None


def failure(lesson: Path, notebook, found: list[str]):
    """nbmake's own failure for `found` (its report shows the summary and the lines)."""
    from nbmake.nb_result import NotebookError, NotebookResult
    from nbmake.pytest_items import NotebookFailedException

    summary = f"{lesson.name} ran, but a student would see: {found[0]}"
    trace = "\n".join([f"{lesson.name} ran without an error; the course's checks of its outputs found:", *found,
                       f"(the executed notebook: {EXECUTED / lesson.name})"])
    return NotebookFailedException(NotebookResult(nb=notebook, error=NotebookError(
        summary=summary, trace=trace, failing_cell_index=0)))
