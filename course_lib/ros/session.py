"""A ROS 2 session for a notebook: nodes spin in the background while cells keep running.

A notebook cell cannot call ``rclpy.spin(node)``: it would block the kernel. Instead the
session runs one executor in a background thread, and cells add nodes to it::

    from course_lib import session
    session.start()
    node = session.add_node(Talker())   # re-running this cell replaces the old Talker
    session.spin_for(2.0)               # let the callbacks run for two seconds
    session.stop()                      # or just restart the kernel

The session is safe to re-run cell by cell: ``start()`` twice does nothing the second time,
``start()`` after ``stop()`` starts again, and a node added under a name the session already
holds replaces the old node instead of running twice. The session stops itself when the
kernel exits.

Replacing happens when the new node is *created*, not when it is added: two nodes of one name in
one process confuse ROS (rcl warns "Publisher already registered for node name", and the graph
loses the new node's topics, which other processes then see under ``_NODE_NAME_UNKNOWN_``). So
while a session has run in this process, creating an rclpy ``Node`` under a name the session
holds first removes the old node. After ``stop()``, creating a node raises
:class:`SessionStopped`, which says to run ``session.start()`` (rclpy's own error would only say
that ``rclpy.init()`` was not called).

In plain ROS 2 the same is an executor spinning in a thread of its own::

    rclpy.init()
    executor = rclpy.executors.SingleThreadedExecutor()
    executor.add_node(node)
    threading.Thread(target=executor.spin, daemon=True).start()
    ...
    executor.shutdown(); node.destroy_node(); rclpy.try_shutdown()

A hidden node (its name: :func:`tool_node_name`) serves the introspection helpers of
:mod:`course_lib.ros.graph`; it is created on first use and never listed by :func:`nodes`.
"""

from __future__ import annotations

import atexit
import functools
import math
import os
import sys
import threading
import time
import traceback
from collections.abc import Callable

from course_lib import waiting
from course_lib.ros import node_logs, node_names, rclpy_backports, rosenv, teardown, type_support_lock
from course_lib.ros.run_limits import time_limit

#: How the name of every process's hidden helper node starts (a leading "_" hides it from node listings).
TOOL_NODE_PREFIX = "_course_tools"

# How long the background thread waits for work before it looks at its own state again.
_SPIN_PERIOD = 0.1
# How many callback errors the session keeps for errors().
_MAX_ERRORS = 20


class _State:
    """Everything one running session holds; replaced as a whole by start() after stop()."""

    def __init__(self, context, executor):
        self.context = context
        self.executor = executor
        self.thread: threading.Thread | None = None
        self.nodes: dict[str, object] = {}  # fully-qualified name -> node, in order added
        self.tool = None
        self.created_at: dict[str, float] = {}  # fully-qualified name -> time.time() of its last creation
        self.stopping = threading.Event()
        # Held by the background thread while it waits or runs a callback, so that a node is
        # destroyed only between two rounds of the executor.
        self.spin_lock = threading.Lock()


_lock = threading.RLock()
_state: _State | None = None
_errors: list[BaseException] = []
_reported: set[tuple[str, str]] = set()
_atexit_registered = False
_stopped = False  # stop() ran and no start() since: a new node gets SessionStopped


class SessionStopped(RuntimeError):
    """A node was created after session.stop() (a lesson's clean-up cell) shut ROS down."""

    def __init__(self):
        super().__init__("ROS is not running in this notebook: the clean-up cell (session.stop()) shut "
                         "it down. Run session.start() (or the notebook's first code cell) and the cells "
                         "that start the processes this cell needs, then run this cell again.")


def is_running() -> bool:
    """True while the background executor spins."""
    state = _state
    return (state is not None and state.thread is not None and state.thread.is_alive()
            and state.context.ok())


def domain_id() -> int | None:
    """The ROS domain the running session is on; None when no session runs."""
    state = _state
    return state.context.get_domain_id() if is_running() else None


