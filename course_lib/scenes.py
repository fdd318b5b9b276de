"""Generated marker scenes: a board with a cat and a dog picture framed by ArUco markers, seen by a camera.

The vision lessons and the graders share one convention, written once here:

- Markers come from ArUco's ``DICT_4X4_50`` (:func:`dictionary`, :func:`detector`).
- The cat is framed by markers 1, 2, 3, 4 and the dog by markers 5, 6, 7, 8, in the order
  top-left, top-right, bottom-right, bottom-left (:data:`PICTURES`).
- Each marker sits just outside its picture corner and touches it with one of its own corners
  (OpenCV order: 0 top-left, 1 top-right, 2 bottom-right, 3 bottom-left of the upright marker).
  The picture's corners are marker 1's corner 2, marker 2's corner 3, marker 3's corner 0 and
  marker 4's corner 1 (:data:`CORNER_OF_MARKER`); no picture content is hidden by a marker.
- A crop maps the picture's top-left corner to pixel (0, 0) and its other corners to the other
  corner pixels of the crop (:func:`crop_corners`); the default crop is 320x240 (width x height),
  BGR, uint8 (:data:`DEFAULT_SIZE`).

:func:`render_scene` draws a frame as a camera would see the board (pose, lighting, noise, blur,
JPEG, clutter, hidden or duplicated markers), deterministic by seed, together with its ground
truth (:class:`Scene`). :class:`CameraPath` moves the camera smoothly over time for the virtual
webcam. :func:`crop_similarity` compares a crop with the expected one.

Coordinates: frame and picture pixels follow OpenCV (the centre of pixel (0, 0) is the point
(0, 0)). The board is measured in board units; inside this module "edge" coordinates put the
top-left *corner* of a pixel at (0, 0), which is what makes homographies compose exactly.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence

import cv2
import numpy as np

# --------------------------------------------------------------------------------------------
# The convention
# --------------------------------------------------------------------------------------------

#: The ArUco dictionary of every marker in the course.
ARUCO_DICTIONARY = cv2.aruco.DICT_4X4_50

#: Marker ids framing each picture, in the order top-left, top-right, bottom-right, bottom-left.
PICTURES: dict[str, tuple[int, int, int, int]] = {"cat": (1, 2, 3, 4), "dog": (5, 6, 7, 8)}

#: For the markers in PICTURES order: which of the marker's own corners is the picture's corner.
CORNER_OF_MARKER: tuple[int, int, int, int] = (2, 3, 0, 1)

#: Default crop size, (width, height) as OpenCV takes it.
DEFAULT_SIZE: tuple[int, int] = (320, 240)

#: crop_similarity at or above this means "the same crop". Measured on seeds 0-99 easy and
#: 0-299 hard with a reference detect + warp (as in tests/test_scenes.py): correct crops of all 299
#: fully framed pictures scored 0.967 or more against expected_crops() (0.91 or more against the
#: printed picture, source="picture"), while crops with the corners in a wrong order (mirrored,
#: upside down, rotated by 90/180/270 degrees) or of the other picture scored 0.53 at most. The
#: threshold sits between the groups with a margin on both sides.
SAME_CROP_THRESHOLD = 0.8

#: A marker whose shortest side in the frame is below this many pixels is not counted as
#: detectable. 4x4 markers have 6x6 cells; in hard scenes (blur, noise, JPEG, dark gamma) the
#: default detector missed 1-5 % of markers of 20-30 pixels and none of 30 pixels or more.
MIN_MARKER_SIDE = 30.0

#: Markers closer than this to the frame border are not counted as detectable (ArUco's
#: minDistanceToBorder is 3 pixels).
FRAME_MARGIN = 4.0

DIFFICULTIES = ("easy", "hard")


def dictionary() -> cv2.aruco.Dictionary:
    """The course's ArUco dictionary (DICT_4X4_50)."""
    return cv2.aruco.getPredefinedDictionary(ARUCO_DICTIONARY)


def detector(parameters: cv2.aruco.DetectorParameters | None = None) -> cv2.aruco.ArucoDetector:
    """An ArucoDetector for the course's markers.

    Args:
        parameters: detector parameters; OpenCV's defaults when None.

    Returns:
        ``cv2.aruco.ArucoDetector``; call ``detectMarkers(image)`` to get ``(corners, ids, rejected)``.
    """
    return cv2.aruco.ArucoDetector(dictionary(), parameters or cv2.aruco.DetectorParameters())


def picture_corners(marker_corners_by_id: Mapping[int, np.ndarray], picture: str) -> np.ndarray | None:
    """The four corners of a picture from the corners of its markers.

    Args:
        marker_corners_by_id: marker id -> that marker's 4 corners in OpenCV order, shape (4, 2)
            or (1, 4, 2) as ``detectMarkers`` returns them.
        picture: "cat" or "dog" (a key of PICTURES).

    Returns:
        float32 array (4, 2): the picture's top-left, top-right, bottom-right and bottom-left
        corners, or None when one of the picture's markers is missing from the mapping.

    Raises:
        KeyError: unknown picture name.
    """
    if picture not in PICTURES:
        raise KeyError(f"Unknown picture {picture!r}: use one of {sorted(PICTURES)}")
    corners = []
    for marker_id, corner in zip(PICTURES[picture], CORNER_OF_MARKER):
        if marker_id not in marker_corners_by_id:
            return None
        marker = np.asarray(marker_corners_by_id[marker_id], dtype=np.float32).reshape(4, 2)
        corners.append(marker[corner])
    return np.array(corners, dtype=np.float32)


