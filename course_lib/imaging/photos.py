"""Photograph-like pictures for the board, and boards that hold them, deterministic by seed.

A marker touches its picture at one corner, so what a picture's corners look like decides
whether the ArUco detector sees the marker as a square of its own. Printed photographs have
every kind of corner: nearly black (a vignette, a night sky), mid-dark (brown wood, a navy
coat), grey, a gradient, a texture (leaves, fur, fabric), light. :func:`draw_photo` makes such
pictures offline from seeded noise; :func:`photo_board` puts two of them on the board.
"""

from __future__ import annotations

from collections.abc import Sequence

import cv2
import numpy as np

from course_lib.imaging.boards import Board
from course_lib.imaging.marker_board import _check_size
from course_lib.imaging.scenes import _seed_entropy

#: The kinds of picture corner draw_photo makes (corners="any" draws one per corner by seed).
CORNER_KINDS = ("near_black", "brown", "navy", "mid_dark", "grey", "gradient", "texture", "light")

#: BGR ranges (low, high) of the plain corner kinds: each channel drawn uniformly in its range.
_CORNER_COLOURS = {
    "near_black": ((0, 0, 0), (25, 25, 25)),
    "brown": ((15, 40, 70), (60, 95, 150)),       # wood, leather, fur, coffee
    "navy": ((70, 10, 0), (150, 60, 45)),          # navy cloth, a dusk sky
    "mid_dark": ((20, 20, 20), (110, 110, 110)),   # any hue: dark green, maroon, purple, olive
    "light": ((150, 150, 150), (250, 250, 250)),
}


def draw_photo(seed: int = 0, size: tuple[int, int] = (400, 300), corners: str | Sequence[str] = "dark") -> np.ndarray:
    """A photograph-like picture, deterministic by seed, with corners of a chosen kind.

    Made offline from seeded noise: a sky-to-ground gradient with a seeded horizon, soft detail
    at several scales (like leaves, clouds or texture) and a few blurred bright spots (like
    lights out of focus). Then the corners:

    - "dark": lens vignetting darkens all four corners almost to black;
    - "any": each corner is one of CORNER_KINDS, drawn by seed, over a seeded part of the picture;
    - four names of CORNER_KINDS: those kinds, top-left, top-right, bottom-right, bottom-left.

    Args:
        seed: chooses colours, horizon, detail, spots and the corners.
        size: (width, height) of the picture.
        corners: "dark", "any" or a sequence of four CORNER_KINDS.

    Returns:
        BGR uint8 image of that size.

    Raises:
        ValueError: a bad size or an unknown corner kind.
    """
    width, height = _check_size(size, "picture size")
    kinds = _corner_kinds(corners)
    rng = np.random.default_rng(np.random.SeedSequence([_seed_entropy(seed)[0], 555]))
    y = (np.arange(height, dtype=np.float32) + 0.5) / height
    x = (np.arange(width, dtype=np.float32) + 0.5) / width
    horizon = rng.uniform(0.3, 0.7) + rng.uniform(-0.15, 0.15) * (x - 0.5)
    ground = (y[:, None] > horizon[None, :]).astype(np.float32)
    ground = cv2.GaussianBlur(ground, (0, 0), max(1.0, 0.01 * width))[:, :, None]
    sky, earth = rng.uniform(70, 230, 3), rng.uniform(30, 170, 3)
    image = (1 - ground) * sky.astype(np.float32) + ground * earth.astype(np.float32)
    detail = _detail(rng, width, height, ((4, 1.0), (8, 0.5), (16, 0.25), (32, 0.12)))
    image += rng.uniform(20, 45) * detail
    for _ in range(int(rng.integers(2, 6))):                     # out-of-focus lights
        centre = (float(rng.uniform(0.15, 0.85) * width), float(rng.uniform(0.15, 0.85) * height))
        spot = np.zeros((height, width), np.float32)
        cv2.circle(spot, (int(centre[0]), int(centre[1])), int(rng.uniform(0.03, 0.08) * width), 1.0, -1)
        spot = cv2.GaussianBlur(spot, (0, 0), 0.02 * width)
        image += spot[:, :, None] * rng.uniform(60, 140, 3).astype(np.float32)
    if kinds is None:
        radius2 = ((x[None, :] - 0.5) ** 2 + (y[:, None] - 0.5) ** 2) * 2   # 1 at the corners
        vignette = np.clip(1 - rng.uniform(0.9, 1.0) * radius2 ** rng.uniform(1.0, 2.0), 0.02, 1)
        return np.clip(image * vignette[:, :, None], 0, 255).astype(np.uint8)
    corner_rng = np.random.default_rng(np.random.SeedSequence([_seed_entropy(seed)[0], 556]))
    if kinds == "any":
        kinds = [CORNER_KINDS[int(i)] for i in corner_rng.integers(0, len(CORNER_KINDS), 4)]
    for (cx, cy), kind in zip(((0, 0), (width, 0), (width, height), (0, height)), kinds, strict=True):
        # The corner's kind covers a seeded quarter-disc of the picture and fades out beyond it.
        reach = corner_rng.uniform(0.2, 0.5) * width
        distance = np.hypot(x[None, :] * width - cx, y[:, None] * height - cy) / reach
        weight = np.clip(1.5 - distance, 0, 1)[:, :, None]
        image = image * (1 - weight) + _corner_paint(corner_rng, kind, width, height, (cx, cy), reach) * weight
    return np.clip(image, 0, 255).astype(np.uint8)