def start(domain_id: int | None = None) -> None:
    """Start ROS and the background executor; does nothing if the session already runs.

    If rclpy was already initialised in this kernel (a cell called ``rclpy.init()``), the
    session uses that initialisation.

    Args:
        domain_id: ROS_DOMAIN_ID to talk on; None uses the ROS_DOMAIN_ID environment variable.

    Raises:
        ValueError: the session already runs on another domain id (call stop() first).
    """
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.signals import SignalHandlerOptions
    from rclpy.utilities import get_default_context

    global _state, _atexit_registered, _stopped
    if domain_id is not None:
        rosenv.check_domain_id(domain_id)
    with _lock:
        if is_running():
            _check_domain(_state.context, domain_id)
            return
        if _state is not None:  # a session whose thread or context died: clear it up first
            _end_thread(_state, timeout=1.0)
            _teardown()
        context = get_default_context()
        if context.ok():
            _check_domain(context, domain_id)
        else:
            # try_shutdown() swaps a shut-down default context for a fresh one, so init works
            # again after stop() or after a cell called rclpy.shutdown().
            rclpy.try_shutdown()
            # No rclpy signal handlers: in Jupyter, "interrupt kernel" must stop the cell,
            # not shut ROS down under the background executor.
            # In a Jupyter kernel, log lines are shown under the cell that added their node
            # (course_lib.ros.node_logs) instead of on the console, which is any cell that runs.
            rclpy.init(args=node_logs.init_arguments() or None, domain_id=domain_id,
                       signal_handler_options=SignalHandlerOptions.NO)
            context = get_default_context()
        state = _State(context, SingleThreadedExecutor(context=context))
        state.thread = threading.Thread(target=_spin, args=(state,), name="course_lib.ros.session",
                                        daemon=True)
        _state = state
        _stopped = False
        _install_node_hook()
        rclpy_backports.install()  # action clients spun by this thread while cells send goals
        type_support_lock.install()  # this thread and the cells' threads may check one type at once
        state.thread.start()
        if not _atexit_registered:
            atexit.register(stop)
            _atexit_registered = True


def _check_domain(context, domain_id: int | None) -> None:
    if domain_id is not None and context.get_domain_id() != domain_id:
        raise ValueError(f"The ROS session already runs on domain {context.get_domain_id()}, "
                         f"not {domain_id}: call session.stop() first, then "
                         f"session.start(domain_id={domain_id})")


def stop(timeout: float = 2.0) -> None:
    """Stop the background executor, destroy the session's nodes and shut ROS down.

    Safe to call when nothing runs. Nodes added before stop() cannot be added again after
    the next start(): create them again.

    Args:
        timeout: seconds to wait for a running callback to finish.
    """
    global _state, _stopped
    state = _state
    if state is not None:  # outside _lock: a callback that removes a node may be waiting for it
        _end_thread(state, timeout)
    with _lock:
        if _state is None:
            return
        if _state is not state:  # another thread started a session meanwhile
            _end_thread(_state, timeout)
        try:
            _teardown()
        finally:
            _state = None
            _stopped = True


def _teardown() -> None:
    """Destroy the nodes of the session, whose thread has ended (_end_thread), and shut ROS down."""
    import rclpy

    state = _state
    state.executor.shutdown(timeout_sec=0)
    for node in list(state.nodes.values()) + ([state.tool] if state.tool is not None else []):
        teardown.destroy_node(node)
    state.nodes.clear()
    state.tool = None
    if state.context is rclpy.utilities.get_default_context():
        rclpy.try_shutdown()
    else:  # someone replaced the default context meanwhile; shut down only our own
        state.context.try_shutdown()


def _end_thread(state: _State, timeout: float) -> None:
    """Ask the background thread to end and wait for it (at once when it has ended already)."""
    state.stopping.set()
    # The thread sees the flag within one spin period, or when its current callback returns.
    if state.thread is not None and state.thread is not threading.current_thread() and state.thread.is_alive():
        state.thread.join(timeout)
        if state.thread.is_alive():
            print(f"course_lib.ros.session: a callback was still running {timeout} s after stop(); "
                  "ROS is shut down anyway. Keep callbacks short (no sleep or long loops).",
                  file=sys.stderr)


def _spin(state: _State) -> None:
    """Body of the background thread: run callbacks until stop(), reporting their errors."""
    from rclpy.exceptions import InvalidHandle
    from rclpy.executors import ExternalShutdownException, ShutdownException

    while not state.stopping.is_set() and state.context.ok():
        try:
            with state.spin_lock:
                state.executor.spin_once(timeout_sec=_SPIN_PERIOD)
        except (ExternalShutdownException, ShutdownException):
            break
        except InvalidHandle:
            # A node removed between two rounds still had an entity in the last wait set.
            continue
        except Exception as error:  # a student's callback raised: report it and keep spinning
            if state.stopping.is_set() or not state.context.ok():
                break
            _report(error)


