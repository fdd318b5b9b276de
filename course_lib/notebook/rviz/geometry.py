"""What RViz's displays draw, as plain numpy: messages' contents turned into points, lines, shapes
and texts in the fixed frame. No ROS import and no widget here; every function has unit tests.

Every drawing is a list of items, each a dict the browser draws with one three.js object:

- ``points``: ``positions`` (N×3 float32), ``colors`` (N×4 uint8 RGBA), ``size`` (metres), and
  maybe ``pose`` (4×4: the positions' frame in the fixed frame, which the browser applies; a
  PointCloud2's, so that a new transform does not send the cloud again);
- ``lines``: segments, ``positions`` (2M×3: start, end, start, end, ...), ``colors`` (2M×4);
- ``shapes``: ``shape`` ("cube", "sphere", "cylinder", "arrow"), ``matrices`` (K×4×4: each the
  unit shape's pose and scale in the fixed frame), ``colors`` (K×4). The unit cube has side 1, the
  sphere diameter 1, the cylinder diameter 1 and height 1 along z, the arrow length 1 along x
  (shaft 0.77 of it), head diameter 1;
- ``texts``: ``texts`` (K strings), ``positions`` (K×3), ``colors`` (K×4), ``heights`` (K metres).
"""

from __future__ import annotations

import numpy as np

from course_lib.notebook.rviz.transforms import transform_points

#: RViz's default colours (RGBA 0-255): a grid's lines, a pose arrow, a path.
GRID_COLOR = (160, 160, 164, 255)
ARROW_COLOR = (255, 25, 0, 255)
PATH_COLOR = (25, 255, 0, 255)
AXIS_COLORS = ((255, 0, 0, 255), (0, 255, 0, 255), (0, 0, 255, 255))  # x red, y green, z blue


def rgba(color) -> tuple[int, int, int, int]:
    """A std_msgs/ColorRGBA (or an (r, g, b, a) of 0-1 floats) as 0-255 integers."""
    if hasattr(color, "r"):
        color = (color.r, color.g, color.b, color.a)
    return tuple(int(round(min(max(float(c), 0.0), 1.0) * 255)) for c in color)


def repeat_color(color, count: int) -> np.ndarray:
    return np.tile(np.asarray(color, dtype=np.uint8), (count, 1))


# --- LaserScan ----------------------------------------------------------------------------

def scan_points(ranges, angle_min: float, angle_increment: float, range_min: float,
                range_max: float) -> tuple[np.ndarray, np.ndarray]:
    """A LaserScan's valid beams as points in the scan's own frame.

    A beam counts when its range is finite and within [range_min, range_max], as RViz keeps it.

    Returns:
        (points N×3 float64, their ranges N).
    """
    ranges = np.asarray(ranges, dtype=float)
    angles = angle_min + angle_increment * np.arange(ranges.size)
    valid = np.isfinite(ranges) & (ranges >= range_min) & (ranges <= range_max)
    r, a = ranges[valid], angles[valid]
    return np.column_stack([r * np.cos(a), r * np.sin(a), np.zeros_like(r)]), r


def rainbow(values, low: float | None = None, high: float | None = None) -> np.ndarray:
    """RViz's "Rainbow" colour transformer: low values red, then yellow, green, cyan, blue, and the
    highest magenta. low and high default to the values' own range.

    Returns:
        N×4 uint8 RGBA.
    """
    values = np.asarray(values, dtype=float)
    if values.size == 0:
        return np.zeros((0, 4), dtype=np.uint8)
    low = float(values.min()) if low is None else low
    high = float(values.max()) if high is None else high
    v = np.clip((values - low) / (high - low), 0.0, 1.0) if high > low else np.zeros_like(values)
    h = (1.0 - v) * 5.0 + 1.0
    i = np.floor(h).astype(int)
    f = h - i
    f = np.where(i % 2 == 0, 1.0 - f, f)
    n = 1.0 - f
    zero, one = np.zeros_like(n), np.ones_like(n)
    red = np.select([i <= 1, i == 2, i == 3, i == 4], [n, zero, zero, n], one)
    green = np.select([i <= 1, i == 2, i == 3], [zero, n, one], np.where(i == 4, one, n))
    blue = np.select([i <= 1, i == 2, i == 3], [one, one, n], zero)
    colors = np.column_stack([red, green, blue, one]) * 255
    return np.round(colors).astype(np.uint8)


