"""Frames and the transforms between them, as RViz's TF handling needs them: plain numpy.

A transform is a 4×4 matrix ``T`` that maps a point's coordinates in the child frame to the parent
frame (``p_parent = T @ p_child``), as ``geometry_msgs/TransformStamped`` means it: its
``header.frame_id`` is the parent, ``child_frame_id`` the child. The tree keeps the newest transform
of each child; a lookup walks both frames up to their common ancestor. Time is not interpolated:
the view draws every message with the newest transforms it has (RViz waits for the transform at
the message's stamp; a course robot's frames move slowly enough for the difference not to show).
"""

from __future__ import annotations

import numpy as np


class NoTransform(LookupError):
    """No chain of transforms joins two frames; the message says so in RViz's words."""

    def __init__(self, source: str, target: str):
        super().__init__(f"No transform from [{source}] to [{target}]")
        self.source, self.target = source, target


def frame_name(frame_id: str) -> str:
    """A frame's name as tf2 keys it: without a leading slash ("/odom" and "odom" are one frame)."""
    return frame_id.lstrip("/")


def rotation_matrix(x: float, y: float, z: float, w: float) -> np.ndarray:
    """The 3×3 rotation of a quaternion (normalised first; an all-zero quaternion is no rotation,
    as RViz takes a Marker's default orientation)."""
    q = np.array([x, y, z, w], dtype=float)
    norm = np.linalg.norm(q)
    if norm < 1e-12:
        return np.eye(3)
    x, y, z, w = q / norm
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def quaternion_from_yaw(yaw: float) -> tuple[float, float, float, float]:
    """The quaternion (x, y, z, w) of a turn by yaw radians about z."""
    return (0.0, 0.0, float(np.sin(yaw / 2)), float(np.cos(yaw / 2)))


def quaternion_from_matrix(rotation) -> tuple[float, float, float, float]:
    """The quaternion (x, y, z, w) of a 3×3 rotation matrix (e.g. cv2.Rodrigues' of solvePnP's rvec),
    with w >= 0."""
    r = np.asarray(rotation, dtype=float)[:3, :3]
    w = np.sqrt(max(0.0, 1.0 + np.trace(r))) / 2
    x = np.copysign(np.sqrt(max(0.0, 1.0 + r[0, 0] - r[1, 1] - r[2, 2])) / 2, r[2, 1] - r[1, 2])
    y = np.copysign(np.sqrt(max(0.0, 1.0 - r[0, 0] + r[1, 1] - r[2, 2])) / 2, r[0, 2] - r[2, 0])
    z = np.copysign(np.sqrt(max(0.0, 1.0 - r[0, 0] - r[1, 1] + r[2, 2])) / 2, r[1, 0] - r[0, 1])
    return float(x), float(y), float(z), float(w)


def matrix(translation=(0.0, 0.0, 0.0), rotation=(0.0, 0.0, 0.0, 1.0)) -> np.ndarray:
    """The 4×4 transform of a translation (x, y, z) and a quaternion (x, y, z, w)."""
    result = np.eye(4)
    result[:3, :3] = rotation_matrix(*rotation)
    result[:3, 3] = translation
    return result


def pose_matrix(pose) -> np.ndarray:
    """The 4×4 transform of a geometry_msgs Pose (or Transform: translation and rotation)."""
    if hasattr(pose, "position"):
        p, q = pose.position, pose.orientation
    else:
        p, q = pose.translation, pose.rotation
    return matrix((p.x, p.y, p.z), (q.x, q.y, q.z, q.w))


def inverse(transform: np.ndarray) -> np.ndarray:
    """The inverse of a rigid 4×4 transform (transposed rotation, no general inversion)."""
    result = np.eye(4)
    rotation_t = transform[:3, :3].T
    result[:3, :3] = rotation_t
    result[:3, 3] = -rotation_t @ transform[:3, 3]
    return result


def transform_points(transform: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Points (N×3) moved by a 4×4 transform; float32, as the browser takes them."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    return (points @ transform[:3, :3].T + transform[:3, 3]).astype(np.float32)


class TransformTree:
    """The newest transform of each child frame, and lookups between any two frames of a tree."""

    def __init__(self):
        self._parents: dict[str, tuple[str, np.ndarray]] = {}  # child -> (parent, T_parent_child)

    def set(self, parent: str, child: str, transform: np.ndarray) -> None:
        """Record the transform from child to parent (replacing the child's previous one).

        Raises:
            ValueError: a frame made its own parent, or the new link would close a loop
                (tf2 refuses both: a frame has one parent).
        """
        parent, child = frame_name(parent), frame_name(child)
        if parent == child:
            raise ValueError(f"A transform from [{child}] to itself: frame_id and child_frame_id must differ")
        if child in self._chain(parent):
            raise ValueError(f"A transform from [{child}] to [{parent}] would close a loop: "
                             f"[{parent}] already hangs below [{child}]")
        self._parents[child] = (parent, np.asarray(transform, dtype=float))

    def add_message(self, stamped) -> None:
        """Record a geometry_msgs/TransformStamped."""
        self.set(stamped.header.frame_id, stamped.child_frame_id, pose_matrix(stamped.transform))

    def frames(self) -> list[str]:
        """Every frame named so far, parents and children, sorted."""
        return sorted(set(self._parents) | {parent for parent, _ in self._parents.values()})

    def parent_of(self, frame: str) -> str | None:
        entry = self._parents.get(frame_name(frame))
        return entry[0] if entry else None

    def _chain(self, frame: str) -> list[str]:
        chain = [frame]
        while frame in self._parents:
            frame = self._parents[frame][0]
            chain.append(frame)
        return chain

    def _to_root(self, frame: str, stop: str) -> np.ndarray:
        result = np.eye(4)
        while frame != stop:
            frame, step = self._parents[frame]
            result = step @ result
        return result

    def lookup(self, target: str, source: str) -> np.ndarray:
        """The 4×4 transform that maps coordinates in source to coordinates in target.

        Raises:
            NoTransform: the frames are not in one tree ("No transform from [laser] to [odom]").
        """
        target, source = frame_name(target), frame_name(source)
        if target == source:
            return np.eye(4)
        up_from_source = self._chain(source)
        above_target = set(self._chain(target))
        common = next((frame for frame in up_from_source if frame in above_target), None)
        if common is None:
            raise NoTransform(source, target)
        return inverse(self._to_root(target, common)) @ self._to_root(source, common)
