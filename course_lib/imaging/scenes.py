"""Generated marker scenes: the board with a cat and a dog picture framed by ArUco markers, seen by a camera.

The board convention (which markers frame which picture, and which of their corners touch it)
is :mod:`course_lib.imaging.marker_board`'s. :func:`render_scene` draws a frame as a camera would see the
board (pose, lighting, noise, blur, JPEG, clutter, hidden or duplicated markers), deterministic by
seed, together with its ground truth (:class:`Scene`). :class:`CameraPath` moves the camera
smoothly over time for the virtual webcam.

Coordinates: frame and picture pixels follow OpenCV (the centre of pixel (0, 0) is the point
(0, 0)). The board is measured in board units; inside this module "edge" coordinates put the
top-left *corner* of a pixel at (0, 0), which is what makes homographies compose exactly.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import cv2
import numpy as np

from course_lib.imaging.boards import Board, TextureLevels, _paste_marker, _square, default_board
from course_lib.imaging.camera_views import (
    Look,
    Pose,
    _apply_look,
    _check_difficulty,
    _in_front,
    _noise_tile,
    _project,
    sample_look,
    sample_pose,
)
from course_lib.imaging.marker_board import DEFAULT_SIZE, PICTURES, _check_size, crop_corners
from course_lib.imaging.table import _plain_table, _table

#: A marker whose shortest side in the frame is below this many pixels is not counted as
#: detectable. 4x4 markers have 6x6 cells; in hard scenes (blur, noise, JPEG, dark gamma) the
#: default detector missed 1-5 % of markers of 20-30 pixels and none of 30 pixels or more.
MIN_MARKER_SIDE = 30.0

#: Markers closer than this to the frame border are not counted as detectable (ArUco's
#: minDistanceToBorder is 3 pixels).
FRAME_MARGIN = 4.0


# --------------------------------------------------------------------------------------------
# Scenes
# --------------------------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True, eq=False)
class Scene:
    """A rendered camera frame and its ground truth.

    Attributes:
        frame: the camera image, BGR uint8, shape (height, width, 3).
        marker_corners: board marker id -> its 4 corners in frame pixels, OpenCV order, float32
            (4, 2), for every marker that is printed and not occluded. Corners may lie outside the
            frame; see visible_ids and detectable_ids.
        duplicates: (id, corners) of extra copies of markers lying on the table (not part of the board).
        homographies: picture name -> 3x3 homography from picture pixels to frame pixels.
        board_homography: 3x3 homography from board units (edge coordinates) to frame pixels.
        missing_markers: board markers left off the print.
        occluded_markers: printed board markers (partly) covered by a finger.
        pose, look: the camera pose and the sensor/lighting settings used.
        board: the Board (its pictures are the sources of the expected crops).
        seed: the seed the scene was made from; time: the time on a CameraPath, else None.
        difficulty: "easy", "hard" or "path".
    """

    frame: np.ndarray
    marker_corners: dict[int, np.ndarray]
    duplicates: tuple[tuple[int, np.ndarray], ...]
    homographies: dict[str, np.ndarray]
    board_homography: np.ndarray
    missing_markers: tuple[int, ...]
    occluded_markers: tuple[int, ...]
    pose: Pose
    look: Look
    board: Board
    seed: object = None
    time: float | None = None
    difficulty: str = "easy"

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) of the frame."""
        return self.frame.shape[1], self.frame.shape[0]

    @property
    def visible_ids(self) -> tuple[int, ...]:
        """Board markers printed, not occluded and with all four corners inside the frame."""
        return tuple(i for i, c in sorted(self.marker_corners.items()) if _inside(c, self.size, 0.0))

    @property
    def detectable_ids(self) -> tuple[int, ...]:
        """Visible board markers FRAME_MARGIN pixels from the border and big enough (see MIN_MARKER_SIDE)."""
        return _detectable_ids(self.marker_corners, self.size)

    @property
    def fully_framed(self) -> tuple[str, ...]:
        """Pictures whose four markers are all detectable: a correct detector must find these."""
        return _framed(self.detectable_ids)

    def picture_corners(self, picture: str) -> np.ndarray:
        """True corners of a picture in frame pixels (even if off-frame or hidden), float32 (4, 2)."""
        if picture not in PICTURES:
            raise KeyError(f"Unknown picture {picture!r}: use one of {sorted(PICTURES)}")
        slot = self.board.picture_slot(picture)
        return _project(_EDGE_TO_CENTRE @ self.board_homography, slot).astype(np.float32)

    def expected_crops(self, size: tuple[int, int] = DEFAULT_SIZE, source: str = "frame") -> dict[str, np.ndarray]:
        """The crop of each picture a perfect detector would produce.

        Args:
            size: (width, height) of the crops.
            source: "frame" warps this frame with the true picture corners (same lighting, noise
                and any finger as the frame); "picture" resizes the source picture (what was printed).

        Returns:
            picture name -> BGR uint8 crop of shape (height, width, 3), for both pictures (check
            fully_framed to know which ones a detector can be asked for).

        Raises:
            ValueError: unknown source or bad size.
        """
        size = _check_size(size, "crop size")
        if source == "picture":
            return {name: cv2.resize(image, size, interpolation=cv2.INTER_AREA if image.shape[1] > size[0]
                                     else cv2.INTER_LINEAR) for name, image in self.board.pictures.items()}
        if source != "frame":
            raise ValueError(f"Unknown source {source!r}: use 'frame' or 'picture'")
        crops = {}
        for name in PICTURES:
            H = cv2.getPerspectiveTransform(self.picture_corners(name), crop_corners(size))
            crops[name] = cv2.warpPerspective(self.frame, H, size, flags=cv2.INTER_LINEAR)
        return crops


