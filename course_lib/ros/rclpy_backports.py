"""Fixes that later rclpy releases have and the ros-jazzy wheels on PyPI lack, applied to this process.

rclpy issue #1123 (fixed upstream by pull request #1308, backported in 2025 by #1517 and #1519): an
ActionClient's ``send_goal_async``, ``get_result_async`` and ``cancel_goal_async`` send their
request and only then note its sequence number. When an executor spins the client in another
thread, as the course's session does (course_lib.ros.session), the answer can be taken in
between: rclpy then drops it with the warning "Ignoring unexpected goal response. There may be
more than one action server", and the future never completes. A busy machine makes the window
wide enough (``ros2 action send_goal`` failed so in a full test run). :func:`install` makes the
three requests and the executor's take of the answers hold one lock per client, as the upstream
fix does; with an rclpy that has the fix (its ActionClient makes a ``_lock``) it does nothing.
"""

from __future__ import annotations

import functools
import threading

#: The ActionClient methods that must not interleave: the executor's take of answers, and the
#: requests that note their sequence number after sending.
LOCKED_METHODS = ("take_data", "send_goal_async", "_cancel_goal_async", "_get_result_async")

#: The attribute of an ActionClient that holds its lock (made at its first locked call: clients
#: made before install() get one too).
_LOCK = "_course_lib_lock"

_installed = False
_installing = threading.Lock()


def install() -> None:
    """Apply the fixes to rclpy in this process (once; later calls do nothing)."""
    from rclpy.action.client import ActionClient

    global _installed
    with _installing:
        if _installed:
            return
        _installed = True
        if "_lock" in ActionClient.__init__.__code__.co_names:  # this rclpy has the upstream fix
            return
        for name in LOCKED_METHODS:
            setattr(ActionClient, name, _holding_the_clients_lock(getattr(ActionClient, name)))


def _holding_the_clients_lock(method):
    @functools.wraps(method)
    def locked(client, *args, **kwargs):
        lock = client.__dict__.get(_LOCK)
        if lock is None:  # the client's first call; setdefault is atomic, so two threads get one lock
            lock = client.__dict__.setdefault(_LOCK, threading.RLock())
        with lock:
            return method(client, *args, **kwargs)

    return locked
