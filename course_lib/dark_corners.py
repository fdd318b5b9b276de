"""Photograph-like pictures with nearly black corners, and boards that hold them.

Markers touching such corners are the hard case for the stock ArUco detector.
"""

from __future__ import annotations

import cv2
import numpy as np

from course_lib.boards import Board
from course_lib.marker_board import _check_size
from course_lib.scenes import _seed_entropy


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