_EDGE_TO_CENTRE = np.array([[1, 0, -0.5], [0, 1, -0.5], [0, 0, 1.0]])


def _inside(corners: np.ndarray, size: tuple[int, int], margin: float) -> bool:
    width, height = size
    return bool(np.all(corners >= margin) and np.all(corners[:, 0] <= width - 1 - margin)
                and np.all(corners[:, 1] <= height - 1 - margin))


def _detectable_ids(marker_corners: dict[int, np.ndarray], size: tuple[int, int], min_side: float = MIN_MARKER_SIDE,
                    margin: float = FRAME_MARGIN) -> tuple[int, ...]:
    return tuple(i for i, c in sorted(marker_corners.items())
                 if _inside(c, size, margin) and _shortest_side(c) >= min_side)


def _framed(ids) -> tuple[str, ...]:
    ids = set(ids)
    return tuple(name for name, markers in PICTURES.items() if ids.issuperset(markers))


def _marker_corners(board: Board, H: np.ndarray, marker_id: int) -> np.ndarray:
    """A board marker's corners in frame pixels (OpenCV order, float32) for the board homography H."""
    return _project(_EDGE_TO_CENTRE @ H, board.marker_square(marker_id)).astype(np.float32)


def _shortest_side(corners: np.ndarray) -> float:
    return float(np.linalg.norm(corners - np.roll(corners, -1, axis=0), axis=1).min())


def render_scene(seed: int | Sequence[int] = 0, *, size: tuple[int, int] = (640, 480), difficulty: str = "easy",
                 board: Board | None = None, pose: Pose | None = None, look: Look | None = None,
                 missing_markers: Sequence[int] = (), occluded_markers: Sequence[int] = (),
                 duplicate_markers: Sequence[int] = ()) -> Scene:
    """Render the board as a camera sees it, with its ground truth. Same arguments, same frame.

    Args:
        seed: seeds every random choice (pose, look, clutter, occlusion, noise).
        size: (width, height) of the frame.
        difficulty: "easy" (whole board in view, mild light and noise) or "hard" (steep and
            rotated views, partly off-frame, strong light changes, noise, blur, JPEG, sometimes a
            finger over a marker).
        board: the board to show; the drawn cat and dog by default. Board(cat=img, dog=img)
            shows your own pictures.
        pose: camera pose to use instead of a random one (see Pose).
        look: lighting and sensor settings instead of random ones; Look() gives a clean frame.
        missing_markers: board marker ids left off the print.
        occluded_markers: board marker ids covered by a finger.
        duplicate_markers: ids of which a second copy lies on the table next to the board.

    Returns:
        Scene.

    Raises:
        ValueError: unknown difficulty, bad size, a marker id outside DICT_4X4_50 (0-49), or a
            pose that puts the board behind the camera.
    """
    _check_difficulty(difficulty)
    size = _check_size(size, "frame size")
    board = board or default_board()
    pose_rng, look_rng, table_rng, finger_rng, noise_rng = _generators(seed)
    sampled_pose = sample_pose(pose_rng, difficulty, size, board)
    sampled_look = sample_look(look_rng, difficulty)
    occluded = set(_check_ids(occluded_markers, "occluded_markers", board_only=True))
    if difficulty == "hard" and finger_rng.random() < 0.25:
        occluded.add(int(finger_rng.choice([i for ids in PICTURES.values() for i in ids])))
    look = look or sampled_look
    return _render(board, pose or sampled_pose, look, size,
                   missing=_check_ids(missing_markers, "missing_markers", board_only=True),
                   occluded=tuple(sorted(occluded)), duplicates=_check_ids(duplicate_markers, "duplicate_markers"),
                   table=lambda: _table(board, _seed_entropy(seed)), finger_rng=finger_rng, noise_rng=noise_rng,
                   seed=seed, difficulty=difficulty, noise_tile=_noise_tile(size) if look.noise > 0 else None)


