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
import threading

#: Lines kept (and shown) per node; older ones are dropped from the view, not from /rosout.
MAX_LINES = 200

#: Said once per kernel, above the first log line shown.
EXPLANATION = ("ROS log lines of the nodes this cell added (they also go to /rosout and to a file under "
               "~/.ros/log; a terminal would print them as they come):")

#: The names rclpy gives the levels of rcl_interfaces/msg/Log (DEBUG=10 ... FATAL=50).
LEVELS = {10: "DEBUG", 20: "INFO", 30: "WARN", 40: "ERROR", 50: "FATAL"}

_lock = threading.Lock()
_views: dict[str, "_NodeLog"] = {}  # logger name -> where its lines go
_subscribed_node = None  # the tool node that holds the /rosout subscription
_explained = False


class _NodeLog:
    def __init__(self, widget):
        self.widget = widget
        self.lines: collections.deque[str] = collections.deque(maxlen=MAX_LINES)
        self.explain = False


def in_kernel() -> bool:
    """True inside a Jupyter kernel, where console output lands in whichever cell runs."""
    try:
        from IPython import get_ipython
    except ImportError:
        return False
    shell = get_ipython()
    return shell is not None and getattr(shell, "kernel", None) is not None


def init_arguments() -> list[str]:
    """Extra rclpy.init() arguments for the session: console logging off inside a kernel."""
    return ["--ros-args", "--disable-stdout-logs"] if in_kernel() else []


def attach(node) -> None:
    """Show the log lines of ``node`` under the current cell from now on (inside a kernel).

    A node added again under the same name (a re-run cell) moves its lines to the new cell.
    """
    if not in_kernel() or node.get_name().startswith("_") or \
            threading.current_thread() is not threading.main_thread():
        return
    import ipywidgets
    from IPython.display import display

    _subscribe()
    view = _NodeLog(ipywidgets.Output(layout={"max_height": "20em", "overflow": "auto"}))
    with _lock:
        _views[node.get_logger().name] = view
    display(view.widget)


def text(name: str) -> str:
    """The kept log lines of the node whose logger (or plain node name) is ``name``."""
    with _lock:
        view = _views.get(name) or _views.get(name.strip("/").replace("/", "."))
        return "\n".join(view.lines) if view is not None else ""


def _subscribe() -> None:
    """Read /rosout on the session's tool node, once per session."""
    global _subscribed_node
    from rcl_interfaces.msg import Log
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    from course_lib import session

    tool = session.tool_node()
    with _lock:
        if _subscribed_node is tool:
            return
        _subscribed_node = tool
    # As /rosout's publishers offer it: reliable, and the last lines kept for a late reader.
    qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
    tool.create_subscription(Log, "/rosout", _on_record, qos)


def format_record(record) -> str:
    """A /rosout record as the console prints it: ``[INFO] [1700000000.123456789] [talker]: text``."""
    level = LEVELS.get(record.level, str(record.level))
    return f"[{level}] [{record.stamp.sec}.{record.stamp.nanosec:09d}] [{record.name}]: {record.msg}"


def _on_record(record) -> None:
    global _explained
    with _lock:
        view = _views.get(record.name)
        if view is None:
            return
        if not _explained:
            view.explain = _explained = True
        view.lines.append(format_record(record))
        shown = ([EXPLANATION] if view.explain else []) + list(view.lines)
    view.widget.outputs = ({"output_type": "stream", "name": "stdout", "text": "\n".join(shown) + "\n"},)