def crop_corners(size: tuple[int, int] = DEFAULT_SIZE) -> np.ndarray:
    """Where a picture's four corners go in a crop of the given (width, height).

    Returns:
        float32 array (4, 2): (0, 0), (w-1, 0), (w-1, h-1), (0, h-1), the centres of the crop's
        corner pixels, in PICTURES order (top-left, top-right, bottom-right, bottom-left).
    """
    width, height = _check_size(size, "crop size")
    return np.array([[0, 0], [width - 1, 0], [width - 1, height - 1], [0, height - 1]], dtype=np.float32)


# --------------------------------------------------------------------------------------------
# Comparing crops
# --------------------------------------------------------------------------------------------

_COMPARE_WIDTH = 80


def crop_similarity(a: np.ndarray, b: np.ndarray) -> float:
    """How alike two crops are, from 0 (unrelated or inverted) to 1 (the same picture).

    Both crops are turned grey, shrunk to 80 pixels wide (b to a's shape), blurred a little,
    stripped of a 5 % border and compared by normalised cross-correlation, clipped at 0.
    Shrinking, blurring and the border forgive a corner that is off by a pixel or two;
    normalising forgives brightness and contrast changes; a crop that is mirrored, rotated or
    of the other picture correlates weakly.
    Compare the result with SAME_CROP_THRESHOLD.

    Args:
        a, b: images, BGR or grey, any dtype that OpenCV can convert (uint8 is usual).

    Returns:
        A float in [0, 1].

    Raises:
        ValueError: an input is not a 2-D or 3-D image with at least one pixel.
    """
    ga, gb = _grey(a, "a"), _grey(b, "b")
    height = max(1, round(_COMPARE_WIDTH * ga.shape[0] / ga.shape[1]))
    shape = (_COMPARE_WIDTH, height)
    ga = cv2.GaussianBlur(cv2.resize(ga, shape, interpolation=cv2.INTER_AREA), (0, 0), 1.0)
    gb = cv2.GaussianBlur(cv2.resize(gb, shape, interpolation=cv2.INTER_AREA), (0, 0), 1.0)
    # Leave out a 5 % border: a corner off by a pixel or two shows a sliver of board there,
    # which would otherwise dominate low-contrast pictures.
    my, mx = height // 20, _COMPARE_WIDTH // 20
    if height > 2 * my + 2:
        ga, gb = ga[my:height - my, mx:-mx], gb[my:height - my, mx:-mx]
    ga -= ga.mean()
    gb -= gb.mean()
    na, nb = float(np.sqrt((ga * ga).sum())), float(np.sqrt((gb * gb).sum()))
    flat = 1e-3 * ga.size  # below ~0.03 grey levels of spread, an image is flat
    if na < flat or nb < flat:
        # Correlation is undefined for a flat image: two flat crops are alike, one is not.
        return 1.0 if na < flat and nb < flat else 0.0
    return float(np.clip((ga * gb).sum() / (na * nb), 0.0, 1.0))


def _grey(image: np.ndarray, name: str) -> np.ndarray:
    image = np.asarray(image)
    if image.ndim not in (2, 3) or image.shape[0] == 0 or image.shape[1] == 0:
        raise ValueError(f"{name} must be an image of shape (height, width) or (height, width, 3), "
                         f"not {image.shape}")
    if image.ndim == 3:
        if image.shape[2] == 1:
            image = image[:, :, 0]
        elif image.shape[2] in (3, 4):
            image = cv2.cvtColor(image.astype(np.float32), cv2.COLOR_BGR2GRAY if image.shape[2] == 3
                                 else cv2.COLOR_BGRA2GRAY)
        else:
            raise ValueError(f"{name} has {image.shape[2]} channels: pass a BGR or grey image")
    return image.astype(np.float32)


# --------------------------------------------------------------------------------------------
# The pictures
# --------------------------------------------------------------------------------------------

