"""`kill` (SIGTERM) ends a node's spin as Ctrl-C does: call :func:`end_spin_as_ctrl_c` before rclpy.init.

Why a node needs it (rclpy 7.1, Jazzy): rclpy's SIGTERM handler only posts a semaphore; a thread
of rclpy's own then triggers the executors' signal guard condition (which wakes ``rcl_wait``) and,
after that, shuts the contexts down (``rcl_shutdown``). An executor that wakes between the two sees
its context still up and nothing to do, and waits again (``Executor._wait_for_ready_callbacks``
loops until it has work); the shutdown that follows wakes nobody, so a node without timers waits
for ever. When the shutdown comes before the next wait set is made, making it fails instead ("the
given context is not valid"). Ctrl-C does not hang: rclpy passes SIGINT on to the handler it found,
Python's, whose KeyboardInterrupt ends spin as soon as the main thread runs again. rclpy passes
SIGTERM on the same way, so a Python handler for SIGTERM installed before ``rclpy.init`` runs when
the woken spin returns to Python: it waits until the context is down (destroying the node while
rclpy's thread shuts the context down can crash the process) and raises KeyboardInterrupt, which
main() catches as for Ctrl-C.
"""

from __future__ import annotations

import signal
import threading
import time

#: The longest the handler waits for rclpy's thread to shut the context down.
SHUTDOWN_WAIT = 1.0


def end_spin_as_ctrl_c() -> None:
    """Make SIGTERM end this process's spin as Ctrl-C does. Call it in main() before rclpy.init
    (which passes SIGTERM on to the handler it finds); in a thread other than the main thread,
    where Python cannot handle signals, it does nothing."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _end_as_ctrl_c)


def _context_is_up() -> bool:
    """The default context is initialized and not shut down. Not rclpy.ok(): its lock may be held by
    the main thread this handler interrupted."""
    from rclpy.utilities import get_default_context

    handle = get_default_context().handle
    try:
        return handle is not None and handle.ok()
    except Exception:  # destroyed: down
        return False


def _end_as_ctrl_c(signum, frame) -> None:
    deadline = time.monotonic() + SHUTDOWN_WAIT
    while _context_is_up() and time.monotonic() < deadline:
        time.sleep(0.001)
    raise KeyboardInterrupt
