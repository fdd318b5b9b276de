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
import importlib.abc
import importlib.util
import sys
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
    """Apply the fixes to rclpy in this process (once; later calls do nothing): now, when
    ``rclpy.action.client`` is imported already, else when it is imported. Importing it costs
    numpy's import, a fifth of a ``ros2`` command's processor time, and a process that never imports
    it has no action client to fix."""
    with _installing:
        if "rclpy.action.client" in sys.modules:
            _fix(sys.modules["rclpy.action.client"].ActionClient)
        elif not any(isinstance(finder, _FixOnImport) for finder in sys.meta_path):
            sys.meta_path.insert(0, _FixOnImport())


def _fix(action_client) -> None:
    global _installed
    if _installed:
        return
    _installed = True
    if "_lock" in action_client.__init__.__code__.co_names:  # this rclpy has the upstream fix
        return
    for name in LOCKED_METHODS:
        setattr(action_client, name, _holding_the_clients_lock(getattr(action_client, name)))


class _FixOnImport(importlib.abc.MetaPathFinder):
    """Finds ``rclpy.action.client`` as the other finders do, and fixes its ActionClient as soon as
    the module has run, before any code can make a client."""

    def find_spec(self, name, path=None, target=None):
        if name != "rclpy.action.client":
            return None
        sys.meta_path.remove(self)  # once; and the finders after it find the spec
        spec = importlib.util.find_spec(name)
        if spec is None or spec.loader is None:
            return spec
        run_module = spec.loader.exec_module

        def exec_module(module):
            run_module(module)
            with _installing:
                _fix(module.ActionClient)

        spec.loader.exec_module = exec_module  # a loader of this spec's own: the finders make one per spec
        return spec


def _holding_the_clients_lock(method):
    @functools.wraps(method)
    def locked(client, *args, **kwargs):
        lock = client.__dict__.get(_LOCK)
        if lock is None:  # the client's first call; setdefault is atomic, so two threads get one lock
            lock = client.__dict__.setdefault(_LOCK, threading.RLock())
        with lock:
            return method(client, *args, **kwargs)

    return locked
