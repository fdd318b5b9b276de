"""A line under a long-running cell that says what runs, the step it is at, and for how long.

A build, a self-check or an assignment check takes 5-30 s; without a word the student sees only
``[*]`` and cannot tell work from a hang. In a Jupyter kernel :class:`Progress` shows one line,
updated in place (``display(..., display_id=True)``, no ipywidgets needed) when the step changes
and every second::

    ⏳ colcon build … Starting >>> my_package (4 s)

and, at the end, what it took (``colcon build: finished after 6 s``). Outside a kernel (a terminal,
the grader's processes) and under grading it shows nothing: commands print their own output.

    with progress.Progress("colcon build") as shown:
        ...
        shown.step("Starting >>> my_package")

or, for a whole function, ``@progress.while_running("self-check: your publisher")``.
"""

from __future__ import annotations

import functools
import threading
import time

from course_lib import contract

#: Seconds between two updates of the time shown.
TICK = 1.0


def _in_kernel() -> bool:
    """True in a Jupyter kernel (IPython with a kernel), outside grading."""
    if contract.under_grading():
        return False
    try:
        from IPython import get_ipython
    except ImportError:
        return False
    shell = get_ipython()
    return shell is not None and getattr(shell, "kernel", None) is not None


class Progress:
    """The progress line of one long call; a context manager (the line shows while it runs).

    Args:
        what: what runs, in the student's words, e.g. "colcon build" or "check 'node'".
    """

    def __init__(self, what: str):
        self.what = what
        self.current = ""
        self._handle = None
        self._started = time.monotonic()
        self._lock = threading.Lock()
        self._stopped = threading.Event()
        self._ticker: threading.Thread | None = None

    def __enter__(self) -> Progress:
        self._started = time.monotonic()
        if _in_kernel():
            from IPython.display import display

            self._handle = display({"text/plain": self._text()}, raw=True, display_id=True)
            self._ticker = threading.Thread(target=self._tick, name="course_lib-progress", daemon=True)
            self._ticker.start()
        return self

    def step(self, text: str) -> None:
        """Say what the call does now (the line shows it until the next step)."""
        self.current = text.strip()
        self._show(self._text())

    def __exit__(self, kind, error, traceback) -> None:
        self._stopped.set()
        if self._ticker is not None:
            self._ticker.join(timeout=5)
        seconds = time.monotonic() - self._started
        if kind is None:
            self._show(f"{self.what}: finished after {seconds:.0f} s")
        else:
            self._show(f"{self.what}: stopped after {seconds:.0f} s ({kind.__name__})")

    def _text(self) -> str:
        step = f" … {self.current}" if self.current else " …"
        return f"⏳ {self.what}{step} ({time.monotonic() - self._started:.0f} s)"

    def _show(self, text: str) -> None:
        with self._lock:
            if self._handle is not None:
                self._handle.update({"text/plain": text}, raw=True)

    def _tick(self) -> None:
        while not self._stopped.wait(TICK):
            self._show(self._text())


def while_running(what: str):
    """Decorator: each call of the function shows a progress line saying `what` while it runs."""
    def decorate(function):
        @functools.wraps(function)
        def shown(*args, **kwargs):
            with Progress(what):
                return function(*args, **kwargs)
        return shown
    return decorate
