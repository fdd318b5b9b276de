"""Each notebook node's ROS log lines under the cell that added it, not in whichever cell runs next.

A node's ``get_logger().info(...)`` line goes to three places in ROS 2: the console (stderr), a
log file under ``~/.ros/log/`` and the topic ``/rosout``. In a notebook "the console" is the
output of whatever cell happens to run when the line is written: lines of a node that keeps
logging spill, in pink, into later cells. So in a Jupyter kernel the session starts ROS with
console logging off (``--ros-args --disable-stdout-logs``) and shows each line it reads back from
``/rosout`` under the cell that added the node (:func:`attach`, called by ``session.add_node``),
where it stays. :func:`text` returns the lines of one node, like ``ros2 topic echo /rosout``
filtered by name. The log file and ``/rosout`` are unchanged, so ``rqt_console`` and
``ros2 topic echo /rosout`` see every line.

Outside a kernel (a script, a test, ``ros2 run``) nothing changes: lines go to the console.
"""

from __future__ import annotations

import collections
import sys
import threading
import time

from course_lib import waiting

#: Lines kept (and shown) per node; older ones are dropped from the view, not from /rosout.
MAX_LINES = 200

#: Said once per kernel, above the first log line shown.
EXPLANATION = ("ROS log lines of the nodes this cell added (they also go to /rosout and to a file under "
               "~/.ros/log; a terminal would print them as they come):")

#: The names rclpy gives the levels of rcl_interfaces/msg/Log (DEBUG=10 ... FATAL=50).
LEVELS = {10: "DEBUG", 20: "INFO", 30: "WARN", 40: "ERROR", 50: "FATAL"}

_lock = threading.Lock()
_views: dict[str, list[_NodeLog]] = {}  # logger name -> the views of its nodes, oldest first
_subscribed_node = None  # the tool node that holds the /rosout subscription
_subscription = None  # that subscription
_explained = False


class _NodeLog:
    def __init__(self, since: float):
        self.widget = None  # set by attach(); lines logged before (in __init__) wait here
        self.since = since  # the node's creation (wall clock): its lines are stamped after it
        self.lines: collections.deque[str] = collections.deque(maxlen=MAX_LINES)
        self.explain = False

    def render(self) -> None:
        if self.widget is not None and self.lines:
            shown = ([EXPLANATION] if self.explain else []) + list(self.lines)
            self.widget.outputs = ({"output_type": "stream", "name": "stdout", "text": "\n".join(shown) + "\n"},)


def in_kernel() -> bool:
    """True inside a Jupyter kernel, where console output lands in whichever cell runs."""
    if "IPython" not in sys.modules:  # a kernel imports it before any cell runs; elsewhere it would
        return False                  # cost the process 60 ms of processor just to say no
    from IPython import get_ipython

    shell = get_ipython()
    return shell is not None and getattr(shell, "kernel", None) is not None


def kernel_hint(text: str) -> str:
    """`` (in a notebook: TEXT)`` inside a Jupyter kernel, else "": a hint that names a notebook
    helper follows an error only where that helper can be called (a terminal shows the real
    tool's words alone)."""
    return f" (in a notebook: {text})" if in_kernel() else ""


def init_arguments() -> list[str]:
    """Extra rclpy.init() arguments for the session: console logging off inside a kernel."""
    return ["--ros-args", "--disable-stdout-logs"] if in_kernel() else []


def logger_name(full_name: str) -> str:
    """The logger name of a node: "/robot1/talker" logs as "robot1.talker"."""
    return full_name.strip("/").replace("/", ".")


def expect(full_name: str, since: float) -> None:
    """A node of this name is being created now: lines stamped from ``since`` on are its own,
    also those its __init__ logs before attach() (an older node of the same name keeps its lines)."""
    if in_kernel():
        with _lock:
            _add_view(logger_name(full_name), since)


def _add_view(name: str, since: float) -> _NodeLog:
    view = _NodeLog(since)
    _views[name] = [v for v in _views.get(name, []) if v.since < since][-3:] + [view]
    return view


def attach(node, reader, since: float | None = None) -> None:
    """Show the log lines of ``node`` under the current cell (inside a kernel).

    Args:
        node: a node the session spins.
        reader: a function of no arguments giving the node that reads /rosout (the session's tool
            node), called only inside a kernel.
        since: the time given to expect() when the node was created; None: from now on.
    """
    if not in_kernel() or node.get_name().startswith("_") or \
            threading.current_thread() is not threading.main_thread():
        return
    import ipywidgets
    from IPython.display import display

    name = node.get_logger().name
    widget = ipywidgets.Output(layout={"max_height": "20em", "overflow": "auto"})
    with _lock:
        view = next((v for v in _views.get(name, ()) if since is not None and v.since == since), None)
        if view is None:
            view = _add_view(name, time.time())
        view.widget = widget
        view.render()
    display(widget)
    _subscribe(reader())


def text(name: str) -> str:
    """The kept log lines of the newest node whose logger (or plain node name) is ``name``."""
    with _lock:
        views = _views.get(name) or _views.get(name.strip("/").replace("/", "."))
        return "\n".join(views[-1].lines) if views else ""


def _subscribe(tool) -> None:
    """Read /rosout on the session's tool node, once per session."""
    global _subscribed_node
    from rcl_interfaces.msg import Log
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    with _lock:
        if _subscribed_node is tool:
            return
        _subscribed_node = tool
    # As /rosout's publishers offer it: reliable, and the last lines kept for a late reader.
    qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
    global _subscription
    _subscription = tool.create_subscription(Log, "/rosout", _on_record, qos)


def deliver(timeout: float = 2.0) -> None:
    """Call before destroying a node: waits (at most `timeout` s) until the /rosout reader has
    matched every /rosout writer the graph shows, then briefly for their kept lines. A writer
    hands its last lines to a late reader only while it exists, so a node replaced right after it
    logged (a cell run twice in quick succession) would otherwise lose its lines from the view."""
    subscription, tool = _subscription, _subscribed_node
    if subscription is None or tool is None or not in_kernel():
        return
    try:
        if not waiting.spin_until(lambda: subscription.get_publisher_count() >= tool.count_publishers("/rosout"),
                                  timeout, poll=0.02):
            return
    except Exception:  # the session is shutting down: nothing to wait for
        return
    time.sleep(0.1)  # the matched writers send what they kept


def format_record(record) -> str:
    """A /rosout record as the console prints it: ``[INFO] [1700000000.123456789] [talker]: text``."""
    level = LEVELS.get(record.level, str(record.level))
    return f"[{level}] [{record.stamp.sec}.{record.stamp.nanosec:09d}] [{record.name}]: {record.msg}"


def _stamp(record) -> float:
    return record.stamp.sec + record.stamp.nanosec * 1e-9


def _on_record(record) -> None:
    global _explained
    with _lock:
        views = [v for v in _views.get(record.name, ()) if v.since <= _stamp(record)]
        if not views:
            return
        view = views[-1]
        if not _explained:
            view.explain = _explained = True
        view.lines.append(format_record(record))
        view.render()
