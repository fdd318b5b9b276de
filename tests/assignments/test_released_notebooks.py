"""The assignments as a student fetches them: "Run All" on an untouched release (nbgrader's
release of assignments/source/*) runs to its end and reaches every self-check, as nbclient runs it.

Cost: the course's release of all assignments is shared with the other grading tests
(support.course), then one kernel per notebook, about 25 CPU-s in all; marked slow.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import nbformat
import pytest
from support.course import ASSIGNMENTS, released_course
from support.imports import module_fixture

from course_lib import contract
from course_lib.checks import registry

nbclient = module_fixture("nbclient")


@pytest.fixture(scope="module")
def released(tmp_path_factory) -> Path:
    return released_course(tmp_path_factory, tmp_path_factory.mktemp("course"), list(ASSIGNMENTS))


def run_all(nbclient, released: Path, name: str, folder: Path) -> nbformat.NotebookNode:
    """The untouched released notebook `name`, run top to bottom in `folder` (as Run All does: it
    stops at the first cell that raises, nbclient's CellExecutionError)."""
    shutil.copytree(released / "release" / name, folder)
    nb = nbformat.read(folder / f"{name}.ipynb", as_version=4)
    nbclient.NotebookClient(nb, timeout=300, startup_timeout=120, kernel_name="python3",
                            resources={"metadata": {"path": str(folder)}}).execute()
    return nb


def stream_text(cell) -> str:
    return "".join(output.get("text", "") for output in cell.get("outputs", []) if output.output_type == "stream")


def check_cells(nb) -> dict[str, dict]:
    return {cell.metadata["nbgrader"]["grade_id"]: cell for cell in nb.cells
            if cell.metadata.get("nbgrader", {}).get("grade_id", "").startswith("check_")}


@pytest.mark.slow  # nbgrader's release and a kernel per notebook
@pytest.mark.parametrize("name", [name for name in ASSIGNMENTS if name != "brightness"])
def test_run_all_on_an_untouched_release_reaches_every_check(nbclient, released, tmp_path, monkeypatch, name):
    """No cell before a check raises on the release's stubs (the "try it" cells say "Not done
    yet" instead). Run as graded, which skips the build cell and the self-checks' runs (the
    brightness release is run in full below)."""
    monkeypatch.setenv(contract.GRADING_ENV, "1")
    nb = run_all(nbclient, released, name, tmp_path / name)
    cells = check_cells(nb)
    assert set(cells) == {f"check_{check}" for check in registry.checks_of(name)}
    assert all(cell.get("execution_count") for cell in cells.values())
    for cell in nb.cells:
        if "except NotImplementedError" in cell.source:
            assert stream_text(cell).startswith("Not done yet:"), cell.source


@pytest.mark.slow  # nbgrader's release, a kernel, a colcon build and the self-checks' runs
def test_run_all_on_the_untouched_brightness_release_shows_every_self_checks_verdict(
        nbclient, released, tmp_path):
    """The issue's case: "Try your function" says "Not done yet", and both self-checks run and
    say what is missing (no point earned)."""
    nb = run_all(nbclient, released, "brightness", tmp_path / "brightness")
    (tried,) = [cell for cell in nb.cells if "print(average_brightness(grey))" in cell.source]
    assert stream_text(tried).startswith("Not done yet: average_brightness still raises NotImplementedError")
    for grade_id, cell in check_cells(nb).items():
        text = stream_text(cell)
        assert f"{grade_id.removeprefix('check_')}: 0 of" in text and "NotImplementedError" in text, text