def _report(error: BaseException) -> None:
    _errors.append(error)
    del _errors[:-_MAX_ERRORS]
    key = (type(error).__name__, str(error))
    if key in _reported:
        return
    _reported.add(key)
    print("course_lib.ros.session: a callback raised an error; the other callbacks keep running "
          "(the same error again is not printed):", file=sys.stderr)
    traceback.print_exception(type(error), error, error.__traceback__, file=sys.stderr)


def errors() -> list[BaseException]:
    """The most recent errors raised by callbacks in the background executor, oldest first."""
    return list(_errors)


def clear_errors() -> None:
    """Forget the recorded callback errors (the next occurrence of each is printed again)."""
    _errors.clear()
    _reported.clear()


def _running_state() -> _State:
    start()
    return _state


def add_node(node):
    """Spin ``node`` in the background; a node of the same full name is replaced.

    Re-running a cell that creates and adds a node therefore leaves one node, not two: the
    old one is removed from the executor and destroyed. In a Jupyter kernel the node's log lines
    appear under this cell (course_lib.ros.node_logs).

    Args:
        node: an rclpy Node created after session.start() (or after rclpy.init()).

    Returns:
        The node, so that a cell can write ``node = session.add_node(MyNode())``.

    Raises:
        ValueError: the node was created before the last session.stop(), or was destroyed.
        TypeError: ``node`` is not an rclpy Node.
    """
    from rclpy.node import Node

    if not isinstance(node, Node):
        raise TypeError(f"session.add_node() takes an rclpy Node, got {type(node).__name__}: "
                        "create the node first, e.g. session.add_node(MyNode())")
    with _lock:
        state = _running_state()
        name = node_names.alive_name(node)
        if node.context is not state.context:
            raise ValueError(f"Node {name} belongs to another ROS context (it was made before "
                             "the session restarted, or with context=...): create it again "
                             "after session.start(), without a context argument")
        if name == "/" + tool_node_name():
            raise ValueError(f"The name {tool_node_name()} is reserved for the session's tool "
                             "node: give your node another name")
        old = state.nodes.get(name)
        if old is node:
            return node
        if old is not None:
            old = _remove(state, name)
        state.nodes[name] = node
        state.executor.add_node(node)
        since = state.created_at.pop(name, None)
    _destroy(state, old)
    node_logs.attach(node, tool_node, since)
    return node


def _install_node_hook() -> None:
    """Make rclpy's Node.__init__ call _before_node_created first (once per process)."""
    from rclpy.node import Node

    original = Node.__init__
    if getattr(original, "_course_lib_session_hook", False):
        return

    @functools.wraps(original)
    def __init__(self, node_name, *args, **kwargs):
        _before_node_created(node_name, kwargs.get("namespace"), kwargs.get("context"),
                             kwargs.get("cli_args"))
        original(self, node_name, *args, **kwargs)

    __init__._course_lib_session_hook = True
    Node.__init__ = __init__


def _before_node_created(node_name, namespace, context, cli_args) -> None:
    """Make room for a node about to be created: remove the session's node of that name.

    Raises:
        SessionStopped: the node would use the default context, which session.stop() shut down.
    """
    from rclpy.utilities import get_default_context

    with _lock:
        state = _state
        if state is None:
            if _stopped and context is None and not get_default_context().ok():
                raise SessionStopped()
            return
        if (context is not None and context is not state.context) or not isinstance(node_name, str):
            return
        name = node_names.expected_name(node_name, namespace, cli_args)
        state.created_at[name] = time.time()
        node_logs.expect(name, state.created_at[name])  # lines stamped from now on are the new node's
        old = _remove(state, name) if name in state.nodes else None
    _destroy(state, old)


def _remove(state: _State, name: str):
    """Take a node out of the session and the executor; returns it for _destroy.

    Called under _lock; _destroy must come after _lock is let go: it waits for the executor's
    thread, and a callback there (a live view's timer that removes its own node) may be waiting
    for _lock."""
    node_logs.deliver()  # the node's last log lines reach its cell before it goes
    node = state.nodes.pop(name)
    state.executor.remove_node(node)  # wakes the executor, which then lets go of spin_lock
    return node


