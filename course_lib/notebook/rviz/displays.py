"""RViz's displays: what each keeps of its topic's messages and what it draws in the fixed frame.

A display's ``receive`` runs on the ROS session's thread for each message; ``draw`` runs on the
view's timer and returns the items of :mod:`course_lib.notebook.rviz.geometry` in the fixed frame,
through the view's transform tree. A display keeps only what it shows (the newest scan, pose and
path; the markers alive; the last ``keep`` odometry arrows): messages that arrive faster than the
view draws replace each other, newest wins. Its ``status`` is RViz's: a level ("ok", "warn",
"error") and a line ("No transform from [laser] to [odom]").
"""

from __future__ import annotations

import collections
import threading

import numpy as np

from course_lib.notebook.rviz import clouds, geometry, markers
from course_lib.notebook.rviz.transforms import NoTransform, TransformTree, matrix, pose_matrix
from course_lib.robot import husky

NO_MESSAGES = "No messages received"
#: The yellow of the Husky's model (husky.xml); its size is course_lib.robot.husky.BODY_SIZE.
HUSKY_COLOR = (242, 191, 26, 255)


class Display:
    """One display of the view: a kind, maybe a topic, what it keeps and its status line."""

    kind = ""
    msg_type = ""  # "package/msg/Type" of its topic, "" for none
    default_topic = ""
    reliable = True  # subscribe reliable (markers, paths) or best effort (sensor streams)

    def __init__(self, name: str, topic: str | None = None):
        self.name = name
        self.topic = topic if topic is not None else self.default_topic
        self.received = 0
        self.replaced = 0  # messages replaced by a newer one before they were drawn
        self.changed = True
        self.status = ("warn", NO_MESSAGES) if self.msg_type else ("ok", "")
        self._lock = threading.Lock()

    def receive(self, msg, now: float) -> None:
        with self._lock:
            self.received += 1
            self._keep(msg, now)
            self.changed = True

    def _keep(self, msg, now: float) -> None:
        raise NotImplementedError

    def draw(self, tree: TransformTree, fixed_frame: str, now: float) -> list[dict]:
        """The display's items in the fixed frame; sets status (and draws nothing for a message
        whose frame has no transform to the fixed frame)."""
        with self._lock:
            self.changed = False
            try:
                items = self._draw(tree, fixed_frame, now)
            except NoTransform as error:
                self.status = ("error", str(error))
                return []
            except ValueError as error:
                self.status = ("error", str(error))
                return []
        return items

    def _draw(self, tree: TransformTree, fixed_frame: str, now: float) -> list[dict]:
        raise NotImplementedError

    def describe(self) -> dict:
        level, text = self.status
        return {"name": self.name, "kind": self.kind, "topic": self.topic, "level": level, "status": text}


class _Latest(Display):
    """A display of the newest message only (LaserScan, PoseStamped, Path)."""

    def __init__(self, name, topic=None):
        super().__init__(name, topic)
        self.latest = None
        self._drawn = None

    def _keep(self, msg, now):
        if self.latest is not None and self.latest is not self._drawn:
            self.replaced += 1
        self.latest = msg

    def _draw(self, tree, fixed_frame, now):
        msg, self._drawn = self.latest, self.latest
        if msg is None:
            return []
        fixed_from_msg = tree.lookup(fixed_frame, msg.header.frame_id)
        items = self._items(msg, fixed_from_msg, tree, fixed_frame)
        self.status = ("ok", self._summary(msg))
        return items


class LaserScan(_Latest):
    kind, msg_type, default_topic, reliable = "LaserScan", "sensor_msgs/msg/LaserScan", "/scan", False

    def __init__(self, name, topic=None, size: float = 0.05):
        super().__init__(name, topic)
        self.size = size
        self.points = 0

    def _items(self, msg, fixed_from_msg, tree, fixed_frame):
        items = geometry.laser_scan(msg, fixed_from_msg, self.size)
        self.points = len(items[0]["positions"])
        return items

    def _summary(self, msg):
        return f"{self.points} points of {len(msg.ranges)} beams"