def photo_board(seed: int = 0, corners: str | Sequence[str] = "any") -> Board:
    """A board whose cat and dog slots hold two draw_photo pictures (seeds 2*seed and 2*seed+1).

    With corners="dark" every board marker touches a nearly black picture corner; with "any"
    (the default) the eight picture corners are of every kind of CORNER_KINDS:
    render_scene(seed, board=photo_board(seed)).
    """
    first = 2 * _seed_entropy(seed)[0]
    return Board(cat=draw_photo(first, corners=corners), dog=draw_photo(first + 1, corners=corners))


def _corner_kinds(corners):
    if isinstance(corners, str):
        if corners not in ("dark", "any"):
            raise ValueError(f"corners must be 'dark', 'any' or four of {CORNER_KINDS}, not {corners!r}")
        return None if corners == "dark" else "any"
    kinds = list(corners)
    if len(kinds) != 4 or any(kind not in CORNER_KINDS for kind in kinds):
        raise ValueError(f"corners must be 'dark', 'any' or four of {CORNER_KINDS}, not {corners!r}")
    return kinds


def _detail(rng: np.random.Generator, width: int, height: int, scales) -> np.ndarray:
    """Smooth seeded noise, (height, width, 3) float32: a sum of random grids of (cells across,
    weight) each, resized to the picture by cubic interpolation."""
    detail = np.zeros((height, width, 3), np.float32)
    for cells, weight in scales:
        grid = rng.normal(0, 1, (max(2, cells * height // width) + 2, cells + 2, 3)).astype(np.float32)
        detail += weight * cv2.resize(grid, (width, height), interpolation=cv2.INTER_CUBIC)
    return detail


def _corner_paint(rng: np.random.Generator, kind: str, width: int, height: int, corner, reach: float) -> np.ndarray:
    """What one corner of kind `kind` looks like over the whole picture (float32 BGR, broadcastable)."""
    if kind in _CORNER_COLOURS:
        low, high = _CORNER_COLOURS[kind]
        colour = rng.uniform(low, high).astype(np.float32)
        if kind == "mid_dark":  # one hue, not three independent channels
            colour = np.sort(colour)[rng.permutation(3)]
        grain = _detail(rng, width, height, ((16, 1.0), (64, 0.5)))  # print and film grain
        return colour + rng.uniform(2, 8) * grain
    if kind == "grey":
        return np.float32(rng.uniform(50, 190)) + np.zeros(3, np.float32)
    if kind == "gradient":  # from one colour to another across the corner, at any angle
        angle = rng.uniform(0, 2 * np.pi)
        xs, ys = np.meshgrid(np.arange(width, dtype=np.float32) - corner[0],
                             np.arange(height, dtype=np.float32) - corner[1])
        t = np.clip(0.5 + (xs * np.cos(angle) + ys * np.sin(angle)) / (2 * reach), 0, 1)[:, :, None]
        start, end = rng.uniform(0, 200, 3).astype(np.float32), rng.uniform(0, 255, 3).astype(np.float32)
        return start + t * (end - start)
    # "texture": leaves, fur, fabric: detail from a few pixels up, around a dark to middle colour.
    cells = int(rng.integers(10, max(11, width // 3)))
    texture = _detail(rng, width, height, ((cells, 1.0), (2 * cells, 0.5)))
    texture = 0.75 * texture[:, :, :1] + 0.25 * texture  # mostly light and shade, a little colour
    return rng.uniform(20, 140, 3).astype(np.float32) + rng.uniform(25, 80) * texture