def scene_pose(seed: int | Sequence[int] = 0, *, size: tuple[int, int] = (640, 480), difficulty: str = "easy",
               board: Board | None = None) -> Pose:
    """The camera pose of render_scene(seed, size=size, difficulty=difficulty, board=board), without drawing it."""
    return sample_pose(_generators(seed)[0], difficulty, _check_size(size, "frame size"), board or default_board())


def framed_from(pose: Pose, *, size: tuple[int, int] = (640, 480), board: Board | None = None) -> tuple[str, ...]:
    """The pictures whose four markers are detectable from `pose` when all are printed and none is
    covered: a scene's fully_framed with that pose is these or fewer. Draws nothing."""
    return _framed(detectable_from(pose, size=size, board=board))


def detectable_from(pose: Pose, *, size: tuple[int, int] = (640, 480), board: Board | None = None,
                    min_side: float = MIN_MARKER_SIDE, margin: float = FRAME_MARGIN) -> tuple[int, ...]:
    """The picture markers detectable from `pose` (a scene's detectable_ids with that pose, when
    all are printed and none is covered), ascending. Draws nothing.

    Args:
        min_side, margin: the shortest side a marker needs in the frame, and how far (pixels) its
            corners must be from the border; the defaults are the scenes' (MIN_MARKER_SIDE and
            FRAME_MARGIN), for frames that may be noisy, blurred and compressed. A clean frame
            needs less (see pan_camera).
    """
    size = _check_size(size, "frame size")
    board = board or default_board()
    H = pose.homography(board.size, size)
    corners = {i: _marker_corners(board, H, i) for ids in PICTURES.values() for i in ids}
    return _detectable_ids(corners, size, min_side, margin)


def _generators(seed) -> list[np.random.Generator]:
    """The random generators of a scene's pose, look, table, finger and noise."""
    return [np.random.default_rng(s) for s in np.random.SeedSequence(_seed_entropy(seed)).spawn(5)]


def _seed_entropy(seed) -> list[int]:
    values = [seed] if np.isscalar(seed) else list(seed)
    try:
        return [int(v) for v in values]
    except (TypeError, ValueError):
        raise ValueError(f"seed must be an integer or a sequence of integers, not {seed!r}") from None


def _check_ids(ids, what: str, board_only: bool = False) -> tuple[int, ...]:
    board_ids = {i for markers in PICTURES.values() for i in markers}
    result = []
    for i in ids:
        if not (isinstance(i, (int, np.integer)) and 0 <= i < 50):
            raise ValueError(f"{what} holds {i!r}: DICT_4X4_50 ids are integers 0-49")
        if board_only and i not in board_ids:
            raise ValueError(f"{what} holds {i}, which is not on the board: board markers are {sorted(board_ids)}")
        result.append(int(i))
    return tuple(result)