class PointCloud2(_Latest):
    """RViz's PointCloud2: the newest cloud's points, coloured by RGB8 (else intensity, else z)."""

    kind, msg_type, default_topic, reliable = "PointCloud2", "sensor_msgs/msg/PointCloud2", "/points", False

    def __init__(self, name, topic=None, size: float = 0.02):
        super().__init__(name, topic)
        self.size = size
        self.points = 0

    def _items(self, msg, fixed_from_msg, tree, fixed_frame):
        items = clouds.point_cloud(msg, fixed_from_msg, self.size)
        self.points = len(items[0]["positions"])
        return items

    def _summary(self, msg):
        return f"{self.points} points"


class PoseStamped(_Latest):
    kind, msg_type, default_topic = "PoseStamped", "geometry_msgs/msg/PoseStamped", "/goal_pose"

    def __init__(self, name, topic=None, length: float = 1.0, width: float = 0.1):
        super().__init__(name, topic)
        self.length, self.width = length, width

    def _items(self, msg, fixed_from_msg, tree, fixed_frame):
        return geometry.pose_arrows([fixed_from_msg @ pose_matrix(msg.pose)], self.length, self.width)

    def _summary(self, msg):
        return "1 pose"


class Path(_Latest):
    kind, msg_type, default_topic = "Path", "nav_msgs/msg/Path", "/plan"

    def _items(self, msg, fixed_from_msg, tree, fixed_frame):
        return geometry.path([fixed_from_msg @ pose_matrix(p.pose) for p in msg.poses])

    def _summary(self, msg):
        return f"{len(msg.poses)} poses"


class Odometry(Display):
    """RViz's Odometry: an arrow per pose, a new one once the robot moved or turned by the
    tolerances, the last `keep` of them."""

    kind, msg_type, default_topic, reliable = "Odometry", "nav_msgs/msg/Odometry", "/odom", False

    def __init__(self, name, topic=None, keep: int = 100, length: float = 1.0, width: float = 0.1,
                 position_tolerance: float = 0.1, angle_tolerance: float = 0.1):
        super().__init__(name, topic)
        self.kept: collections.deque = collections.deque(maxlen=max(1, keep))
        self.length, self.width = length, width
        self.position_tolerance, self.angle_tolerance = position_tolerance, angle_tolerance

    def _keep(self, msg, now):
        pose = pose_matrix(msg.pose.pose)
        if self.kept:
            frame, last = self.kept[-1]
            moved = np.linalg.norm(pose[:3, 3] - last[:3, 3])
            turned = np.arccos(np.clip((np.trace(last[:3, :3].T @ pose[:3, :3]) - 1) / 2, -1, 1))
            if frame == msg.header.frame_id and moved < self.position_tolerance and turned < self.angle_tolerance:
                return
        self.kept.append((msg.header.frame_id, pose))

    def _draw(self, tree, fixed_frame, now):
        poses = [tree.lookup(fixed_frame, frame) @ pose for frame, pose in self.kept]
        if self.kept:
            self.status = ("ok", f"{len(poses)} arrows")
        return geometry.pose_arrows(poses, self.length, self.width)


class Marker(Display):
    """RViz's Marker display: every marker alive, each drawn in its own frame; a marker whose
    frame has no transform is left out and named in the status."""

    kind, msg_type, default_topic = "Marker", "visualization_msgs/msg/Marker", "/visualization_marker"

    def __init__(self, name, topic=None):
        super().__init__(name, topic)
        self.store = markers.MarkerStore()

    def _keep(self, msg, now):
        self.store.apply(msg, now)

    def expire(self, now: float) -> None:
        with self._lock:
            if self.store.expire(now):
                self.changed = True

    def _draw(self, tree, fixed_frame, now):
        self.store.expire(now)
        items, problems = [], []
        for kept in self.store.kept.values():
            try:
                items += markers.marker_items(kept.marker, tree.lookup(fixed_frame, kept.marker.header.frame_id))
            except (NoTransform, ValueError) as error:
                problems.append(f"{kept.marker.ns}/{kept.marker.id}: {error}")
        namespaces = ", ".join(f"{ns or '(no namespace)'}: {n}" for ns, n in self.store.namespaces().items())
        if problems:
            self.status = ("error", "; ".join(dict.fromkeys(problems)))
        elif self.received:
            self.status = ("ok", f"{len(self.store.kept)} markers ({namespaces})" if namespaces else "0 markers")
        return items


