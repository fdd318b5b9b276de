"""Live views of topics in a notebook: a picture that follows an image topic and a plot of numbers.

``image_view`` does in a notebook what ``rqt_image_view`` does in a window: it shows the latest
frame of a ``sensor_msgs/Image`` (or ``CompressedImage``) topic and keeps replacing it while
frames arrive. ``plot`` does what ``rqt_plot`` does: it draws numbers from topics against time,
named the way rqt_plot names them, a topic followed by the path of a field::

    from course_lib import live
    live.image_view("/image")                       # like: ros2 run rqt_image_view rqt_image_view /image
    live.plot("/brightness")                        # a std_msgs number: its data field
    live.plot("/odom/pose/pose/position/x", "/odom/pose/pose/position/y")   # like rqt_plot

Both are ipywidgets shown as the cell's output. They subscribe through the notebook's ROS
session (:mod:`course_lib.ros.session`), each with a hidden node of its own, and redraw at most
``max_rate`` times a second however fast messages come (frames are sent to the browser as
JPEG). ``view.stop()`` stops one; re-running the cell replaces the old view of the same topics;
``session.stop()`` and the kernel's end stop them all. Under test or grading a view stops by
itself after LIMITED_UPDATES redraws or LIMITED_SECONDS seconds.
"""

from __future__ import annotations

import collections
import re
import threading
import time

import cv2
import ipywidgets
import numpy as np

from course_lib import waiting
from course_lib.imaging import images
from course_lib.notebook.field_paths import resolve_field_path
from course_lib.ros import discovery, graph, message_yaml, rosenv, session

#: Redraws, and seconds after its creation, after which a view stops by itself under test or grading.
LIMITED_UPDATES = 20
LIMITED_SECONDS = 10.0

#: Frames wider than this are shrunk before they are sent to the browser (as rqt_image_view fits
#: its window); the ROS message itself is untouched.
MAX_WIDTH = 960
JPEG_QUALITY = 80

#: The types an image view accepts, by the name the graph reports.
IMAGE_TYPES = ("sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage")

_views: dict[str, _View] = {}  # hidden node name -> the view that holds it
_views_lock = threading.Lock()


class _View:
    """What image and plot views share: a hidden session node, a redraw timer, the bounds, stop()."""

    def __init__(self, node_name: str, max_rate: float, seconds: float | None, updates: int | None):
        from rclpy.node import Node

        if max_rate <= 0:
            raise ValueError(f"max_rate must be above 0 redraws per second, not {max_rate}; for example 10")
        limited = rosenv.under_test() or rosenv.under_grading()
        self.updates = 0
        self.max_updates = updates if updates is not None else (LIMITED_UPDATES if limited else None)
        self.seconds = seconds if seconds is not None else (LIMITED_SECONDS if limited else None)
        self.stopped = False
        self.stop_reason = ""
        self._started = time.monotonic()
        self._lock = threading.Lock()  # between the session's thread and the cell's
        self.status = ipywidgets.Label()
        self.node_name = node_name
        with _views_lock:
            old = _views.pop(node_name, None)
        if old is not None:
            old.stop("replaced by a new view")
        session.start()
        self.node = session.add_node(Node(node_name, start_parameter_services=False))
        with _views_lock:
            _views[node_name] = self
        self._timer = self.node.create_timer(1.0 / max_rate, self._tick)

    def _tick(self) -> None:
        """The redraw timer: draw what arrived since the last redraw, then check the bounds."""
        if self.stopped:
            return
        if self._redraw():
            self.updates += 1
        if self.max_updates is not None and self.updates >= self.max_updates:
            self.stop(f"stopped after {self.updates} updates")
        elif self.seconds is not None and time.monotonic() - self._started >= self.seconds:
            self.stop(f"stopped after {self.seconds:g} s")

    def _redraw(self) -> bool:
        raise NotImplementedError

    def stop(self, reason: str = "stopped") -> None:
        """Stop updating (the picture or plot stays as it is) and remove the view's node."""
        with self._lock:
            if self.stopped:
                return
            self.stopped = True
            self.stop_reason = reason
        forget_view(self, _views, _views_lock)
        self._show_status()

    def _show_status(self) -> None:
        raise NotImplementedError

    def _repr_mimebundle_(self, **kwargs):
        return self.widget._repr_mimebundle_(**kwargs)