def _render(board: Board, pose: Pose, look: Look, size, *, missing, occluded, duplicates, table,
            finger_rng, noise_rng, seed, difficulty, time=None, supersample=None, noise_tile=None) -> Scene:
    width, height = size
    # Drawing at twice the size and shrinking anti-aliases edges; large frames need it less.
    k = supersample or (2 if width * height <= 1280 * 960 else 1)
    if not _in_front(pose, board, size):
        raise ValueError(f"{pose} puts part of the board behind or edge-on to the camera: use less tilt")
    H = pose.homography(board.size, size)                       # units -> frame edge coordinates
    to_super = np.array([[k, 0, -0.5], [0, k, -0.5], [0, 0, 1.0]]) @ H
    super_size = (width * k, height * k)

    # The table and its clutter lie in the board's plane, so they move with the board.
    table_levels, table_origin = table() if look.clutter else (_plain_table(), (0.0, 0.0))
    image = _warp_levels(table_levels, to_super @ _translation(*table_origin), super_size,
                         border=cv2.BORDER_REFLECT_101)
    image = _composite(image, board.texture(missing), to_super, super_size)
    duplicate_truth = []
    for marker_id, origin in zip(duplicates, _sticker_places(board, H, size, len(duplicates)), strict=True):
        sticker = _sticker(marker_id)
        image = _composite(image, TextureLevels.of([(4.0, sticker)]), to_super @ _translation(*origin), super_size)
        corners = _square(origin[0] + Board.QUIET, origin[1] + Board.QUIET, Board.MARKER)
        duplicate_truth.append((marker_id, _project(_EDGE_TO_CENTRE @ H, corners).astype(np.float32)))

    finger_mask = None  # where fingers cover the board (only drawn when a marker is occluded)
    if occluded:
        finger_mask = np.zeros(image.shape[:2], np.uint8)
        for marker_id in occluded:
            _draw_finger(image, finger_mask, _project(to_super, board.marker_square(marker_id)),
                         _project(to_super, [np.array(board.size) / 2])[0], finger_rng)
        finger_mask = cv2.resize(finger_mask, size, interpolation=cv2.INTER_AREA)
    frame = image if k == 1 else cv2.resize(image, size, interpolation=cv2.INTER_AREA)
    frame = _apply_look(frame, look, noise_rng, noise_tile)

    marker_corners, covered = {}, set()
    for marker_id in sorted(i for ids in PICTURES.values() for i in ids):
        if marker_id in missing:
            continue
        corners = _marker_corners(board, H, marker_id)
        if marker_id in occluded or (finger_mask is not None and _covered(finger_mask, corners)):
            covered.add(marker_id)
        else:
            marker_corners[marker_id] = corners
    homographies = {name: _EDGE_TO_CENTRE @ H @ board.picture_homography(name) for name in PICTURES}
    return Scene(frame=frame, marker_corners=marker_corners, duplicates=tuple(duplicate_truth),
                 homographies=homographies, board_homography=H, missing_markers=tuple(sorted(missing)),
                 occluded_markers=tuple(sorted(covered)), pose=pose, look=look, board=board, seed=seed,
                 time=time, difficulty=difficulty)


def _translation(x, y) -> np.ndarray:
    return np.array([[1, 0, x], [0, 1, y], [0, 0, 1.0]])


def _warp_levels(levels, to_super, super_size, border=cv2.BORDER_CONSTANT, flags=cv2.INTER_LINEAR):
    """Warp the texture level (pixels per unit, image) that best matches the on-screen scale."""
    scale, texture = _pick_level(levels, to_super)
    from_texture = to_super @ np.array([[1 / scale, 0, 0.5 / scale], [0, 1 / scale, 0.5 / scale], [0, 0, 1.0]])
    # Outside a BGRA texture: its edge colour, fully transparent, so that edges do not darken.
    outside = (*(float(v) for v in texture[0, 0, :3]), 0.0) if texture.shape[2] == 4 else 0
    return cv2.warpPerspective(texture, from_texture, super_size, flags=flags, borderMode=border,
                               borderValue=outside)


def _pick_level(levels: TextureLevels, to_super):
    """The coarsest level that still has at least one texture pixel per screen pixel everywhere."""
    texture_h, texture_w = levels.shapes[0][:2]
    w, h = texture_w / levels.scales[0], texture_h / levels.scales[0]
    probes = np.array([[0, 0], [w, 0], [w, h], [0, h], [w / 2, h / 2]], np.float64)
    base = _project(to_super, probes)
    dx = np.linalg.norm(_project(to_super, probes + [1, 0]) - base, axis=1)
    dy = np.linalg.norm(_project(to_super, probes + [0, 1]) - base, axis=1)
    needed = float(max(dx.max(), dy.max()))
    chosen = 0
    for index, scale in enumerate(levels.scales):
        if scale >= needed:
            chosen = index
    return levels[chosen]


