"""tf2's buffer and listener for the pip install, which has no tf2_ros: the same names, arguments and
exceptions, so that code written here runs unchanged with ``from tf2_ros import ...`` on a full
ROS install.

    buffer = Buffer()
    listener = TransformListener(buffer, node)          # fills it from /tf and /tf_static
    t = buffer.lookup_transform("odom", "laser", Time())  # the newest: laser's pose in odom
    # t.header.frame_id == "odom", t.child_frame_id == "laser": it maps laser coordinates to odom's

As in tf2: a lookup walks the tree of frames from the source frame up to the frames' common
ancestor and down to the target frame; each moving transform (/tf) is interpolated between the
two stamps around the time asked (its translation linearly, its rotation by slerp), a static one
(/tf_static) holds at every time, and ``Time()`` (zero) asks for the newest time at which every
transform on the way is known. The buffer keeps ``cache_time`` (10 s) of each moving transform.
"""

from __future__ import annotations

import bisect
import math
import threading
import time as wall

from geometry_msgs.msg import TransformStamped
from rclpy.duration import Duration
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile
from rclpy.time import Time
from tf2_msgs.msg import TFMessage


class TransformException(Exception):
    """Any failure to find a transform (tf2_ros.TransformException)."""


class LookupException(TransformException):
    """A frame the buffer has never heard of."""


class ConnectivityException(TransformException):
    """Both frames are known but in two trees that no transform joins."""


class ExtrapolationException(TransformException):
    """The time asked lies outside what the buffer holds of a transform on the way."""


class InvalidArgumentException(TransformException):
    """An empty frame name, or a transform that is not one (NaN, a zero quaternion)."""


def _nanoseconds(stamp) -> int:
    """Nanoseconds of an rclpy Time, a builtin_interfaces/Time or a number of seconds."""
    if isinstance(stamp, Time):
        return stamp.nanoseconds
    if hasattr(stamp, "sec"):
        return stamp.sec * 10**9 + stamp.nanosec
    return round(float(stamp) * 1e9)


def _seconds(nanoseconds: int) -> str:
    return f"{nanoseconds / 1e9:.6f}"


# Poses are (translation (x, y, z), rotation (x, y, z, w)) tuples of floats: a lookup composes a few
# of them per call, and plain floats do that many times faster than numpy's small arrays.

def _slerp(q0: tuple, q1: tuple, ratio: float) -> tuple:
    dot = sum(a * b for a, b in zip(q0, q1, strict=True))
    if dot < 0:
        q1, dot = tuple(-v for v in q1), -dot
    dot = min(dot, 1.0)
    if dot > 0.9995:  # nearly the same rotation: a straight line is exact enough
        q = tuple(a + ratio * (b - a) for a, b in zip(q0, q1, strict=True))
    else:
        angle = math.acos(dot)
        w0, w1 = math.sin((1 - ratio) * angle) / math.sin(angle), math.sin(ratio * angle) / math.sin(angle)
        q = tuple(w0 * a + w1 * b for a, b in zip(q0, q1, strict=True))
    norm = math.sqrt(sum(v * v for v in q))
    return tuple(v / norm for v in q)


def _cross(a: tuple, b: tuple) -> tuple:
    return a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]


def _rotate(q: tuple, v: tuple) -> tuple:
    """v turned by the unit quaternion q (x, y, z, w)."""
    u, w = q[:3], q[3]
    inner = _cross(u, v)
    outer = _cross(u, (inner[0] + w * v[0], inner[1] + w * v[1], inner[2] + w * v[2]))
    return v[0] + 2 * outer[0], v[1] + 2 * outer[1], v[2] + 2 * outer[2]


def _multiply(a: tuple, b: tuple) -> tuple:
    (ax, ay, az, aw), (bx, by, bz, bw) = a, b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def _compose(a, b):
    """The pose `b` (in a's child frame) in a's parent frame: a ∘ b."""
    moved = _rotate(a[1], b[0])
    return (a[0][0] + moved[0], a[0][1] + moved[1], a[0][2] + moved[2]), _multiply(a[1], b[1])


def _inverse(t):
    x, y, z, w = t[1]
    q = (-x, -y, -z, w)
    back = _rotate(q, t[0])
    return (-back[0], -back[1], -back[2]), q