def forget_view(view, views: dict, lock: threading.Lock) -> None:
    """A stopped view out of its registry `views` (name of its hidden node -> view; unless a view
    made since holds that name) and its node out of the session."""
    with lock:
        if views.get(view.node_name) is view:
            del views[view.node_name]
    try:
        session.remove_node(view.node)
    except ValueError:  # the session stopped (or replaced the node) already
        pass


def _hidden_name(kind: str, topics) -> str:
    """A hidden node name (leading "_") for a view of these topics: one view per kind and topics."""
    return "_live_" + kind + "_" + "_".join(re.sub(r"\W", "_", topic.strip("/")) for topic in topics)


# --- rqt_image_view ------------------------------------------------------------------------

class ImageView(_View):
    """The latest frame of an image topic, redrawn while frames arrive (see image_view).

    Attributes:
        widget: the ipywidgets box shown in the notebook (a status line and the picture).
        image: the ipywidgets.Image whose value is the latest frame as JPEG (or PNG) bytes.
        frames: frames received so far; updates: frames drawn so far.
        topic: the resolved topic name; msg_type: its message class.
    """

    def __init__(self, topic: str, *, msg_type=None, max_rate: float = 10.0, max_width: int = MAX_WIDTH,
                 seconds: float | None = None, updates: int | None = None, timeout: float = 5.0):
        from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy

        tool = discovery._graph_node()
        self.topic = tool.resolve_topic_name(topic)
        self.msg_type = _image_class(tool, self.topic, msg_type, timeout)
        self.max_width = int(max_width)
        self.frames = 0
        self.error = ""
        self._latest = None
        self._drawn = None
        self._arrivals: collections.deque[float] = collections.deque(maxlen=30)
        self.image = ipywidgets.Image(format="jpeg")
        super().__init__(_hidden_name("image", [self.topic]), max_rate, seconds, updates)
        self.widget = ipywidgets.VBox([self.status, self.image])
        self._show_status()
        # Best effort with depth 1: every publisher can serve it, and only the newest frame matters.
        qos = QoSProfile(depth=1, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.BEST_EFFORT)
        self.node.create_subscription(self.msg_type, self.topic, self._on_frame, qos)

    def _on_frame(self, msg) -> None:
        self._latest = msg
        self.frames += 1
        self._arrivals.append(time.monotonic())

    def _redraw(self) -> bool:
        msg = self._latest
        if msg is None or msg is self._drawn:
            return False
        self._drawn = msg
        try:
            data, format_ = frame_for_browser(msg, self.max_width)
        except ValueError as error:
            self.error = str(error)
            self._show_status()
            return False
        self.error = ""
        self.image.format = format_
        self.image.value = data
        self._show_status()
        return True

    def _show_status(self) -> None:
        msg = self._drawn
        parts = [self.topic]
        if msg is not None and hasattr(msg, "encoding"):
            parts.append(f"{msg.width}x{msg.height} {msg.encoding}")
        elif msg is not None:
            parts.append(f"{msg.format or 'compressed'}")
        if len(self._arrivals) >= 2 and self._arrivals[-1] > self._arrivals[0]:
            parts.append(f"{(len(self._arrivals) - 1) / (self._arrivals[-1] - self._arrivals[0]):.1f} Hz")
        if msg is None and not self.stopped:
            parts.append("waiting for frames")
        if self.error:
            parts.append("cannot show this frame: " + self.error)
        if self.stopped:
            parts.append(self.stop_reason)
        self.status.value = " · ".join(parts)


def image_view(topic: str = "/image", **options) -> ImageView:
    """Show an image topic as a picture that follows its frames: what ``rqt_image_view`` does.

    Args:
        topic: a sensor_msgs/msg/Image or sensor_msgs/msg/CompressedImage topic.
        msg_type: the message class or type name; None takes it from the graph (and assumes
            Image when the topic is not there yet).
        max_rate: redraws per second at most (10); frames in between are skipped, not queued.
        max_width: frames wider than this (pixels) are shrunk for the browser.
        seconds, updates: stop after this long or this many redraws; None runs until stop(),
            except under test or grading (LIMITED_SECONDS, LIMITED_UPDATES).
        timeout: seconds to wait for the topic to appear in the graph to learn its type.

    Returns:
        The view; as the last line of a cell it shows itself. Call ``.stop()`` to end it.

    Raises:
        ValueError: the topic carries another type than an image (the message names it).
    """
    return ImageView(topic, **options)