def _composite(image: np.ndarray, levels, to_super, super_size) -> np.ndarray:
    """Paste a BGRA texture (a list of levels) through a homography onto image, in place; returns
    image. Only the texture's bounding box (2 pixels more for the interpolated edge) is warped:
    outside it the layer is fully transparent."""
    scale, shape = levels.scales[0], levels.shapes[0]
    outline = _project(to_super, _square(0, 0, 1) * [shape[1] / scale, shape[0] / scale])
    x0, y0 = np.maximum(np.floor(outline.min(axis=0)).astype(int) - 2, 0)
    x1, y1 = np.minimum(np.ceil(outline.max(axis=0)).astype(int) + 3, super_size)
    if x1 <= x0 or y1 <= y0:
        return image
    layer = _warp_levels(levels, _translation(-x0, -y0) @ to_super, (int(x1 - x0), int(y1 - y0)))
    _blend(image[y0:y1, x0:x1], layer)
    return image


def _blend(box: np.ndarray, layer: np.ndarray) -> None:
    """box = layer over box by the layer's alpha, in place: cv2.blendLinear's pixels (weights alpha / 255
    and 1 - alpha / 255). Where alpha is 255 that is the layer's pixel and where it is 0 the box's, so
    only the pixels in between (a textured layer's anti-aliased edge, about 0.2 % of a board's box)
    are blended: a fifth of the processor time of blending the whole box."""
    alpha = cv2.extractChannel(layer, 3)
    edge = cv2.findNonZero(cv2.inRange(alpha, 1, 254))
    if edge is not None:
        xs, ys = edge.reshape(-1, 2).T
        weight = alpha[ys, xs].astype(np.float32)[:, None] * np.float32(1 / 255)
        blended = cv2.blendLinear(layer[ys, xs, :3][:, None], box[ys, xs][:, None], weight, 1 - weight)
    cv2.copyTo(cv2.cvtColor(layer, cv2.COLOR_BGRA2BGR), alpha, box)
    if edge is not None:
        box[ys, xs] = blended[:, 0]


def _sticker(marker_id: int) -> np.ndarray:
    scale, side = 4, Board.MARKER + 2 * Board.QUIET
    sticker = np.empty((side * scale, side * scale, 4), np.uint8)
    sticker[:] = (250, 250, 250, 255)
    _paste_marker(sticker, marker_id, Board.QUIET * scale, Board.QUIET * scale, Board.MARKER * scale)
    return sticker


def _sticker_places(board: Board, H, size, count: int) -> list[tuple[float, float]]:
    """Top-left corners (units) of stickers on the table next to the board, in view where possible."""
    bw, bh = board.size
    side = Board.MARKER + 2 * Board.QUIET
    gap = 16
    candidates = [(bw / 2, bh + gap), (bw / 2, -gap - side), (bw * 0.15, bh + gap), (bw * 0.85 - side, bh + gap),
                  (bw * 0.15, -gap - side), (bw * 0.85 - side, -gap - side), (-gap - side, bh / 2 - side / 2),
                  (bw + gap, bh / 2 - side / 2)]
    width, height = size

    def in_view(origin):
        corners = _project(_EDGE_TO_CENTRE @ H, _square(origin[0] + Board.QUIET, origin[1] + Board.QUIET, Board.MARKER))
        return bool(np.all(corners >= FRAME_MARGIN) and np.all(corners[:, 0] <= width - 1 - FRAME_MARGIN)
                    and np.all(corners[:, 1] <= height - 1 - FRAME_MARGIN))

    ordered = [c for c in candidates if in_view(c)] + [c for c in candidates if not in_view(c)]
    return [ordered[i % len(ordered)] for i in range(count)]


def _draw_finger(image, mask, marker, board_centre, rng) -> None:
    """A fingertip over a marker, reaching in from outside the board."""
    centre = marker.mean(axis=0) + rng.uniform(-0.1, 0.1, 2) * _shortest_side(marker)
    side = float(np.sqrt(cv2.contourArea(marker.astype(np.float32))))
    direction = centre - board_centre
    direction /= max(np.linalg.norm(direction), 1e-9)
    angle = math.degrees(math.atan2(direction[1], direction[0]))
    skin = tuple(float(v) for v in np.array([120, 160, 215]) * rng.uniform(0.85, 1.1))
    half_width = side * rng.uniform(0.62, 0.72)
    tip = centre - direction * side * 0.3
    far = tip + direction * side * 6
    normal = np.array([-direction[1], direction[0]])
    finger = np.array([tip + normal * half_width, far + normal * half_width,
                       far - normal * half_width, tip - normal * half_width])
    for target, colour in ((image, skin), (mask, 255)):
        cv2.fillConvexPoly(target, np.round(finger * 16).astype(np.int32), colour, cv2.LINE_AA, shift=4)
        cv2.ellipse(target, ((float(tip[0]), float(tip[1])), (2 * half_width, 2 * half_width * 1.2), angle + 90),
                    colour, -1, cv2.LINE_AA)
    nail = tip + direction * side * 0.15
    cv2.ellipse(image, ((float(nail[0]), float(nail[1])), (half_width, half_width * 0.8), angle + 90),
                tuple(min(255.0, c * 1.15) for c in skin), -1, cv2.LINE_AA)


