"""What Validate is doing while nbgrader runs an assignment: which cell, of how many, and what a
long cell does (a build, the graded checks).

nbgrader's Validate runs the whole notebook on the server (13-18 s for the brightness
assignment) while its button says only "Validating...". :class:`ValidateProgress` records, per
notebook, the step Validate is at (starting a kernel, running code cell n of m, reading the
results), fed by nbclient's ``on_cell_execute`` hook; :class:`ProgressHandler` serves it at
``GET course-lib/validate-progress?path=NOTEBOOK`` as JSON, and the lab extension beside this file
(``labextensions/@course-lib/validate-progress``) shows it on the button, once a second.
"""

from __future__ import annotations

import dataclasses
import json
import threading

from jupyter_server.base.handlers import JupyterHandler
from tornado import web

from course_lib.checks import validate

#: The URL of the progress, under the server's base URL (the lab extension asks it).
PROGRESS_URL = "course-lib/validate-progress"


@dataclasses.dataclass
class Step:
    """Where one validation is: ``cell`` of ``cells`` code cells (0 before the first), the first
    line of the cell that runs, and what it does when that takes long (:func:`doing`)."""

    cell: int
    cells: int
    line: str = ""
    doing: str = ""

    def as_json(self) -> dict:
        return {"running": True, "cell": self.cell, "cells": self.cells, "line": self.line, "doing": self.doing}


def doing(cell) -> str:
    """What a cell that may run long does, in the words the button shows; "" for any other cell
    (a build took 35-67 s, and "cell 11 of 14" all along said nothing of it)."""
    if validate.build_cell(cell):
        return "building the workspace (colcon)"
    if validate.graded_cell(cell):
        return "running the graded checks"
    return ""


def code_cells(notebook) -> list:
    """The cells nbclient runs: code cells with some source."""
    return [cell for cell in notebook.get("cells", []) if cell.get("cell_type") == "code"
            and "".join(cell.get("source", "")).strip()]


class ValidateProgress:
    """The step of each validation that runs, by the notebook's path as the browser names it."""

    def __init__(self):
        self._lock = threading.Lock()
        self._steps: dict[str, Step] = {}

    def start(self, path: str, notebook) -> None:
        """Validation of path began; notebook is its JSON (for the number of code cells)."""
        with self._lock:
            self._steps[path] = Step(0, len(code_cells(notebook)))

    def hook(self, path: str):
        """nbclient's ``on_cell_execute`` hook for the validation of path: counts the cells it runs."""

        def on_cell_execute(cell, cell_index):
            with self._lock:
                step = self._steps.get(path)
                if step is not None:
                    lines = cell.source.strip().splitlines()
                    self._steps[path] = Step(min(step.cell + 1, step.cells), step.cells, lines[0] if lines else "",
                                             doing(cell))

        return on_cell_execute

    def finish(self, path: str) -> None:
        with self._lock:
            self._steps.pop(path, None)

    def of(self, path: str) -> dict:
        """The step of path's validation as JSON: ``{"running": False}`` when none runs."""
        with self._lock:
            step = self._steps.get(path)
        return step.as_json() if step is not None else {"running": False}


#: The progress of this server's validations (one server, one record).
PROGRESS = ValidateProgress()


class ProgressHandler(JupyterHandler):
    """GET course-lib/validate-progress?path=NOTEBOOK: the step of that notebook's validation."""

    @web.authenticated
    def get(self):
        self.set_header("Content-Type", "application/json")
        self.finish(json.dumps(PROGRESS.of(self.get_argument("path"))))