def _image_class(tool, topic: str, msg_type, timeout: float):
    if msg_type is None:
        kinds = []

        def known():
            kinds[:] = [k for name, ks in tool.get_topic_names_and_types() if name == topic for k in ks]
            return bool(kinds)

        waiting.spin_until(known, timeout)
        msg_type = kinds[0] if len(kinds) == 1 else IMAGE_TYPES[0]
        if len(kinds) > 1:
            raise ValueError(f"Topic {topic} carries several types {kinds}: pass msg_type= to choose one")
    cls = message_yaml.message_class(msg_type) if isinstance(msg_type, str) else msg_type
    name = f"{cls.__module__.split('.')[0]}/msg/{cls.__name__}"
    if name not in IMAGE_TYPES:
        raise ValueError(f"Topic {topic} carries {name}, not an image: image_view shows "
                         f"{' or '.join(IMAGE_TYPES)}; for numbers use live.plot({topic!r}/<field>)")
    return cls


def frame_for_browser(msg, max_width: int = MAX_WIDTH) -> tuple[bytes, str]:
    """An Image or CompressedImage message as bytes an <img> shows, and their format.

    JPEG and PNG CompressedImages pass through as they are (whatever their width); an Image is
    shrunk to max_width if
    wider, then encoded as JPEG (16-bit mono as an 8-bit picture scaled from its darkest to its
    brightest pixel, as rqt_image_view does).

    Returns:
        (bytes, "jpeg" or "png").

    Raises:
        ValueError: an encoding or compressed format the course's images module cannot read.
    """
    if not hasattr(msg, "encoding"):  # CompressedImage
        codec = images.parse_compressed_format(msg.format)
        if codec in ("jpeg", "png"):
            return bytes(msg.data), codec
        picture = images.compressed_to_image(msg)
        encoding = "mono8" if picture.ndim == 2 else "bgr8"
    else:
        picture = images.msg_to_image(msg)
        encoding = msg.encoding
    if picture.dtype != np.uint8:
        picture = cv2.normalize(picture, None, 0, 255, cv2.NORM_MINMAX, dtype=cv2.CV_8U)
        encoding = "mono8"
    if picture.ndim == 3:
        picture = images.to_bgr(picture, encoding)
    if picture.shape[1] > max_width:
        height = max(1, round(picture.shape[0] * max_width / picture.shape[1]))
        picture = cv2.resize(picture, (max_width, height), interpolation=cv2.INTER_AREA)
    ok, encoded = cv2.imencode(".jpg", picture, [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
    if not ok:  # pragma: no cover - OpenCV encodes every 8-bit grey or BGR picture
        raise ValueError(f"OpenCV could not encode a {picture.shape} picture as JPEG")
    return encoded.tobytes(), "jpeg"


# --- rqt_plot ------------------------------------------------------------------------------

class PlotView(_View):
    """Numbers from topics against time, redrawn while messages arrive (see plot).

    Attributes:
        widget: the ipywidgets box shown in the notebook (a status line and the plot).
        image: the ipywidgets.Image whose value is the plot as PNG bytes.
        series: the plotted paths, e.g. ["/odom/pose/pose/position/x"].
        data: per path, (times in seconds since the view started, values) as lists.
    """

    def __init__(self, paths, *, msg_type=None, max_rate: float = 5.0, window: float | None = 30.0,
                 ylim=None, max_points: int = 10000, seconds: float | None = None, updates: int | None = None,
                 timeout: float = 5.0):
        if not paths:
            raise ValueError("live.plot() needs at least one topic, e.g. live.plot('/brightness')")
        tool = discovery._graph_node()
        fields = [resolve_field_path(tool, path, msg_type, timeout) for path in paths]
        if len({series for series, _, _, _ in fields}) != len(fields):
            raise ValueError(f"live.plot() got the same path twice in {paths}: give each once")
        self.series = [series for series, _, _, _ in fields]
        self.window = window
        self.ylim = ylim
        self._points = {series: collections.deque(maxlen=max_points) for series in self.series}
        self._changed = False
        self._t0 = time.monotonic()
        self.image = ipywidgets.Image(format="png")
        self._figure, self._axes, self._lines = _plot_figure(self.series)
        topics = list(dict.fromkeys(topic for _, topic, _, _ in fields))
        super().__init__(_hidden_name("plot", self.series), max_rate, seconds, updates)
        self.widget = ipywidgets.VBox([self.status, self.image])
        self._show_status()
        for topic in topics:
            readers = [(series, getter) for series, name, _, getter in fields if name == topic]
            cls = next(cls for _, name, cls, _ in fields if name == topic)
            self.node.create_subscription(cls, topic, self._receiver(readers),
                                          graph.matching_qos(tool, topic, depth=100))

    @property
    def data(self) -> dict[str, tuple[list[float], list[float]]]:
        with self._lock:
            return {series: ([t for t, _ in points], [v for _, v in points])
                    for series, points in self._points.items()}

    def _receiver(self, readers):
        def receive(msg):
            now = time.monotonic() - self._t0
            with self._lock:
                for series, getter in readers:
                    self._points[series].append((now, float(getter(msg))))
                self._changed = True
        return receive

    def _redraw(self) -> bool:
        with self._lock:
            if not self._changed:
                return False
            self._changed = False
            snapshot = {series: np.array(points, dtype=float).reshape(-1, 2) for series, points in self._points.items()}
        latest = max((points[-1, 0] for points in snapshot.values() if len(points)), default=0.0)
        for line, series in zip(self._lines, self.series, strict=True):
            points = snapshot[series]
            if self.window is not None:
                points = points[points[:, 0] >= latest - self.window]
            line.set_data(points[:, 0], points[:, 1])
        self._axes.relim()
        self._axes.autoscale_view()
        if self.window is not None:
            self._axes.set_xlim(max(0.0, latest - self.window), max(latest, 1.0))
        if self.ylim is not None:
            self._axes.set_ylim(*self.ylim)
        self.image.value = _png_of(self._figure)
        self._show_status()
        return True

    def _show_status(self) -> None:
        with self._lock:
            counts = [len(self._points[series]) for series in self.series]
        parts = [f"{series}: {count} values" for series, count in zip(self.series, counts, strict=True)]
        if not any(counts) and not self.stopped:
            parts.append("waiting for messages")
        if self.stopped:
            parts.append(self.stop_reason)
        self.status.value = " · ".join(parts)


def plot(*paths: str, **options) -> PlotView:
    """Plot numbers from topics against time, updating while messages arrive: what ``rqt_plot`` does.

    Args:
        paths: each a topic followed by the path of a numeric field, rqt_plot's way:
            ``"/odom/pose/pose/position/x"``, ``"/scan/ranges[0]"``; a topic alone when its
            message holds one number (``"/brightness"`` for std_msgs/UInt8).
        msg_type: the message class or type name for topics not in the graph yet.
        max_rate: redraws per second at most (5).
        window: seconds of history shown (30); None shows everything kept.
        ylim: fixed y range, e.g. (0, 255); None fits the data.
        max_points: values kept per path; older ones are dropped.
        seconds, updates: stop after this long or this many redraws; None runs until stop(),
            except under test or grading (LIMITED_SECONDS, LIMITED_UPDATES).
        timeout: seconds to wait for each topic to appear in the graph.

    Returns:
        The view; as the last line of a cell it shows itself. ``.data`` holds what it received;
        ``.stop()`` ends it.

    Raises:
        ValueError: a path names no numeric field (the message lists the fields there are).
        TimeoutError: a topic did not appear and no msg_type was given.
    """
    return PlotView(paths, **options)


def _plot_figure(series):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    # Fixed margins: a layout engine would cost more than the drawing, on every redraw.
    figure = Figure(figsize=(7, 3), dpi=80)
    FigureCanvasAgg(figure)
    axes = figure.subplots()
    figure.subplots_adjust(left=0.09, right=0.98, top=0.96, bottom=0.16)
    lines = [axes.plot([], [], linewidth=1.2, label=name)[0] for name in series]
    axes.set_xlabel("time (s)")
    axes.grid(alpha=0.3)
    axes.legend(loc="upper left", fontsize="small")
    return figure, axes, lines


def _png_of(figure) -> bytes:
    figure.canvas.draw()
    rgba = np.asarray(figure.canvas.buffer_rgba())
    ok, encoded = cv2.imencode(".png", cv2.cvtColor(rgba, cv2.COLOR_RGBA2BGR), [cv2.IMWRITE_PNG_COMPRESSION, 1])
    if not ok:  # pragma: no cover
        raise ValueError("OpenCV could not encode the plot as PNG")
    return encoded.tobytes()


def stop_all() -> None:
    """Stop every live view of this kernel."""
    with _views_lock:
        views = list(_views.values())
    for view in views:
        view.stop()