class MarkerArray(Marker):
    kind, msg_type, default_topic = "MarkerArray", "visualization_msgs/msg/MarkerArray", "/visualization_marker_array"

    def _keep(self, msg, now):
        for marker in msg.markers:
            self.store.apply(marker, now)


class Grid(Display):
    """RViz's Grid: in the fixed frame unless `frame` names another."""

    kind = "Grid"

    def __init__(self, name, topic=None, cell_size: float = 1.0, cells: int = 10, frame: str | None = None):
        super().__init__(name, None)
        self.cell_size, self.cells, self.frame = cell_size, cells, frame

    def _draw(self, tree, fixed_frame, now):
        fixed_from_grid = tree.lookup(fixed_frame, self.frame or fixed_frame)
        self.status = ("ok", f"{self.cells}×{self.cells} cells of {self.cell_size:g} m")
        return geometry.grid(fixed_from_grid, self.cell_size, self.cells)


class TF(Display):
    """RViz's TF display: every frame joined to the fixed frame, its axes and its name; the frames
    not joined are named in the status."""

    kind = "TF"

    def __init__(self, name, topic=None, length: float = 0.3, names: bool = True, text_height: float = 0.1):
        super().__init__(name, None)
        self.length, self.names, self.text_height = length, names, text_height

    def _draw(self, tree, fixed_frame, now):
        frames, apart = {}, []
        for frame in tree.frames() or [fixed_frame]:
            try:
                frames[frame] = tree.lookup(fixed_frame, frame)
            except NoTransform:
                apart.append(frame)
        self.status = ("warn", f"No transform to [{fixed_frame}] from [{'], ['.join(apart)}]") if apart else \
            ("ok", f"{len(frames)} frames")
        return geometry.tf_frames(frames, self.length, self.names, self.text_height)


class RobotModel(Display):
    """The robot's shape: a box of the Husky's outer size standing on base_link (RViz's RobotModel
    draws the URDF's links; the course's robot is one box, and no URDF is read)."""

    kind = "RobotModel"

    def __init__(self, name, topic=None, frame: str = husky.BASE_FRAME, size=husky.BODY_SIZE, color=HUSKY_COLOR):
        super().__init__(name, None)
        self.frame, self.size, self.color = frame, tuple(size), color

    def _draw(self, tree, fixed_frame, now):
        base = tree.lookup(fixed_frame, self.frame)
        length, width, height = self.size
        box = geometry.scaled(base @ matrix((0.0, 0.0, height / 2)), length, width, height)
        self.status = ("ok", f"a box {length:g} × {width:g} × {height:g} m on [{self.frame}]")
        return [{"type": "shapes", "shape": "cube", "matrices": box[None].astype(np.float32),
                 "colors": geometry.repeat_color(self.color, 1)}]


class Image(_Latest):
    """RViz's Image display: the newest picture in a 2D panel over the view (sent as a JPEG)."""

    kind, msg_type, default_topic, reliable = "Image", "sensor_msgs/msg/Image", "/image", False

    def __init__(self, name, topic=None, width: int = 240, quality: int = 80):
        super().__init__(name, topic)
        self.width, self.quality = width, quality

    def _draw(self, tree, fixed_frame, now):
        import cv2

        from course_lib.imaging.images import msg_to_image, to_bgr

        msg, self._drawn = self.latest, self.latest
        if msg is None:
            return []
        picture = to_bgr(msg_to_image(msg), msg.encoding)
        ok, jpeg = cv2.imencode(".jpg", picture, [cv2.IMWRITE_JPEG_QUALITY, self.quality])
        self.status = ("ok", f"{msg.width}×{msg.height} {msg.encoding}")
        return [{"type": "image", "jpeg": jpeg.reshape(-1), "width": int(self.width),
                 "aspect": msg.height / max(1, msg.width)}]


#: The displays by the name `RViz.add` takes (RViz's own names for them).
KINDS = {cls.kind: cls for cls in (Grid, TF, LaserScan, PointCloud2, Marker, MarkerArray, Odometry, Path,
                                   PoseStamped, RobotModel, Image)}
