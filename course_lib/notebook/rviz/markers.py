"""visualization_msgs/Marker as RViz draws it: the shapes of each type, and the set of markers
alive (by namespace and id, with DELETE, DELETEALL and lifetimes). Plain numpy, no ROS import:
a marker is read through its fields only.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from course_lib.notebook.rviz.geometry import repeat_color, rgba, scaled
from course_lib.notebook.rviz.transforms import pose_matrix, transform_points

# Marker.type and Marker.action values (visualization_msgs/msg/Marker.msg).
ARROW, CUBE, SPHERE, CYLINDER, LINE_STRIP, LINE_LIST, CUBE_LIST, SPHERE_LIST, POINTS, \
    TEXT_VIEW_FACING, MESH_RESOURCE, TRIANGLE_LIST = range(12)
ADD, MODIFY, DELETE, DELETEALL = 0, 0, 2, 3
TYPE_NAMES = ["ARROW", "CUBE", "SPHERE", "CYLINDER", "LINE_STRIP", "LINE_LIST", "CUBE_LIST",
              "SPHERE_LIST", "POINTS", "TEXT_VIEW_FACING", "MESH_RESOURCE", "TRIANGLE_LIST"]
UNSUPPORTED = {MESH_RESOURCE: "MESH_RESOURCE (meshes are not loaded)",
               TRIANGLE_LIST: "TRIANGLE_LIST"}
_SOLIDS = {CUBE: "cube", SPHERE: "sphere", CYLINDER: "cylinder"}
_LISTS = {CUBE_LIST: "cube", SPHERE_LIST: "sphere"}


def _points(marker) -> np.ndarray:
    return np.array([(p.x, p.y, p.z) for p in marker.points], dtype=float).reshape(-1, 3)


def _colors(marker, count: int) -> np.ndarray:
    """Per-point colours when the marker gives one per point, else its one colour."""
    if len(marker.colors) == count and count:
        return np.array([rgba(c) for c in marker.colors], dtype=np.uint8)
    return repeat_color(rgba(marker.color), count)


def _arrow_between(start: np.ndarray, end: np.ndarray, head_diameter: float) -> np.ndarray:
    """The unit arrow's matrix from start to end (an ARROW marker given by two points)."""
    direction = end - start
    length = float(np.linalg.norm(direction))
    x = direction / length if length > 1e-12 else np.array([1.0, 0.0, 0.0])
    helper = np.array([0.0, 0.0, 1.0]) if abs(x[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
    y = np.cross(helper, x)
    y /= np.linalg.norm(y)
    z = np.cross(x, y)
    result = np.eye(4)
    result[:3, :3] = np.column_stack([x, y, z])
    result[:3, 3] = start
    return scaled(result, length, head_diameter, head_diameter)


def marker_items(marker, fixed_from_frame: np.ndarray) -> list[dict]:
    """A Marker's shapes in the fixed frame (fixed_from_frame: its header's frame to the fixed frame).

    Raises:
        ValueError: a type the view does not draw (MESH_RESOURCE, TRIANGLE_LIST, or unknown).
    """
    kind = marker.type
    if kind in UNSUPPORTED or not 0 <= kind < len(TYPE_NAMES):
        raise ValueError(f"Marker type {UNSUPPORTED.get(kind, kind)} is not supported by this view")
    fixed_from_marker = fixed_from_frame @ pose_matrix(marker.pose)
    s = marker.scale
    color = rgba(marker.color)
    if kind in _SOLIDS:
        matrices = scaled(fixed_from_marker, s.x, s.y, s.z)[None].astype(np.float32)
        return [{"type": "shapes", "shape": _SOLIDS[kind], "matrices": matrices, "colors": repeat_color(color, 1)}]
    if kind == ARROW:
        points = _points(marker)
        if len(points) >= 2:  # start and end; scale: shaft diameter, head diameter, head length
            start, end = transform_points(fixed_from_marker, points[:2]).astype(float)
            matrix = _arrow_between(start, end, s.y)
        else:  # pose and scale: length, width, height
            matrix = scaled(fixed_from_marker, s.x, s.y, s.z)
        return [{"type": "shapes", "shape": "arrow", "matrices": matrix[None].astype(np.float32),
                 "colors": repeat_color(color, 1)}]
    points = _points(marker)
    if kind == TEXT_VIEW_FACING:
        position = fixed_from_marker[None, :3, 3].astype(np.float32)
        return [{"type": "texts", "texts": [marker.text], "positions": position,
                 "colors": repeat_color(color, 1), "heights": np.array([s.z], dtype=np.float32)}]
    if not len(points):
        return []
    positions = transform_points(fixed_from_marker, points)
    colors = _colors(marker, len(points))
    if kind == POINTS:
        return [{"type": "points", "positions": positions, "colors": colors, "size": float(s.x)}]
    if kind in _LISTS:
        rotation = fixed_from_marker[:3, :3] @ np.diag([s.x, s.y, s.z])
        matrices = np.tile(np.eye(4), (len(points), 1, 1))
        matrices[:, :3, :3] = rotation
        matrices[:, :3, 3] = positions
        return [{"type": "shapes", "shape": _LISTS[kind], "matrices": matrices.astype(np.float32), "colors": colors}]
    if kind == LINE_STRIP:
        if len(points) < 2:
            return []
        index = np.repeat(np.arange(len(points)), 2)[1:-1]
        return [{"type": "lines", "positions": positions[index], "colors": colors[index]}]
    count = len(points) // 2 * 2  # LINE_LIST: pairs; a last odd point is left out
    return [{"type": "lines", "positions": positions[:count], "colors": colors[:count]}]


@dataclasses.dataclass
class KeptMarker:
    marker: object
    expires: float | None  # the view's clock (seconds), None: until deleted


class MarkerStore:
    """The markers alive, by (namespace, id), as RViz keeps them between messages."""

    def __init__(self):
        self.kept: dict[tuple[str, int], KeptMarker] = {}

    def apply(self, marker, now: float) -> None:
        """Take one Marker message received at time now (seconds of the view's clock).

        ADD and MODIFY replace the marker of the same namespace and id; DELETE removes it;
        DELETEALL removes every marker, or only those of its namespace when it names one
        (as RViz 2 does). A non-zero lifetime makes the marker expire that long after now.
        """
        key = (marker.ns, marker.id)
        if marker.action == DELETEALL:
            self.kept = {k: v for k, v in self.kept.items() if marker.ns and k[0] != marker.ns}
        elif marker.action == DELETE:
            self.kept.pop(key, None)
        elif marker.action == ADD:
            lifetime = marker.lifetime.sec + marker.lifetime.nanosec * 1e-9
            self.kept[key] = KeptMarker(marker, now + lifetime if lifetime > 0 else None)
        else:
            raise ValueError(f"Marker action {marker.action} is none of ADD/MODIFY (0), DELETE (2), DELETEALL (3)")

    def expire(self, now: float) -> bool:
        """Drop the markers whose lifetime ended by now; True when any was dropped."""
        alive = {k: v for k, v in self.kept.items() if v.expires is None or v.expires > now}
        dropped = len(alive) != len(self.kept)
        self.kept = alive
        return dropped

    def namespaces(self) -> dict[str, int]:
        """Markers alive per namespace (RViz lists them under the display)."""
        counts: dict[str, int] = {}
        for ns, _ in self.kept:
            counts[ns] = counts.get(ns, 0) + 1
        return dict(sorted(counts.items()))
