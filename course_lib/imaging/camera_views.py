"""How a camera sees the board: where from (:class:`Pose`), and through what light and sensor (:class:`Look`).

Poses and looks are sampled at random for "easy" and "hard" scenes (:func:`sample_pose`,
:func:`sample_look`). Board coordinates are board units; inside this module "edge" coordinates
put the top-left *corner* of a pixel at (0, 0), which is what makes homographies compose exactly.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import cv2
import numpy as np

from course_lib.imaging import drawn_cache
from course_lib.imaging.boards import Board, _square, default_board

DIFFICULTIES = ("easy", "hard")

# --------------------------------------------------------------------------------------------
# The camera
# --------------------------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class Pose:
    """Where the camera looks at the board from.

    Attributes:
        tilt_x, tilt_y: perspective tilt of the board about its horizontal / vertical axis, degrees.
        roll: in-plane rotation, degrees (positive turns the board clockwise in the image).
        scale: apparent board width as a fraction of the frame width (above 1: larger than the frame).
        center: where the board centre lands, as offsets from the frame centre in frame widths/heights.
        focal: focal length in frame widths (about 1: a 53-degree horizontal field of view).
    """

    tilt_x: float = 0.0
    tilt_y: float = 0.0
    roll: float = 0.0
    scale: float = 0.85
    center: tuple[float, float] = (0.0, 0.0)
    focal: float = 1.0

    def homography(self, board_size: tuple[float, float], frame_size: tuple[int, int]) -> np.ndarray:
        """Board units -> frame, both in edge coordinates (pixel (0, 0) spans 0..1)."""
        H = self._unnormalised_homography(board_size, frame_size)
        return H / H[2, 2]

    def depths(self, board_size, frame_size, points: np.ndarray) -> np.ndarray:
        """Distance along the optical axis of board points, relative to the board centre's."""
        H = self._unnormalised_homography(board_size, frame_size)
        points = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        centre = np.array([board_size[0] / 2, board_size[1] / 2, 1.0]) @ H[2]
        return (np.column_stack([points, np.ones(len(points))]) @ H[2]) / centre

    def _unnormalised_homography(self, board_size, frame_size) -> np.ndarray:
        bw, bh = board_size
        width, height = frame_size
        f = self.focal * width
        K = np.array([[f, 0, width / 2], [0, f, height / 2], [0, 0, 1.0]])
        R = _rotation_z(self.roll) @ _rotation_x(self.tilt_x) @ _rotation_y(self.tilt_y)
        z = f * bw / (self.scale * width)
        t = np.array([self.center[0] * width * z / f, self.center[1] * height * z / f, z])
        centre_board = np.array([[1, 0, -bw / 2], [0, 1, -bh / 2], [0, 0, 1.0]])
        return K @ np.column_stack([R[:, 0], R[:, 1], t]) @ centre_board