class _Link:
    """The transforms from one parent to one child frame, by stamp (one for a static transform)."""

    def __init__(self, parent: str, static: bool):
        self.parent, self.static = parent, static
        self.stamps: list[int] = []
        self.values: list[tuple[tuple, tuple]] = []

    def insert(self, stamp: int, value, cache_ns: int) -> None:
        if self.static:
            self.stamps, self.values = [0], [value]
            return
        index = bisect.bisect_left(self.stamps, stamp)
        if index < len(self.stamps) and self.stamps[index] == stamp:
            self.values[index] = value
        else:
            self.stamps.insert(index, stamp)
            self.values.insert(index, value)
        while self.stamps[-1] - self.stamps[0] > cache_ns:
            del self.stamps[0], self.values[0]

    def at(self, stamp: int):
        """The transform at `stamp`, interpolated; raises ExtrapolationException outside (its message
        is completed by the lookup, with the frames asked for)."""
        if self.static or (stamp == self.stamps[-1]):
            return self.values[-1]
        if stamp > self.stamps[-1] or stamp < self.stamps[0]:
            future = stamp > self.stamps[-1]
            raise ExtrapolationException(
                f"Lookup would require extrapolation into the {'future' if future else 'past'}.  Requested time "
                f"{_seconds(stamp)} but the {'latest' if future else 'earliest'} data is at time "
                f"{_seconds(self.stamps[-1] if future else self.stamps[0])}")
        after = bisect.bisect_left(self.stamps, stamp)
        if self.stamps[after] == stamp:
            return self.values[after]
        (t0, v0), (t1, v1) = (self.stamps[after - 1], self.values[after - 1]), (self.stamps[after], self.values[after])
        ratio = (stamp - t0) / (t1 - t0)
        return tuple(a + ratio * (b - a) for a, b in zip(v0[0], v1[0], strict=True)), _slerp(v0[1], v1[1], ratio)


