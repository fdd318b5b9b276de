"""The grader's run of a notebook, with limits that the machine's load does not move.

nbclient stops a cell only at its wall-clock timeout. That timeout grows with the load factor
(course_lib.checks.validate.scaled), so that a right cell is never cut because the machine was
busy; but a cell that never ends then costs all of it: on a machine with two busy processes per
core, over a minute of one submission's grading.

WatchedExecute is nbgrader's Execute preprocessor that watches each ordinary cell while it runs
(not a graded test cell nor a build cell: validate.long_cell) and interrupts the kernel, as
nbclient does at a timeout, when the kernel and its child processes

- have used ``cpu_budget`` seconds of processor time in the cell: code that computes, judged by
  what the load does not change, or
- have run the cell ``idle_limit`` seconds and used less than IDLE_SHARE of a core over the last
  ``idle_window`` seconds: code that sleeps or blocks, which a quiet machine would not end sooner.

The cell's output then says which limit stopped it. nbclient's timeout stays the backstop, for a
kernel that ignores the interrupt.
"""

from __future__ import annotations

import asyncio
import collections
import threading
import time

import nbformat
from nbclient.util import run_sync
from nbgrader.preprocessors import Execute
from traitlets import Float

from course_lib.checks import validate
from course_lib.checks.context import MAX_LOAD_FACTOR
from course_lib.supervision.process_tree import cpu_seconds

#: Processor seconds an ordinary cell may use: importing rclpy, numpy and OpenCV and calling the
#: student's function on a few frames takes one or two; a loop that never ends uses them up.
CPU_BUDGET = 10.0

#: Wall seconds after which an ordinary cell that no longer computes is stopped.
IDLE_LIMIT = float(validate.CELL_TIMEOUT)

#: Seconds over which "no longer computes" is judged.
IDLE_WINDOW = 10.0

#: Below this share of one core the kernel does not compute: half of what a process gets at the
#: highest load the grader allows for (MAX_LOAD_FACTOR processes per core).
IDLE_SHARE = 1 / (2 * MAX_LOAD_FACTOR)

#: Seconds between two looks at the kernel's processor time.
POLL_SECONDS = 0.5


class CellWatch(threading.Thread):
    """Watches the processor time of process `pid` and its descendants during one cell, and calls
    `interrupt` once, naming the limit in `reason`, when the cell uses up its budget or idles."""

    def __init__(self, pid: int, interrupt, cpu_budget: float, idle_limit: float, idle_window: float):
        super().__init__(name="cell-watch", daemon=True)
        self.pid, self.interrupt = pid, interrupt
        self.cpu_budget, self.idle_limit, self.idle_window = cpu_budget, idle_limit, idle_window
        self.reason: str | None = None
        self._done = threading.Event()

    def run(self) -> None:
        started, base = time.monotonic(), cpu_seconds(self.pid)
        recent = collections.deque([(started, 0.0)])  # (time, processor seconds used in the cell)
        while not self._done.wait(POLL_SECONDS):
            now, used = time.monotonic(), cpu_seconds(self.pid) - base
            recent.append((now, used))
            while len(recent) > 2 and recent[1][0] <= now - self.idle_window:
                recent.popleft()
            since, used_then = recent[0]
            if used >= self.cpu_budget:
                self.reason = (f"it used {self.cpu_budget:g} s of processor time, the limit of a cell that is not "
                               "a graded test: a loop that never ends?")
            elif (now - started >= self.idle_limit and now - since >= min(self.idle_window, self.idle_limit)
                  and used - used_then < IDLE_SHARE * (now - since)):
                self.reason = (f"it ran {self.idle_limit:g} s and had stopped computing (it sleeps or waits "
                               "for something that does not come)")
            if self.reason:
                self.interrupt()
                return

    def stop(self) -> None:
        self._done.set()
        self.join()


class WatchedExecute(Execute):
    """nbgrader's Execute with a CellWatch on every ordinary cell (see the module docstring)."""

    cpu_budget = Float(CPU_BUDGET, help="processor seconds an ordinary cell may use").tag(config=True)
    idle_limit = Float(IDLE_LIMIT, help="wall seconds after which an idle ordinary cell is stopped").tag(config=True)
    idle_window = Float(IDLE_WINDOW, help="seconds over which idleness is judged").tag(config=True)

    _watch: CellWatch | None = None

    async def async_execute_cell(self, cell, cell_index, execution_count=None, store_history=True):
        self._watch = self._start_watch(cell)
        try:
            return await super().async_execute_cell(cell, cell_index, execution_count, store_history)
        finally:
            if self._watch is not None:  # on_cell_executed has stopped it, unless the cell raised
                self._watch.stop()
            self._watch = None

    # nbclient binds its synchronous execute_cell (which nbconvert's preprocessor calls) to its
    # own async_execute_cell: bound again here, to this one.
    execute_cell = run_sync(async_execute_cell)

    def _start_watch(self, cell) -> CellWatch | None:
        pid = getattr(getattr(self.km, "provisioner", None), "pid", None)
        if cell.cell_type != "code" or validate.long_cell(cell) or not pid:
            return None
        loop = asyncio.get_running_loop()

        def interrupt():
            asyncio.run_coroutine_threadsafe(self.km.interrupt_kernel(), loop)

        watch = CellWatch(pid, interrupt, self.cpu_budget, self.idle_limit, self.idle_window)
        watch.start()
        return watch

    def on_cell_executed(self, **kwargs):
        watch = self._watch
        if watch is not None:
            watch.stop()
            if watch.reason:
                cell = kwargs["cell"]
                message = f"The grader stopped this cell: {watch.reason}."
                self.log.error("Cell %s stopped: %s", kwargs.get("cell_index"), watch.reason)
                cell.outputs.append(nbformat.v4.new_output("stream", name="stderr", text=message + "\n"))
        return super().on_cell_executed(**kwargs)
