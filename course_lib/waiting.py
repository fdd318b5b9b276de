"""One bounded wait for the whole course: until something is true, or the time is up.

In plain rclpy this is the loop every ROS 2 program writes by hand::

    end = time.monotonic() + timeout
    while not condition() and time.monotonic() < end:
        executor.spin_once(timeout_sec=0.05)

:func:`spin_until` is that loop, written once: it always has a timeout, checks the condition
before the first wait (an event that has already happened returns at once), returns as soon as
the condition holds, and between two checks either spins an executor (callbacks run in this
thread), spins one node in an executor of its own, or only sleeps (when a background thread
spins, like the notebook session's).
"""

from __future__ import annotations

import time
from collections.abc import Callable

#: Seconds between two checks of the condition, unless the caller chooses otherwise.
POLL = 0.05


def spin_until(condition: Callable[[], object], timeout: float, *, executor=None, node=None,
               poll: float = POLL, between: Callable[[], None] | None = None) -> bool:
    """Wait until ``condition()`` is true, for at most ``timeout`` seconds.

    Args:
        condition: a function of no arguments, e.g. ``lambda: len(received) >= 5``.
        timeout: seconds to wait at most (required: every wait in the course is bounded).
            ``math.inf`` waits until the condition holds or Ctrl-C; only a live notebook or
            terminal command whose user asked for "until Ctrl-C" should pass it.
        executor: an rclpy executor to spin while waiting (``executor.spin_once``), for code
            that owns its executor, like the grader's probe.
        node: an rclpy node that is in no executor, to spin while waiting in an executor made
            for this wait (on the node's context); use ``executor`` when the node has one.
        poll: at most this many seconds between two checks of the condition.
        between: called between two checks (after the time check, before waiting); it may
            raise to end the wait early, e.g. when the thing waited on has stopped.

    Returns:
        True as soon as the condition holds; False when ``timeout`` passed first (the
        condition is checked one last time at the end).

    Raises:
        ValueError: no timeout (None) or a negative one, a poll that is not positive, both an
            executor and a node, or a node that already has an executor.
        KeyboardInterrupt: the cell or command was interrupted.
    """
    if timeout is None or not timeout >= 0:
        raise ValueError(f"spin_until needs a timeout in seconds (0 or more), not {timeout!r}: "
                         "every wait is bounded; pass math.inf only to wait until Ctrl-C")
    if not poll > 0:
        raise ValueError(f"poll must be a positive number of seconds, not {poll!r}")
    if executor is not None and node is not None:
        raise ValueError("Pass an executor or a node to spin, not both: an executor that has the node spins it")
    own = None
    if node is not None:
        from rclpy.executors import SingleThreadedExecutor

        if node.executor is not None:
            raise ValueError(f"Node {node.get_name()} already belongs to an executor: pass executor= (that one) "
                             "instead of node=, so that the wait does not take the node away from it")

        own = executor = SingleThreadedExecutor(context=node.context)
        own.add_node(node)
    try:
        end = time.monotonic() + timeout
        while not condition():
            left = end - time.monotonic()
            if left <= 0:
                return bool(condition())
            if between is not None:
                between()
            step = min(poll, left)
            if executor is None:
                time.sleep(step)
            else:
                executor.spin_once(timeout_sec=step)
        return True
    finally:
        if own is not None:
            node.executor = None  # removes the node from this wait's executor
            own.shutdown(timeout_sec=0)