class Buffer:
    """The transforms heard, and lookups between any two frames (tf2_ros.Buffer)."""

    def __init__(self, cache_time: Duration | None = None, node=None):
        self.cache_ns = (cache_time or Duration(seconds=10)).nanoseconds
        self._links: dict[str, _Link] = {}  # child frame -> its link to its parent
        self._changed = threading.Condition()

    def set_transform(self, transform: TransformStamped, authority: str) -> bool:
        return self._set(transform, static=False)

    def set_transform_static(self, transform: TransformStamped, authority: str) -> bool:
        return self._set(transform, static=True)

    def _set(self, transform: TransformStamped, static: bool) -> bool:
        parent, child = transform.header.frame_id.lstrip("/"), transform.child_frame_id.lstrip("/")
        t, r = transform.transform.translation, transform.transform.rotation
        translation, rotation = (t.x, t.y, t.z), (r.x, r.y, r.z, r.w)
        norm = math.sqrt(sum(v * v for v in rotation))
        finite = all(map(math.isfinite, translation + rotation))
        if not parent or not child or parent == child or not finite or norm == 0:
            return False  # tf2 refuses such a transform with an error and keeps the rest
        with self._changed:
            link = self._links.get(child)
            if link is None or link.parent != parent or link.static != static:
                link = self._links[child] = _Link(parent, static)
            unit = tuple(v / norm for v in rotation)
            link.insert(_nanoseconds(transform.header.stamp), (translation, unit), self.cache_ns)
            self._changed.notify_all()
        return True

    def _frames(self) -> set[str]:
        return set(self._links) | {link.parent for link in self._links.values()}

    def _chain(self, frame: str) -> list[str]:
        chain = [frame]
        while chain[-1] in self._links and len(chain) <= len(self._links):
            chain.append(self._links[chain[-1]].parent)
        return chain

    def _path(self, target: str, source: str) -> tuple[list[str], list[str]]:
        """The frames from source up to the common ancestor, and from target up to it."""
        known = self._frames()
        for frame, argument in ((target, "target_frame"), (source, "source_frame")):
            if not frame:
                raise InvalidArgumentException(f'Invalid argument "" passed to lookupTransform argument {argument} '
                                               "- in tf2 frame_ids cannot be empty")
            if frame not in known:
                raise LookupException(f'"{frame}" passed to lookupTransform argument {argument} does not exist. ')
        up_from_source, up_from_target = self._chain(source), self._chain(target)
        common = next((f for f in up_from_source if f in up_from_target), None)
        if common is None:
            raise ConnectivityException(f"Could not find a connection between '{target}' and '{source}' because they "
                                        "are not part of the same tree.Tf has two or more unconnected trees.")
        return (up_from_source[:up_from_source.index(common)], up_from_target[:up_from_target.index(common)])

    def _latest(self, children: list[str]) -> int:
        moving = [self._links[c].stamps[-1] for c in children if not self._links[c].static]
        return min(moving) if moving else 0

    def _lookup(self, target: str, source: str, stamp: int):
        target, source = target.lstrip("/"), source.lstrip("/")
        with self._changed:
            source_side, target_side = self._path(target, source)
            if stamp == 0:
                stamp = self._latest(source_side + target_side)
            try:
                pose = up = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
                for child in source_side:  # source in the common ancestor's frame
                    pose = _compose(self._links[child].at(stamp), pose)
                for child in target_side:  # target in the common ancestor's frame
                    up = _compose(self._links[child].at(stamp), up)
            except ExtrapolationException as error:  # tf2's words name the frames of the lookup
                raise ExtrapolationException(f"{error}, when looking up transform from frame [{source}] to frame "
                                             f"[{target}]") from None
            return _compose(_inverse(up), pose), stamp

    def lookup_transform(self, target_frame: str, source_frame: str, time, timeout: Duration | None = None
                         ) -> TransformStamped:
        """The transform that maps coordinates in `source_frame` to `target_frame` at `time`
        (``Time()``: the newest common time); waits up to `timeout` for it (another thread must
        spin the listener's node meanwhile).

        Raises:
            LookupException, ConnectivityException, ExtrapolationException, InvalidArgumentException.
        """
        stamp = _nanoseconds(time)
        deadline = wall.monotonic() + (timeout.nanoseconds / 1e9 if timeout else 0.0)
        while True:
            try:
                (translation, rotation), stamp = self._lookup(target_frame, source_frame, stamp)
                break
            except (LookupException, ConnectivityException, ExtrapolationException):
                with self._changed:
                    left = deadline - wall.monotonic()
                    if left <= 0:
                        raise
                    self._changed.wait(left)
        found = TransformStamped()
        found.header.frame_id, found.child_frame_id = target_frame, source_frame
        found.header.stamp = Time(nanoseconds=stamp).to_msg()
        t, r = found.transform.translation, found.transform.rotation
        t.x, t.y, t.z = translation
        r.x, r.y, r.z, r.w = rotation
        return found

    def can_transform(self, target_frame: str, source_frame: str, time, timeout: Duration | None = None,
                      return_debug_tuple: bool = False):
        """Whether the lookup would succeed; with `return_debug_tuple`, (that, tf2's reason why not)."""
        try:
            self.lookup_transform(target_frame, source_frame, time, timeout)
            return (True, "") if return_debug_tuple else True
        except TransformException as error:
            if not return_debug_tuple:
                return False
            known = self._frames()
            for frame, argument in ((target_frame, "target_frame"), (source_frame, "source_frame")):
                if frame.lstrip("/") not in known:  # canTransform's words, not lookupTransform's
                    return False, (f'Invalid frame ID "{frame}" passed to canTransform argument {argument} '
                                   "- frame does not exist")
            return False, str(error)

    def all_frames_as_yaml(self) -> str:
        """Each frame with its parent and what the buffer holds of it, as tf2's ``allFramesAsYAML``
        (what view_frames draws): a static transform's rate is tf2's 10000 (one entry over no time)."""
        lines = []
        with self._changed:
            for child, link in sorted(self._links.items()):
                newest, oldest = link.stamps[-1] / 1e9, link.stamps[0] / 1e9
                rate = len(link.stamps) / max(newest - oldest, 0.0001)
                lines.append(f"{child}: \n  parent: '{link.parent}'\n  broadcaster: 'default_authority'\n"
                             f"  rate: {rate:.3f}\n  most_recent_transform: {newest:.6f}\n"
                             f"  oldest_transform: {oldest:.6f}\n  buffer_length: {newest - oldest:.3f}\n")
        return "".join(lines)

    def all_frames_as_string(self) -> str:
        """One line per frame, as tf2's ``allFramesAsString`` (what tf2_echo prints on a failure)."""
        with self._changed:
            return "".join(f"Frame {child} exists with parent {link.parent}.\n"
                           for child, link in sorted(self._links.items()))


class TransformListener:
    """Fills a Buffer from /tf and /tf_static, with tf2_ros's QoS (tf2_ros.TransformListener)."""

    def __init__(self, buffer: Buffer, node, *, qos=None, static_qos=None):
        self.buffer = buffer
        qos = qos or QoSProfile(depth=100)
        static_qos = static_qos or QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL,
                                              history=HistoryPolicy.KEEP_LAST)
        self.tf_sub = node.create_subscription(TFMessage, "/tf", self.on_tf, qos)
        self.tf_static_sub = node.create_subscription(TFMessage, "/tf_static", self.on_tf_static, static_qos)

    def on_tf(self, msg: TFMessage) -> None:
        for transform in msg.transforms:
            self.buffer.set_transform(transform, "default_authority")

    def on_tf_static(self, msg: TFMessage) -> None:
        for transform in msg.transforms:
            self.buffer.set_transform_static(transform, "default_authority")