def _destroy(state: _State, node) -> None:
    """Destroy a node _remove took out, between two rounds of the executor."""
    if node is None:
        return
    if threading.current_thread() is state.thread:  # a callback removes a node: spin_lock is ours
        teardown.destroy_node(node)
        return
    with state.spin_lock:
        teardown.destroy_node(node)


def remove_node(node_or_name) -> None:
    """Stop spinning a node and destroy it.

    Args:
        node_or_name: the node, its fully-qualified name ("/talker") or its plain name
            ("talker") when only one node has that name.

    Raises:
        ValueError: the session holds no such node; the message lists the ones it holds.
    """
    with _lock:
        state = _state
        held = state.nodes if state is not None else {}
        if isinstance(node_or_name, str):
            names = [n for n, node in held.items()
                     if n == node_or_name or node.get_name() == node_or_name]
        else:
            names = [n for n, node in held.items() if node is node_or_name]
        if len(names) != 1:
            problem = "no node" if not names else f"{len(names)} nodes"
            raise ValueError(f"The session holds {problem} matching {node_or_name!r}; it holds "
                             f"{sorted(held) or 'none'}: pass one of these full names")
        node = _remove(state, names[0])
    _destroy(state, node)


def nodes() -> list:
    """The nodes the session spins, in the order they were added (without the tool node)."""
    with _lock:
        return [] if _state is None else list(_state.nodes.values())


def tool_node_name() -> str:
    """The name of this process's tool node: the prefix and the process id.

    Every notebook kernel, `ros2` command and `ros2` daemon has one; with one name for all, `ros2
    node list -a` warned that nodes share a name."""
    return f"{TOOL_NODE_PREFIX}_{os.getpid()}"


def tool_node():
    """The session's hidden helper node for graph introspection, created on first use."""
    from rclpy.node import Node
    from rclpy.parameter import Parameter

    with _lock:
        state = _running_state()
        if state.tool is None:
            # Without parameter services and type description service: nobody asks a hidden
            # tool node for them, and the latter makes creating the node (and so every `ros2`
            # command) take twice as long.
            state.tool = Node(tool_node_name(), context=state.context, start_parameter_services=False,
                              parameter_overrides=[Parameter("start_type_description_service", value=False)])
            state.tool.created_at = time.monotonic()
            state.executor.add_node(state.tool)
        return state.tool


def wait_for(predicate: Callable[[], bool], timeout: float | None = 10.0,
             poll: float = 0.02) -> bool:
    """Wait until ``predicate()`` is true while the background executor keeps spinning.

    Args:
        predicate: a function of no arguments, e.g. ``lambda: len(received) >= 5``.
        timeout: seconds to wait at most; None waits as long as time_limit(None) allows
            (forever in a live notebook, a short bound under test or grading).
        poll: seconds between two calls of ``predicate``.

    Returns:
        True if the predicate became true, False if the time ran out first.

    Raises:
        KeyboardInterrupt: the cell was interrupted; the session keeps running.
    """
    if timeout is None:
        timeout = time_limit(None)
    start()

    def still_running():
        if not is_running():
            raise RuntimeError("The ROS session stopped while waiting (session.stop() or "
                               "rclpy.shutdown() was called): run session.start() again")

    # The background thread spins, so this thread only polls. Interrupting the kernel raises
    # KeyboardInterrupt here, in the cell's thread; the background thread holds no state of
    # this wait, so nothing needs undoing.
    return waiting.spin_until(predicate, math.inf if timeout is None else max(0.0, timeout), poll=poll,
                              between=still_running)


def spin_for(seconds: float | None = None) -> float:
    """Let the background callbacks run for a while, then return.

    Args:
        seconds: how long; None runs until the kernel is interrupted. Under test or grading
            the time is capped (see run_limits.time_limit), so a lesson cell never hangs a run.

    Returns:
        The seconds actually waited.

    Raises:
        KeyboardInterrupt: the cell was interrupted; the session keeps running.
    """
    seconds = time_limit(seconds)
    began = time.monotonic()
    wait_for(lambda: False, timeout=seconds, poll=0.1)
    return time.monotonic() - began
