"""The grader's notebook run stops an ordinary cell by processor time or once it idles
(autograder.sandbox.cell_watch), in a real kernel; a graded test cell keeps its own timeout."""

import time

import nbformat
import pytest

from autograder.sandbox.cell_watch import WatchedExecute

pytestmark = pytest.mark.slow


def run(cells, **limits):
    """Run `cells` (source, nbgrader metadata or None) in a fresh kernel; the executed notebook
    and the seconds each cell took (between the starts of consecutive cells)."""
    nb = nbformat.v4.new_notebook()
    for source, meta in cells:
        cell = nbformat.v4.new_code_cell(source)
        if meta:
            cell.metadata["nbgrader"] = meta
        nb.cells.append(cell)
    nb.cells.append(nbformat.v4.new_code_cell("print('the run went on')"))
    executor = WatchedExecute(timeout=120, **limits)
    started = time.monotonic()
    executor.preprocess(nb, {"metadata": {"path": "."}})
    return nb, time.monotonic() - started


def said(cell) -> str:
    return "".join(output.get("text", "") + output.get("ename", "") for output in cell.outputs)


def test_a_cell_that_computes_forever_is_stopped_at_its_processor_budget():
    nb, _ = run([("while True:\n    pass", None)], cpu_budget=2.0, idle_limit=60.0)
    assert "The grader stopped this cell: it used 2 s of processor time" in said(nb.cells[0])
    assert "KeyboardInterrupt" in said(nb.cells[0])
    assert said(nb.cells[-1]) == "the run went on\n"


def test_a_cell_that_sleeps_is_stopped_once_it_has_idled_its_limit():
    nb, seconds = run([("import time\ntime.sleep(1000)", None)], cpu_budget=60.0, idle_limit=3.0, idle_window=2.0)
    assert "The grader stopped this cell: it ran 3 s and had stopped computing" in said(nb.cells[0])
    assert said(nb.cells[-1]) == "the run went on\n"
    assert seconds < 60  # not the cell's timeout (120 s): a backstop here, the event ends the wait


def test_right_cells_and_a_graded_test_cell_that_waits_are_not_stopped():
    graded = {"grade": True, "solution": False, "grade_id": "t", "points": 1, "locked": True}
    nb, _ = run([("x = sum(range(10**6))\nprint(x)", None),
                 ("import time\ntime.sleep(4)\nprint('waited')", graded)],
                cpu_budget=2.0, idle_limit=2.0, idle_window=1.0)
    assert said(nb.cells[0]) == "499999500000\n"
    assert said(nb.cells[1]) == "waited\n"
    assert said(nb.cells[-1]) == "the run went on\n"
