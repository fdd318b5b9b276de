"""The table top under the board: wood grain and clutter (paper, pens, mugs, coins, keypads), seeded."""

from __future__ import annotations

import math
import threading

import cv2
import numpy as np

from course_lib.imaging import drawn_cache
from course_lib.imaging.boards import Board, TextureLevels

# --------------------------------------------------------------------------------------------
# The table
# --------------------------------------------------------------------------------------------

_TABLE_SCALE = 0.5      # texture pixels per board unit
_TABLE_CACHE: dict = {}


_GRAIN: dict = {}
_GRAIN_LOCK = threading.Lock()  # the checks of a submission render in threads: one grain is drawn once


def _wood_grain(size) -> np.ndarray:
    """Brightness pattern of a wooden table top around 1.0 (one channel, float32), the same for
    every table of that size: mapped from the copy kept on disk (drawn_cache), else drawn."""
    with _GRAIN_LOCK:
        if size not in _GRAIN:
            width, height = size
            _GRAIN[size] = drawn_cache.kept(f"wood_grain-{width}x{height}", drawn_cache.key("table.py"),
                                            lambda: _draw_wood_grain(size), np.float32)
        return _GRAIN[size]


def _draw_wood_grain(size) -> np.ndarray:
    rng = np.random.default_rng(12345)
    width, height = size
    blotches = cv2.resize(rng.normal(0, 1, (6, 8)).astype(np.float32), size, interpolation=cv2.INTER_CUBIC)
    y = np.arange(height, dtype=np.float32)[:, None]
    grain = (np.sin(y * np.float32(0.2) + 3 * blotches) * 0.5 + rng.normal(0, 0.15, (height, 1)).astype(np.float32))
    return np.ascontiguousarray(1 + 0.08 * blotches + 0.06 * grain, dtype=np.float32)


def _plain_table():
    texture = np.empty((64, 64, 3), np.uint8)
    texture[:] = (96, 118, 140)
    return TextureLevels.of([(_TABLE_SCALE, texture)])


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
        grain = _wood_grain((width, height))  # each channel: the grain times that channel's wood colour
        texture = cv2.merge([cv2.convertScaleAbs(grain, alpha=float(level)) for level in wood])
        board_box = np.array([-origin[0], -origin[1], -origin[0] + bw, -origin[1] + bh]) * _TABLE_SCALE
        for _ in range(int(rng.integers(40, 60))):
            _clutter_item(texture, rng, board_box)
        _TABLE_CACHE[key] = (TextureLevels.pyramid(_TABLE_SCALE, texture), origin)
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