def laser_scan(scan, fixed_from_scan: np.ndarray, size: float = 0.05) -> list[dict]:
    """A sensor_msgs/LaserScan as points in the fixed frame, coloured by range (Rainbow)."""
    points, ranges = scan_points(scan.ranges, scan.angle_min, scan.angle_increment, scan.range_min,
                                 scan.range_max)
    return [{"type": "points", "positions": transform_points(fixed_from_scan, points),
             "colors": rainbow(ranges), "size": float(size)}]


# --- arrows, axes, grid -------------------------------------------------------------------

def scaled(transform: np.ndarray, sx: float, sy: float, sz: float) -> np.ndarray:
    return transform @ np.diag([sx, sy, sz, 1.0])


def pose_arrows(fixed_from_poses: list[np.ndarray], length: float = 1.0, width: float = 0.1,
                color=ARROW_COLOR) -> list[dict]:
    """Arrows along each pose's x axis (RViz's Odometry and PoseStamped "Arrow" shape)."""
    if not fixed_from_poses:
        return []
    matrices = np.stack([scaled(t, length, width, width) for t in fixed_from_poses]).astype(np.float32)
    return [{"type": "shapes", "shape": "arrow", "matrices": matrices,
             "colors": repeat_color(color, len(fixed_from_poses))}]


def axes(fixed_from_frame: np.ndarray, length: float = 0.3) -> np.ndarray:
    """A frame's three axes as six segment ends (x, y, z from its origin), in the fixed frame."""
    ends = np.array([[0, 0, 0], [length, 0, 0], [0, 0, 0], [0, length, 0], [0, 0, 0], [0, 0, length]])
    return transform_points(fixed_from_frame, ends)


def tf_frames(frames: dict[str, np.ndarray], length: float = 0.3, names: bool = True,
              text_height: float = 0.1) -> list[dict]:
    """RViz's TF display: each frame's axes (x red, y green, z blue) and, beside it, its name."""
    if not frames:
        return []
    positions = np.concatenate([axes(t, length) for t in frames.values()])
    colors = np.tile(np.repeat(np.asarray(AXIS_COLORS, dtype=np.uint8), 2, axis=0), (len(frames), 1))
    items = [{"type": "lines", "positions": positions, "colors": colors}]
    if names:
        origins = np.array([t[:3, 3] for t in frames.values()], dtype=np.float32)
        items.append({"type": "texts", "texts": list(frames), "positions": origins,
                      "colors": repeat_color((255, 255, 255, 255), len(frames)),
                      "heights": np.full(len(frames), text_height, dtype=np.float32)})
    return items


def grid(fixed_from_grid: np.ndarray, cell_size: float = 1.0, cells: int = 10,
         color=GRID_COLOR) -> list[dict]:
    """RViz's Grid: cells × cells squares in the grid frame's xy plane, centred on its origin."""
    half = cell_size * cells / 2
    ticks = np.linspace(-half, half, cells + 1)
    along_x = [([-half, t, 0], [half, t, 0]) for t in ticks]
    along_y = [([t, -half, 0], [t, half, 0]) for t in ticks]
    ends = np.array(along_x + along_y, dtype=float).reshape(-1, 3)
    return [{"type": "lines", "positions": transform_points(fixed_from_grid, ends),
             "colors": repeat_color(color, len(ends))}]


def path(fixed_from_poses: list[np.ndarray], color=PATH_COLOR) -> list[dict]:
    """RViz's Path display: the poses' positions joined by a line."""
    if len(fixed_from_poses) < 2:
        return []
    corners = np.array([t[:3, 3] for t in fixed_from_poses], dtype=np.float32)
    segments = np.repeat(corners, 2, axis=0)[1:-1]
    return [{"type": "lines", "positions": segments, "colors": repeat_color(color, len(segments))}]