def _covered(mask: np.ndarray, corners: np.ndarray) -> bool:
    """True when a finger covers any noticeable part of the marker."""
    poly = np.zeros_like(mask)
    cv2.fillConvexPoly(poly, np.round(corners * 16).astype(np.int32), 255, cv2.LINE_8, shift=4)
    area = int(np.count_nonzero(poly))
    return area > 0 and np.count_nonzero((mask > 64) & (poly > 0)) > 0.01 * area


# --------------------------------------------------------------------------------------------
# A camera moving over time
# --------------------------------------------------------------------------------------------

class CameraPath:
    """A hand-held camera drifting smoothly over the board while the light changes slowly.

    Every quantity is a slow sine wave with a seeded period and phase, so the path is smooth,
    never leaves the board out of view (both pictures stay fully framed) and is the same for
    the same seed. The brightness swings by about +-30 % over 20-30 seconds.

    Args:
        seed: chooses the path, the table and the noise.
        size: (width, height) of the frames.
        board: the board to film; the drawn cat and dog by default.
        noise: sensor noise, grey levels.

    Example:
        >>> path = CameraPath(seed=1)
        >>> scene = path.scene_at(2.5)      # the frame 2.5 s into the path, with ground truth
    """

    def __init__(self, seed: int = 0, *, size: tuple[int, int] = (640, 480), board: Board | None = None,
                 noise: float = 2.0):
        self.seed = int(seed)
        self.size = _check_size(size, "frame size")
        self.board = board or default_board()
        self.noise = float(noise)
        rng = np.random.default_rng(np.random.SeedSequence([self.seed, 99]))

        def wave(amplitude, shortest, longest):
            return amplitude, rng.uniform(shortest, longest), rng.uniform(0, 2 * math.pi)

        self._waves = {"tilt_x": wave(10, 17, 23), "tilt_y": wave(12, 13, 19), "roll": wave(8, 25, 35),
                       "scale": wave(0.04, 11, 15), "cx": wave(0.025, 9, 12), "cy": wave(0.025, 8, 11),
                       "gain": wave(0.3, 20, 30), "gradient": wave(0.1, 30, 40)}
        self._gradient_period = rng.uniform(50, 70)
        self._noise_tile = _noise_tile(self.size)

    def _value(self, name: str, t: float) -> float:
        amplitude, period, phase = self._waves[name]
        return amplitude * math.sin(2 * math.pi * t / period + phase)

    def pose_at(self, t: float) -> Pose:
        """The camera pose t seconds into the path."""
        v = self._value
        return Pose(tilt_x=v("tilt_x", t), tilt_y=v("tilt_y", t), roll=v("roll", t), scale=0.8 + v("scale", t),
                    center=(v("cx", t), v("cy", t)), focal=1.0)

    def look_at(self, t: float) -> Look:
        """Lighting and noise t seconds into the path (no blur or JPEG: a raw webcam frame)."""
        return Look(gain=1 + self._value("gain", t), gradient=0.12 + self._value("gradient", t),
                    gradient_angle=360 * t / self._gradient_period, noise=self.noise)

    def scene_at(self, t: float) -> Scene:
        """The frame and its ground truth t seconds into the path (same t, same frame)."""
        t = float(t)
        tick = int(round(t * 1000))  # noise differs per millisecond of path time
        noise_rng = np.random.default_rng(np.random.SeedSequence([self.seed, 98, tick & 0xFFFFFFFF, tick >> 32]))
        return _render(self.board, self.pose_at(t), self.look_at(t), self.size, missing=(), occluded=(), duplicates=(),
                       table=lambda: _table(self.board, [self.seed, 97]), finger_rng=None, noise_rng=noise_rng,
                       seed=self.seed, difficulty="path", time=t, supersample=1, noise_tile=self._noise_tile)