def _rotation_x(deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _rotation_y(deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _rotation_z(deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


@dataclasses.dataclass(frozen=True)
class Look:
    """How the sensor and the light change the image. The defaults give a clean frame.

    Attributes:
        gain: overall brightness factor.
        gradient: brightness difference across the frame (0.4: one side 40 % brighter than the other).
        gradient_angle: direction of the gradient, degrees (0: brighter to the right).
        gamma: tone curve exponent (above 1 darkens mid-tones).
        tint: per-channel gain (B, G, R), a white-balance error.
        noise: standard deviation of sensor noise, grey levels.
        blur: Gaussian blur sigma, pixels (focus or motion).
        jpeg_quality: JPEG quality 1-100 of a compression round trip, or None for none.
        clutter: draw objects on the table around the board (else a plain table).
    """

    gain: float = 1.0
    gradient: float = 0.0
    gradient_angle: float = 0.0
    gamma: float = 1.0
    tint: tuple[float, float, float] = (1.0, 1.0, 1.0)
    noise: float = 0.0
    blur: float = 0.0
    jpeg_quality: int | None = None
    clutter: bool = True


def sample_pose(rng: np.random.Generator, difficulty: str = "easy",
                frame_size: tuple[int, int] = (640, 480), board: Board | None = None) -> Pose:
    """A random camera pose.

    "easy": mild tilt and rotation, the whole board inside the frame. "hard": steep tilt, any
    rotation, small to larger-than-frame boards, often partly off-frame.

    Raises:
        ValueError: unknown difficulty.
    """
    _check_difficulty(difficulty)
    board = board or default_board()
    if difficulty == "hard":
        for _ in range(100):
            pose = Pose(tilt_x=rng.uniform(-50, 50), tilt_y=rng.uniform(-50, 50), roll=rng.uniform(-180, 180),
                        scale=rng.uniform(0.6, 1.3), center=(rng.uniform(-0.2, 0.2), rng.uniform(-0.2, 0.2)),
                        focal=rng.uniform(0.8, 1.3))
            if _in_front(pose, board, frame_size):
                return pose
        return Pose()
    for attempt in range(200):
        shrink = 0.995 ** attempt  # keeps the loop finite for odd frame shapes
        pose = Pose(tilt_x=rng.uniform(-18, 18), tilt_y=rng.uniform(-22, 22), roll=rng.uniform(-15, 15),
                    scale=rng.uniform(0.76, 0.94) * shrink, center=(rng.uniform(-0.05, 0.05), rng.uniform(-0.06, 0.06)),
                    focal=rng.uniform(0.9, 1.2))
        corners = _project(pose.homography(board.size, frame_size), _board_outline(board))
        width, height = frame_size
        if corners[:, 0].min() > 0.01 * width and corners[:, 0].max() < 0.99 * width and \
                corners[:, 1].min() > 0.01 * height and corners[:, 1].max() < 0.99 * height:
            return pose
    return Pose(scale=0.5)


def sample_look(rng: np.random.Generator, difficulty: str = "easy") -> Look:
    """Random lighting and sensor effects: mild for "easy", strong for "hard".

    Raises:
        ValueError: unknown difficulty.
    """
    _check_difficulty(difficulty)
    if difficulty == "hard":
        return Look(gain=rng.uniform(0.5, 1.35), gradient=rng.uniform(0.2, 0.5), gradient_angle=rng.uniform(0, 360),
                    gamma=rng.uniform(0.7, 1.4), tint=tuple(rng.uniform(0.85, 1.15, 3)), noise=rng.uniform(3, 7),
                    blur=rng.uniform(0.3, 0.9), jpeg_quality=int(rng.integers(40, 80)), clutter=True)
    return Look(gain=rng.uniform(0.85, 1.1), gradient=rng.uniform(0, 0.15), gradient_angle=rng.uniform(0, 360),
                gamma=rng.uniform(0.9, 1.1), tint=tuple(rng.uniform(0.97, 1.03, 3)), noise=rng.uniform(1, 3),
                blur=rng.uniform(0, 0.5), jpeg_quality=int(rng.integers(85, 96)), clutter=True)


def _check_difficulty(difficulty):
    if difficulty not in DIFFICULTIES:
        raise ValueError(f"Unknown difficulty {difficulty!r}: use one of {DIFFICULTIES}")


def _board_outline(board: Board) -> np.ndarray:
    return _square(0, 0, 1) * np.array(board.size, dtype=np.float64)


def _project(H: np.ndarray, points: np.ndarray) -> np.ndarray:
    points = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    p = np.column_stack([points, np.ones(len(points))]) @ H.T
    return p[:, :2] / p[:, 2:3]


def _in_front(pose: Pose, board: Board, frame_size) -> bool:
    """True when the whole board (and a margin for stickers) is in front of the camera, not edge-on."""
    bw, bh = board.size
    outline = np.array([[-200, -200], [bw + 200, -200], [bw + 200, bh + 200], [-200, bh + 200]], np.float64)
    R = _rotation_z(pose.roll) @ _rotation_x(pose.tilt_x) @ _rotation_y(pose.tilt_y)
    facing = abs(R[2, 2])  # cosine between the board's normal and the optical axis
    return facing > 0.25 and bool(np.all(pose.depths(board.size, frame_size, outline) > 0.35))


_NOISE_PAD = 64


@functools.lru_cache(maxsize=2)
def _noise_tile(size) -> np.ndarray:
    """A fixed field of sensor noise for frames of `size`: a random window of it, with a random sign,
    is a frame's noise (scenes and the camera's video; drawing 921,600 normal numbers per frame took
    8 of a scene's 40 ms). The default frame size's is mapped from the copy kept on disk
    (drawn_cache), others are drawn."""
    width, height = size

    def draw():
        rng = np.random.default_rng(4321)
        return rng.standard_normal((height + _NOISE_PAD, width + _NOISE_PAD, 3), dtype=np.float32)

    if (width, height) != (640, 480):
        return draw()
    return drawn_cache.kept("noise_tile", drawn_cache.key("camera_views.py"), draw, np.float32)


def _gamma_table(gamma: float) -> np.ndarray:
    return np.clip(255 * (np.arange(256) / 255) ** gamma + 0.5, 0, 255).astype(np.uint8)


def _apply_look(frame: np.ndarray, look: Look, rng: np.random.Generator, noise_tile=None) -> np.ndarray:
    # Grey levels (0-255) in float32 throughout: light, then noise, then rounded and saturated.
    # One gain map (gradient x gain x tint, built per channel and merged) and OpenCV's passes over
    # the frame take about 3 ms for 640x480, a third of numpy's step-by-step arithmetic.
    height, width = frame.shape[:2]
    image = frame.astype(np.float32)
    if look.blur > 0:
        image = cv2.GaussianBlur(image, (0, 0), look.blur)
    light = [look.gain * t for t in look.tint]  # per channel
    if look.gradient:
        a = math.radians(look.gradient_angle)
        x = (np.arange(width, dtype=np.float32) + 0.5) / width - 0.5
        y = (np.arange(height, dtype=np.float32) + 0.5) / height - 0.5
        ramp = np.add((np.float32(look.gradient * math.sin(a)) * y + 1)[:, None],
                      np.float32(look.gradient * math.cos(a)) * x, dtype=np.float32)
        cv2.multiply(image, cv2.merge([ramp * np.float32(v) for v in light]), dst=image)
    else:
        image *= np.asarray(light, np.float32)
    if look.noise > 0:
        if noise_tile is None:
            noise = rng.standard_normal(image.shape, dtype=np.float32)
        else:  # a random window of a fixed noise field: 5x cheaper, and it looks the same
            dy, dx = rng.integers(0, _NOISE_PAD, 2)
            noise = noise_tile[dy:dy + height, dx:dx + width]
        cv2.scaleAdd(noise, look.noise * (1 if rng.random() < 0.5 else -1), image, dst=image)
    out = cv2.convertScaleAbs(image)  # rounds and saturates to 0..255
    if look.gamma != 1:
        out = cv2.LUT(out, _gamma_table(look.gamma))
    if look.jpeg_quality is not None:
        ok, data = cv2.imencode(".jpg", out, [cv2.IMWRITE_JPEG_QUALITY, int(look.jpeg_quality)])
        out = cv2.imdecode(data, cv2.IMREAD_COLOR)
    return out