def draw_cat(size: tuple[int, int] = DEFAULT_SIZE) -> np.ndarray:
    """A cartoon cat sitting in a room (window on the left, ball of wool on the right).

    The drawing is deliberately not left-right symmetric, so a mirrored crop looks different.

    Args:
        size: (width, height) of the picture.

    Returns:
        BGR uint8 image of that size.
    """
    width, height = _check_size(size, "picture size")
    s = 4  # draw at 4x and shrink, for smooth edges at any size
    w, h = 320 * s, 240 * s
    img = np.empty((h, w, 3), np.uint8)
    img[:] = (214, 228, 246)                       # pale peach wall
    img[int(h * 0.72):] = (168, 200, 226)           # light wooden floor
    for x in range(0, w, 40 * s):                   # floor boards
        cv2.line(img, (x, int(h * 0.72)), (x - 30 * s, h), (150, 182, 210), 2 * s, cv2.LINE_AA)
    cv2.line(img, (0, int(h * 0.72)), (w, int(h * 0.72)), (120, 150, 180), 3 * s, cv2.LINE_AA)
    # Window, upper left.
    cv2.rectangle(img, (30 * s, 28 * s), (112 * s, 110 * s), (240, 205, 150), -1)
    cv2.circle(img, (50 * s, 48 * s), 10 * s, (120, 235, 255), -1, cv2.LINE_AA)
    cv2.rectangle(img, (30 * s, 28 * s), (112 * s, 110 * s), (90, 120, 160), 5 * s)
    cv2.line(img, (71 * s, 28 * s), (71 * s, 110 * s), (90, 120, 160), 4 * s)
    cv2.line(img, (30 * s, 69 * s), (112 * s, 69 * s), (90, 120, 160), 4 * s)
    # Picture frame on the wall, upper right, tilted.
    box = cv2.boxPoints(((262 * s, 52 * s), (44 * s, 34 * s), -8)).astype(np.int32)
    cv2.fillConvexPoly(img, box, (150, 190, 120), cv2.LINE_AA)
    cv2.polylines(img, [box], True, (60, 80, 110), 3 * s, cv2.LINE_AA)
    fur, dark, pink = (70, 150, 235), (30, 90, 180), (170, 160, 245)
    # Tail curling out to the right.
    tail = np.array([[190, 200], [222, 196], [242, 178], [246, 150], [236, 132]], np.int32) * s
    cv2.polylines(img, [tail], False, dark, 13 * s, cv2.LINE_AA)
    cv2.polylines(img, [tail], False, fur, 9 * s, cv2.LINE_AA)
    # Body and front paws.
    cv2.ellipse(img, (150 * s, 168 * s), (52 * s, 50 * s), 0, 0, 360, fur, -1, cv2.LINE_AA)
    cv2.ellipse(img, (150 * s, 178 * s), (30 * s, 34 * s), 0, 0, 360, (200, 225, 250), -1, cv2.LINE_AA)
    for x in (128, 170):
        cv2.ellipse(img, (x * s, 214 * s), (14 * s, 8 * s), 0, 0, 360, (215, 235, 252), -1, cv2.LINE_AA)
    # Head with ears.
    cx, cy = 150 * s, 100 * s
    for sign in (-1, 1):
        ear = np.array([[cx + sign * 44 * s, cy - 12 * s], [cx + sign * 40 * s, cy - 62 * s],
                        [cx + sign * 10 * s, cy - 34 * s]], np.int32)
        inner = np.array([[cx + sign * 36 * s, cy - 20 * s], [cx + sign * 37 * s, cy - 50 * s],
                          [cx + sign * 18 * s, cy - 33 * s]], np.int32)
        cv2.fillConvexPoly(img, ear, fur, cv2.LINE_AA)
        cv2.fillConvexPoly(img, inner, pink, cv2.LINE_AA)
    cv2.ellipse(img, (cx, cy), (48 * s, 40 * s), 0, 0, 360, fur, -1, cv2.LINE_AA)
    for dx in (-12, 0, 12):                          # forehead stripes
        cv2.line(img, (cx + dx * s, cy - 38 * s), (cx + dx * s // 2, cy - 24 * s), dark, 4 * s, cv2.LINE_AA)
    cv2.ellipse(img, (cx, cy + 16 * s), (22 * s, 15 * s), 0, 0, 360, (215, 235, 252), -1, cv2.LINE_AA)
    for sign in (-1, 1):                             # green eyes with slit pupils
        ex = cx + sign * 19 * s
        cv2.ellipse(img, (ex, cy - 4 * s), (10 * s, 8 * s), 0, 0, 360, (60, 190, 90), -1, cv2.LINE_AA)
        cv2.ellipse(img, (ex, cy - 4 * s), (3 * s, 7 * s), 0, 0, 360, (20, 20, 20), -1, cv2.LINE_AA)
        cv2.circle(img, (ex - 3 * s, cy - 7 * s), 2 * s, (255, 255, 255), -1, cv2.LINE_AA)
    nose = np.array([[cx - 6 * s, cy + 8 * s], [cx + 6 * s, cy + 8 * s], [cx, cy + 15 * s]], np.int32)
    cv2.fillConvexPoly(img, nose, (140, 110, 230), cv2.LINE_AA)
    cv2.ellipse(img, (cx - 6 * s, cy + 18 * s), (6 * s, 5 * s), 0, 0, 180, (40, 40, 40), 2 * s, cv2.LINE_AA)
    cv2.ellipse(img, (cx + 6 * s, cy + 18 * s), (6 * s, 5 * s), 0, 0, 180, (40, 40, 40), 2 * s, cv2.LINE_AA)
    for sign in (-1, 1):                             # whiskers
        for dy, slope in ((10, -8), (16, 0), (22, 8)):
            start = (cx + sign * 16 * s, cy + dy * s)
            end = (cx + sign * 62 * s, cy + (dy + slope) * s)
            cv2.line(img, start, end, (50, 50, 50), 2 * s, cv2.LINE_AA)
    # Ball of wool on the floor, lower right.
    cv2.circle(img, (268 * s, 206 * s), 20 * s, (70, 60, 200), -1, cv2.LINE_AA)
    for angle in (20, 70, 120):
        cv2.ellipse(img, (268 * s, 206 * s), (20 * s, 8 * s), angle, 0, 360, (40, 30, 150), 2 * s, cv2.LINE_AA)
    cv2.line(img, (250 * s, 216 * s), (212 * s, 228 * s), (70, 60, 200), 2 * s, cv2.LINE_AA)
    return cv2.resize(img, (width, height), interpolation=cv2.INTER_AREA)


def draw_dog(size: tuple[int, int] = DEFAULT_SIZE) -> np.ndarray:
    """A cartoon dog on a lawn (sun top right, bone bottom left), floppy ears and tongue out.

    The drawing is deliberately not left-right symmetric, so a mirrored crop looks different.

    Args:
        size: (width, height) of the picture.

    Returns:
        BGR uint8 image of that size.
    """
    width, height = _check_size(size, "picture size")
    s = 4
    w, h = 320 * s, 240 * s
    img = np.empty((h, w, 3), np.uint8)
    img[:] = (245, 222, 190)                        # pale blue sky
    lawn = np.array([[0, 118], [320, 158], [320, 240], [0, 240]], np.int32) * s   # sloping lawn
    cv2.fillConvexPoly(img, lawn, (140, 212, 150), cv2.LINE_AA)
    cv2.ellipse(img, (40 * s, 124 * s), (90 * s, 34 * s), 0, 180, 360, (120, 190, 130), -1, cv2.LINE_AA)
    cv2.fillConvexPoly(img, np.array([[0, 124], [130, 124], [130, 150], [0, 150]], np.int32) * s,
                       (120, 190, 130))
    cv2.fillConvexPoly(img, lawn, (140, 212, 150), cv2.LINE_AA)
    cv2.circle(img, (272 * s, 40 * s), 22 * s, (90, 215, 255), -1, cv2.LINE_AA)          # sun
    for k in range(8):
        a = k * math.pi / 4
        p1 = (int(272 * s + 28 * s * math.cos(a)), int(40 * s + 28 * s * math.sin(a)))
        p2 = (int(272 * s + 38 * s * math.cos(a)), int(40 * s + 38 * s * math.sin(a)))
        cv2.line(img, p1, p2, (90, 215, 255), 3 * s, cv2.LINE_AA)
    for x, y in ((50, 40), (90, 30)):                                                       # cloud
        cv2.ellipse(img, (x * s, y * s), (26 * s, 12 * s), 0, 0, 360, (252, 250, 248), -1, cv2.LINE_AA)
    for x in range(12, 320, 22):                                                            # grass blades
        cv2.line(img, (x * s, 236 * s), ((x + 4) * s, 226 * s), (90, 170, 100), 2 * s, cv2.LINE_AA)
    # Bone, lower left.
    cv2.line(img, (34 * s, 206 * s), (84 * s, 194 * s), (235, 245, 250), 9 * s, cv2.LINE_AA)
    for x, y in ((34, 206), (84, 194)):
        for d in (-5, 5):
            cv2.circle(img, ((x - 2) * s, (y + d) * s), 6 * s, (235, 245, 250), -1, cv2.LINE_AA)
    brown, dark, light = (60, 110, 170), (30, 55, 95), (150, 195, 230)
    # Body sitting, a little right of centre, and a red collar.
    cv2.ellipse(img, (190 * s, 184 * s), (50 * s, 44 * s), 0, 0, 360, brown, -1, cv2.LINE_AA)
    cv2.ellipse(img, (242 * s, 214 * s), (22 * s, 10 * s), -20, 0, 360, brown, -1, cv2.LINE_AA)  # back leg
    cv2.ellipse(img, (170 * s, 222 * s), (14 * s, 8 * s), 0, 0, 360, light, -1, cv2.LINE_AA)
    cv2.ellipse(img, (206 * s, 222 * s), (14 * s, 8 * s), 0, 0, 360, light, -1, cv2.LINE_AA)
    cx, cy = 184 * s, 98 * s
    cv2.ellipse(img, (cx, cy + 42 * s), (34 * s, 8 * s), 0, 0, 360, (40, 40, 200), -1, cv2.LINE_AA)
    cv2.circle(img, (cx + 8 * s, cy + 52 * s), 6 * s, (40, 200, 240), -1, cv2.LINE_AA)     # tag
    # Head.
    cv2.ellipse(img, (cx, cy), (44 * s, 42 * s), 0, 0, 360, brown, -1, cv2.LINE_AA)
    cv2.ellipse(img, (cx + 16 * s, cy - 14 * s), (14 * s, 12 * s), 0, 0, 360, light, -1, cv2.LINE_AA)  # eye patch
    # Floppy ears hanging down beside the head.
    cv2.ellipse(img, (cx - 44 * s, cy + 8 * s), (14 * s, 36 * s), 18, 0, 360, dark, -1, cv2.LINE_AA)
    cv2.ellipse(img, (cx + 44 * s, cy + 8 * s), (14 * s, 36 * s), -18, 0, 360, dark, -1, cv2.LINE_AA)
    for ex in (cx - 16 * s, cx + 16 * s):
        cv2.circle(img, (ex, cy - 12 * s), 7 * s, (255, 255, 255), -1, cv2.LINE_AA)
        cv2.circle(img, (ex + 2 * s, cy - 11 * s), 4 * s, (20, 20, 20), -1, cv2.LINE_AA)
    cv2.ellipse(img, (cx, cy + 16 * s), (24 * s, 17 * s), 0, 0, 360, light, -1, cv2.LINE_AA)   # snout
    cv2.ellipse(img, (cx, cy + 6 * s), (9 * s, 6 * s), 0, 0, 360, (25, 25, 25), -1, cv2.LINE_AA)  # nose
    cv2.line(img, (cx, cy + 12 * s), (cx, cy + 20 * s), (25, 25, 25), 2 * s, cv2.LINE_AA)
    cv2.ellipse(img, (cx, cy + 20 * s), (12 * s, 6 * s), 0, 0, 180, (25, 25, 25), 2 * s, cv2.LINE_AA)
    # Tongue hanging out to the dog's left (our right).
    cv2.ellipse(img, (cx + 6 * s, cy + 32 * s), (8 * s, 12 * s), -10, 0, 360, (130, 110, 240), -1, cv2.LINE_AA)
    cv2.line(img, (cx + 6 * s, cy + 26 * s), (cx + 7 * s, cy + 38 * s), (100, 80, 200), 2 * s, cv2.LINE_AA)
    return cv2.resize(img, (width, height), interpolation=cv2.INTER_AREA)


def draw_photo(seed: int = 0, size: tuple[int, int] = (400, 300)) -> np.ndarray:
    """A photograph-like picture whose corners are dark (a strong vignette), deterministic by seed.

    Made offline from seeded noise: a sky-to-ground gradient with a seeded horizon, soft detail
    at several scales (like leaves, clouds or texture), a few blurred bright spots (like lights
    out of focus) and lens vignetting that darkens the corners almost to black. Such corners are
    the hard case for markers that touch them (see dark_corner_board).

    Args:
        seed: chooses colours, horizon, detail, spots and how dark the corners get.
        size: (width, height) of the picture.

    Returns:
        BGR uint8 image of that size.
    """
    width, height = _check_size(size, "picture size")
    rng = np.random.default_rng(np.random.SeedSequence([_seed_entropy(seed)[0], 555]))
    y = (np.arange(height, dtype=np.float32) + 0.5) / height
    x = (np.arange(width, dtype=np.float32) + 0.5) / width
    horizon = rng.uniform(0.3, 0.7) + rng.uniform(-0.15, 0.15) * (x - 0.5)
    ground = (y[:, None] > horizon[None, :]).astype(np.float32)
    ground = cv2.GaussianBlur(ground, (0, 0), max(1.0, 0.01 * width))[:, :, None]
    sky, earth = rng.uniform(70, 230, 3), rng.uniform(30, 170, 3)
    image = (1 - ground) * sky.astype(np.float32) + ground * earth.astype(np.float32)
    detail = np.zeros((height, width, 3), np.float32)
    for cells, weight in ((4, 1.0), (8, 0.5), (16, 0.25), (32, 0.12)):
        grid = rng.normal(0, 1, (max(2, cells * height // width) + 2, cells + 2, 3)).astype(np.float32)
        detail += weight * cv2.resize(grid, (width, height), interpolation=cv2.INTER_CUBIC)
    image += rng.uniform(20, 45) * detail
    for _ in range(int(rng.integers(2, 6))):                     # out-of-focus lights
        centre = (float(rng.uniform(0.15, 0.85) * width), float(rng.uniform(0.15, 0.85) * height))
        spot = np.zeros((height, width), np.float32)
        cv2.circle(spot, (int(centre[0]), int(centre[1])), int(rng.uniform(0.03, 0.08) * width), 1.0, -1)
        spot = cv2.GaussianBlur(spot, (0, 0), 0.02 * width)
        image += spot[:, :, None] * rng.uniform(60, 140, 3).astype(np.float32)
    radius2 = ((x[None, :] - 0.5) ** 2 + (y[:, None] - 0.5) ** 2) * 2   # 1 at the corners
    vignette = np.clip(1 - rng.uniform(0.9, 1.0) * radius2 ** rng.uniform(1.0, 2.0), 0.02, 1)
    return np.clip(image * vignette[:, :, None], 0, 255).astype(np.uint8)


def dark_corner_board(seed: int = 0) -> Board:
    """A board whose cat and dog slots hold two draw_photo pictures (seeds 2*seed and 2*seed+1).

    Every board marker touches a nearly black picture corner, which is where the stock ArUco
    detector can miss it: render_scene(seed, board=dark_corner_board(seed)).
    """
    first = 2 * _seed_entropy(seed)[0]
    return Board(cat=draw_photo(first), dog=draw_photo(first + 1))


def _check_size(size, what: str) -> tuple[int, int]:
    try:
        width, height = (int(v) for v in size)
    except (TypeError, ValueError):
        raise ValueError(f"{what} must be (width, height), for example (320, 240), not {size!r}") from None
    if width < 1 or height < 1:
        raise ValueError(f"{what} must be at least 1x1 pixels, not {width}x{height}")
    return width, height


# --------------------------------------------------------------------------------------------
# The board
# --------------------------------------------------------------------------------------------

class Board:
    """The flat board: the cat and dog pictures side by side, each framed by its four markers.

    Lengths are in board units: a picture slot is 320x240 units, a marker 96 units (16 per cell)
    with at least 24 units (1.5 cells) of white paper around it.

    Args:
        cat, dog: BGR (or grey) images to show instead of the drawn cat and dog; any size, they
            are stretched to the 4:3 slot. Picture pixels in Scene homographies are pixels of
            these images.

    Raises:
        ValueError: an image is not 2-D/3-D uint8 with at least one pixel.
    """

    PICTURE_SIZE = (320, 240)
    MARKER = 96
    QUIET = 24
    GAP = 48
    PAPER = (236, 240, 242)

    def __init__(self, cat: np.ndarray | None = None, dog: np.ndarray | None = None):
        self.pictures: dict[str, np.ndarray] = {
            "cat": draw_cat() if cat is None else _as_bgr(cat, "cat"),
            "dog": draw_dog() if dog is None else _as_bgr(dog, "dog"),
        }
        m, q, (pw, ph) = self.MARKER, self.QUIET, self.PICTURE_SIZE
        left = q + m
        self._slots = {"cat": (left, q + m, left + pw, q + m + ph)}
        left = left + pw + m + self.GAP + m
        self._slots["dog"] = (left, q + m, left + pw, q + m + ph)
        self.size = (left + pw + m + q, q + m + ph + m + q)  # (width, height) in units
        self._textures: dict[frozenset, list[tuple[float, np.ndarray]]] = {}

    def picture_slot(self, picture: str) -> np.ndarray:
        """The picture's corners in board units (top-left, top-right, bottom-right, bottom-left)."""
        x0, y0, x1, y1 = self._slots[picture]
        return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=np.float64)

    def marker_square(self, marker_id: int) -> np.ndarray:
        """A board marker's corners in board units, in OpenCV order (0 top-left ... 3 bottom-left)."""
        for name, ids in PICTURES.items():
            if marker_id in ids:
                index = ids.index(marker_id)
                corner = self.picture_slot(name)[index]
                # The marker lies diagonally outside the picture corner it touches.
                dx, dy = ((-1, -1), (1, -1), (1, 1), (-1, 1))[index]
                x0 = corner[0] if dx > 0 else corner[0] - self.MARKER
                y0 = corner[1] if dy > 0 else corner[1] - self.MARKER
                return _square(x0, y0, self.MARKER)
        raise KeyError(f"Marker {marker_id} is not on the board: board markers are "
                       f"{sorted(i for ids in PICTURES.values() for i in ids)}")

    def picture_homography(self, picture: str) -> np.ndarray:
        """Picture pixels (OpenCV centres) -> board units."""
        image_h, image_w = self.pictures[picture].shape[:2]
        x0, y0, x1, y1 = self._slots[picture]
        sx, sy = (x1 - x0) / image_w, (y1 - y0) / image_h
        return np.array([[sx, 0, x0 + 0.5 * sx], [0, sy, y0 + 0.5 * sy], [0, 0, 1]])

    def texture(self, missing: Sequence[int] = ()) -> list[tuple[float, np.ndarray]]:
        """The printed board as images at several resolutions (pixels per unit, image), finest first."""
        key = frozenset(missing)
        if key not in self._textures:
            if len(self._textures) >= 4:  # each set of levels takes ~40 MB
                self._textures.pop(next(iter(self._textures)))
            scale = 4
            width, height = self.size
            image = np.empty((height * scale, width * scale, 4), np.uint8)
            image[:] = (*self.PAPER, 255)  # BGRA: the alpha channel gives the board anti-aliased edges
            for name, picture in self.pictures.items():
                x0, y0, x1, y1 = (v * scale for v in self._slots[name])
                image[y0:y1, x0:x1, :3] = cv2.resize(picture, (x1 - x0, y1 - y0), interpolation=cv2.INTER_AREA
                                                 if picture.shape[1] > x1 - x0 else cv2.INTER_CUBIC)
            for marker_id in sorted(i for ids in PICTURES.values() for i in ids):
                if marker_id not in key:
                    x0, y0 = (int(v) * scale for v in self.marker_square(marker_id)[0])
                    _paste_marker(image, marker_id, x0, y0, self.MARKER * scale)
            levels = [(float(scale), image)]
            while levels[-1][1].shape[1] > 64:
                levels.append((levels[-1][0] / 2, cv2.pyrDown(levels[-1][1])))
            self._textures[key] = levels
        return self._textures[key]


def _square(x0: float, y0: float, side: float) -> np.ndarray:
    return np.array([[x0, y0], [x0 + side, y0], [x0 + side, y0 + side], [x0, y0 + side]], dtype=np.float64)


def _paste_marker(image: np.ndarray, marker_id: int, x0: int, y0: int, side: int) -> None:
    marker = cv2.aruco.generateImageMarker(dictionary(), marker_id, side)
    image[y0:y0 + side, x0:x0 + side, :3] = marker[:, :, None]


def _as_bgr(image, name: str) -> np.ndarray:
    image = np.asarray(image)
    if image.dtype != np.uint8 or image.ndim not in (2, 3) or 0 in image.shape[:2]:
        raise ValueError(f"The {name} picture must be a uint8 image (height, width[, 3]), not "
                         f"{image.dtype} {image.shape}; load one with cv2.imread")
    if image.ndim == 2 or image.shape[2] == 1:
        return cv2.cvtColor(image.reshape(image.shape[:2]), cv2.COLOR_GRAY2BGR)
    if image.shape[2] == 4:
        return cv2.cvtColor(image, cv2.COLOR_BGRA2BGR)
    return image.copy()


_DEFAULT_BOARD: Board | None = None


def default_board() -> Board:
    """The board with the drawn cat and dog (made once, then shared)."""
    global _DEFAULT_BOARD
    if _DEFAULT_BOARD is None:
        _DEFAULT_BOARD = Board()
    return _DEFAULT_BOARD


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

    def _inside(self, corners: np.ndarray, margin: float) -> bool:
        width, height = self.size
        return bool(np.all(corners >= margin) and np.all(corners[:, 0] <= width - 1 - margin)
                    and np.all(corners[:, 1] <= height - 1 - margin))

    @property
    def visible_ids(self) -> tuple[int, ...]:
        """Board markers printed, not occluded and with all four corners inside the frame."""
        return tuple(i for i, c in sorted(self.marker_corners.items()) if self._inside(c, 0.0))

    @property
    def detectable_ids(self) -> tuple[int, ...]:
        """Visible board markers FRAME_MARGIN pixels from the border and big enough (see MIN_MARKER_SIDE)."""
        return tuple(i for i, c in sorted(self.marker_corners.items())
                     if self._inside(c, FRAME_MARGIN) and _shortest_side(c) >= MIN_MARKER_SIDE)

    @property
    def fully_framed(self) -> tuple[str, ...]:
        """Pictures whose four markers are all detectable: a correct detector must find these."""
        ids = set(self.detectable_ids)
        return tuple(name for name, markers in PICTURES.items() if ids.issuperset(markers))

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
    pose_rng, look_rng, table_rng, finger_rng, noise_rng = (
        np.random.default_rng(s) for s in np.random.SeedSequence(_seed_entropy(seed)).spawn(5))
    sampled_pose = sample_pose(pose_rng, difficulty, size, board)
    sampled_look = sample_look(look_rng, difficulty)
    occluded = set(_check_ids(occluded_markers, "occluded_markers", board_only=True))
    if difficulty == "hard" and finger_rng.random() < 0.25:
        occluded.add(int(finger_rng.choice([i for ids in PICTURES.values() for i in ids])))
    return _render(board, pose or sampled_pose, look or sampled_look, size,
                   missing=_check_ids(missing_markers, "missing_markers", board_only=True),
                   occluded=tuple(sorted(occluded)), duplicates=_check_ids(duplicate_markers, "duplicate_markers"),
                   table=lambda: _table(board, _seed_entropy(seed)), finger_rng=finger_rng, noise_rng=noise_rng,
                   seed=seed, difficulty=difficulty)


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
    for index, (marker_id, origin) in enumerate(zip(duplicates, _sticker_places(board, H, size, len(duplicates)))):
        sticker = _sticker(marker_id)
        image = _composite(image, [(4.0, sticker)], to_super @ _translation(*origin), super_size)
        corners = _square(origin[0] + Board.QUIET, origin[1] + Board.QUIET, Board.MARKER)
        duplicate_truth.append((marker_id, _project(_EDGE_TO_CENTRE @ H, corners).astype(np.float32)))

    finger_mask = np.zeros(image.shape[:2], np.uint8)
    for marker_id in occluded:
        _draw_finger(image, finger_mask, _project(to_super, board.marker_square(marker_id)),
                     _project(to_super, [np.array(board.size) / 2])[0], finger_rng)
    frame = cv2.resize(image, size, interpolation=cv2.INTER_AREA)
    finger_mask = cv2.resize(finger_mask, size, interpolation=cv2.INTER_AREA)
    frame = _apply_look(frame, look, noise_rng, noise_tile)

    marker_corners, covered = {}, set()
    for marker_id in sorted(i for ids in PICTURES.values() for i in ids):
        if marker_id in missing:
            continue
        corners = _project(_EDGE_TO_CENTRE @ H, board.marker_square(marker_id)).astype(np.float32)
        if marker_id in occluded or _covered(finger_mask, corners):
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


def _pick_level(levels, to_super):
    """The coarsest level that still has at least one texture pixel per screen pixel everywhere."""
    texture_h, texture_w = levels[0][1].shape[:2]
    w, h = texture_w / levels[0][0], texture_h / levels[0][0]
    probes = np.array([[0, 0], [w, 0], [w, h], [0, h], [w / 2, h / 2]], np.float64)
    base = _project(to_super, probes)
    dx = np.linalg.norm(_project(to_super, probes + [1, 0]) - base, axis=1)
    dy = np.linalg.norm(_project(to_super, probes + [0, 1]) - base, axis=1)
    needed = float(max(dx.max(), dy.max()))
    chosen = levels[0]
    for level in levels:
        if level[0] >= needed:
            chosen = level
    return chosen


def _composite(image: np.ndarray, levels, to_super, super_size) -> np.ndarray:
    """Paste a BGRA texture (a list of levels) through a homography onto image; returns the new image."""
    layer = _warp_levels(levels, to_super, super_size)
    alpha = layer[:, :, 3].astype(np.float32) * np.float32(1 / 255)
    return cv2.blendLinear(layer[:, :, :3], image, alpha, 1 - alpha)


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


_NOISE_PAD = 64


def _noise_tile(size) -> np.ndarray:
    width, height = size
    rng = np.random.default_rng(4321)
    return rng.standard_normal((height + _NOISE_PAD, width + _NOISE_PAD, 3), dtype=np.float32)


def _gamma_table(gamma: float) -> np.ndarray:
    return np.clip(255 * (np.arange(256) / 255) ** gamma + 0.5, 0, 255).astype(np.uint8)


def _apply_look(frame: np.ndarray, look: Look, rng: np.random.Generator, noise_tile=None) -> np.ndarray:
    height, width = frame.shape[:2]
    image = frame.astype(np.float32) * (1 / 255)
    if look.blur > 0:
        image = cv2.GaussianBlur(image, (0, 0), look.blur)
    light = np.float32(look.gain) * np.asarray(look.tint, np.float32)[None, None, :]
    if look.gradient:
        a = math.radians(look.gradient_angle)
        x = (np.arange(width, dtype=np.float32) + 0.5) / width - 0.5
        y = (np.arange(height, dtype=np.float32) + 0.5) / height - 0.5
        ramp = 1 + look.gradient * (math.cos(a) * x[None, :] + math.sin(a) * y[:, None])
        image *= ramp[:, :, None]
    image *= light
    if look.noise > 0:
        if noise_tile is None:
            noise = rng.standard_normal(image.shape, dtype=np.float32)
        else:  # video: a random window of a fixed noise field is 5x cheaper and looks the same
            dy, dx = rng.integers(0, _NOISE_PAD, 2)
            noise = noise_tile[dy:dy + height, dx:dx + width]
        image += noise * np.float32(look.noise / 255 * (1 if rng.random() < 0.5 else -1))
    out = cv2.convertScaleAbs(image, alpha=255)  # rounds and saturates to 0..255
    if look.gamma != 1:
        out = cv2.LUT(out, _gamma_table(look.gamma))
    if look.jpeg_quality is not None:
        ok, data = cv2.imencode(".jpg", out, [cv2.IMWRITE_JPEG_QUALITY, int(look.jpeg_quality)])
        out = cv2.imdecode(data, cv2.IMREAD_COLOR)
    return out


# --------------------------------------------------------------------------------------------
# The table
# --------------------------------------------------------------------------------------------

_TABLE_SCALE = 0.5      # texture pixels per board unit
_TABLE_CACHE: dict = {}


_GRAIN: dict = {}


def _wood_grain(size) -> np.ndarray:
    """Brightness pattern of a wooden table top around 1.0, the same for every table of that size."""
    if size not in _GRAIN:
        rng = np.random.default_rng(12345)
        width, height = size
        blotches = cv2.resize(rng.normal(0, 1, (6, 8)).astype(np.float32), size, interpolation=cv2.INTER_CUBIC)
        y = np.arange(height, dtype=np.float32)[:, None]
        grain = np.sin(y * np.float32(0.2) + 3 * blotches) * 0.5 + rng.normal(0, 0.15, (height, 1)).astype(np.float32)
        _GRAIN[size] = cv2.merge([1 + 0.08 * blotches + 0.06 * grain] * 3)
    return _GRAIN[size]


def _plain_table():
    texture = np.empty((64, 64, 3), np.uint8)
    texture[:] = (96, 118, 140)
    return [(_TABLE_SCALE, texture)]


def _table(board: Board, entropy: list[int]):
    """A table top with clutter around the board, in board units: (levels, origin)."""
    key = tuple(entropy)
    if key not in _TABLE_CACHE:
        if len(_TABLE_CACHE) > 16:
            _TABLE_CACHE.clear()
        rng = np.random.default_rng(np.random.SeedSequence(entropy + [7]))
        bw, bh = board.size
        origin = (-bw, -2.0 * bh)
        width, height = int(3 * bw * _TABLE_SCALE), int(5 * bh * _TABLE_SCALE)
        wood = rng.uniform([60, 90, 120], [110, 140, 180])
        texture = cv2.convertScaleAbs(cv2.multiply(_wood_grain((width, height)), (*wood, 0.0)))
        board_box = np.array([-origin[0], -origin[1], -origin[0] + bw, -origin[1] + bh]) * _TABLE_SCALE
        for _ in range(int(rng.integers(40, 60))):
            _clutter_item(texture, rng, board_box)
        levels = [(_TABLE_SCALE, texture)]
        while levels[-1][1].shape[1] > 64:
            levels.append((levels[-1][0] / 2, cv2.pyrDown(levels[-1][1])))
        _TABLE_CACHE[key] = (levels, origin)
    return _TABLE_CACHE[key]


def _clutter_item(texture, rng, board_box) -> None:
    """One object on the table: a sheet of paper, a pen, a mug, a coin or a keypad."""
    height, width = texture.shape[:2]
    kind = rng.choice(["paper", "pen", "mug", "coin", "keypad"], p=[0.3, 0.3, 0.15, 0.15, 0.1])
    # Keep most objects off the area under the board, where they would only be hidden.
    bx0, by0, bx1, by1 = board_box
    bw, bh = bx1 - bx0, by1 - by0
    near = np.array([bx0 - bw * 0.5, by0 - bh * 1.5, bx1 + bw * 0.5, by1 + bh * 1.5])
    for _ in range(20):
        centre = rng.uniform(near[:2], near[2:])
        if not (board_box[0] < centre[0] < board_box[2] and board_box[1] < centre[1] < board_box[3]):
            break
    colour = tuple(float(v) for v in rng.uniform(20, 235, 3))
    cx, cy = (int(v) for v in centre)
    if kind == "paper":
        box = cv2.boxPoints(((cx, cy), tuple(rng.uniform(60, 160, 2)), rng.uniform(0, 180))).astype(np.int32)
        cv2.fillConvexPoly(texture, box, tuple(float(v) for v in rng.uniform(200, 250, 3)), cv2.LINE_AA)
        for row in range(6):                          # a few lines of "text"
            t = (row + 1) / 7
            a, b = box[0] + (box[3] - box[0]) * t, box[1] + (box[2] - box[1]) * t
            a, b = a + (b - a) * 0.1, a + (b - a) * rng.uniform(0.5, 0.9)
            cv2.line(texture, tuple(a.astype(int)), tuple(b.astype(int)), (90, 90, 90), 1, cv2.LINE_AA)
    elif kind == "pen":
        angle = rng.uniform(0, math.pi)
        length = rng.uniform(50, 90)
        d = np.array([math.cos(angle), math.sin(angle)]) * length / 2
        cv2.line(texture, (int(cx - d[0]), int(cy - d[1])), (int(cx + d[0]), int(cy + d[1])), colour,
                 int(rng.integers(3, 6)), cv2.LINE_AA)
        cv2.circle(texture, (int(cx + d[0]), int(cy + d[1])), 3, (30, 30, 30), -1, cv2.LINE_AA)
    elif kind == "mug":
        radius = int(rng.uniform(18, 32))
        cv2.circle(texture, (cx, cy), radius, colour, -1, cv2.LINE_AA)
        cv2.circle(texture, (cx, cy), int(radius * 0.78), tuple(c * 0.5 for c in colour), -1, cv2.LINE_AA)
        cv2.circle(texture, (cx, cy), int(radius * 0.7), (30, 50, 70), -1, cv2.LINE_AA)
    elif kind == "coin":
        radius = int(rng.uniform(5, 9))
        cv2.circle(texture, (cx, cy), radius, (80, 160, 190), -1, cv2.LINE_AA)
        cv2.circle(texture, (cx, cy), radius, (50, 110, 140), 1, cv2.LINE_AA)
    else:
        cols, rows, key = int(rng.integers(4, 8)), int(rng.integers(3, 5)), int(rng.integers(7, 11))
        x0, y0 = cx - cols * key // 2, cy - rows * key // 2
        cv2.rectangle(texture, (x0 - 3, y0 - 3), (x0 + cols * key + 3, y0 + rows * key + 3), (35, 35, 35), -1)
        for r in range(rows):
            for c in range(cols):
                cv2.rectangle(texture, (x0 + c * key + 1, y0 + r * key + 1),
                              (x0 + (c + 1) * key - 2, y0 + (r + 1) * key - 2), (200, 200, 200), -1)


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
