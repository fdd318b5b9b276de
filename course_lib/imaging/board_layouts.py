"""Boards of other layouts than the course's, on other tables: held-out boards for the photo bench.

The marker convention stays :mod:`course_lib.imaging.marker_board`'s (which ids frame which
picture, and that each marker touches its picture corner with one of its own corners); what
changes is the geometry: picture sizes and aspect ratios (the cat and the dog may differ), the
marker size, the paper around the markers, the gap between the pictures and whether the dog is
beside the cat or below it. :func:`layout_scene` photographs such a board as
:func:`course_lib.imaging.scenes.render_scene` does (pose, light, blur, noise, JPEG, a finger),
on a table of a chosen kind, deterministic by seed.
"""

from __future__ import annotations

import dataclasses
import threading

import cv2
import numpy as np

from course_lib.imaging import scenes
from course_lib.imaging.boards import Board, TextureLevels
from course_lib.imaging.camera_views import sample_look, sample_pose
from course_lib.imaging.marker_board import PICTURES
from course_lib.imaging.photos import _detail, draw_photo
from course_lib.imaging.table import _table


@dataclasses.dataclass(frozen=True)
class BoardLayout:
    """A board's geometry in board units: picture slots (width, height), marker side, paper
    around the markers (quiet), paper between the two pictures' markers (gap), and whether the
    dog is below the cat (stacked) instead of beside it."""

    cat: tuple[int, int] = Board.PICTURE_SIZE
    dog: tuple[int, int] = Board.PICTURE_SIZE
    marker: int = Board.MARKER
    quiet: int = Board.QUIET
    gap: int = Board.GAP
    stacked: bool = False


#: The course's board, and held-out layouts: other aspect ratios, sizes, markers and margins.
LAYOUTS: dict[str, BoardLayout] = {
    "course": BoardLayout(),
    "wide 16:9": BoardLayout(cat=(384, 216), dog=(384, 216), marker=80, quiet=20, gap=40),
    "portrait 3:4": BoardLayout(cat=(240, 320), dog=(240, 320), marker=88),
    "square, small markers": BoardLayout(cat=(300, 300), dog=(300, 300), marker=64, quiet=16, gap=24),
    "big cat, small dog": BoardLayout(cat=(400, 300), dog=(240, 180), marker=80, quiet=24, gap=32),
    "stacked, big markers": BoardLayout(cat=(320, 200), dog=(320, 200), marker=120, quiet=24, gap=30, stacked=True),
}

#: The tables a board lies on: the course's wood with clutter, and two textured cloths.
TABLES = ("wood", "dark weave", "busy print")


class LayoutBoard(Board):
    """A Board of another layout (see BoardLayout); cat and dog as for Board."""

    def __init__(self, layout: BoardLayout, cat: np.ndarray | None = None, dog: np.ndarray | None = None):
        super().__init__(cat=cat, dog=dog)
        m, q = layout.marker, layout.quiet
        self.MARKER, self.QUIET, self.PICTURE_SIZE = m, q, layout.cat
        (cw, ch), (dw, dh) = layout.cat, layout.dog
        self._slots = {"cat": (q + m, q + m, q + m + cw, q + m + ch)}
        if layout.stacked:
            top = q + m + ch + m + layout.gap + m
            self._slots["dog"] = (q + m, top, q + m + dw, top + dh)
            self.size = (q + m + max(cw, dw) + m + q, top + dh + m + q)
        else:
            left = q + m + cw + m + layout.gap + m
            self._slots["dog"] = (left, q + m, left + dw, q + m + dh)
            self.size = (left + dw + m + q, q + m + max(ch, dh) + m + q)
        self._textures = {}
        self._textures_lock = threading.Lock()


def layout_board(seed: int, layout: BoardLayout) -> LayoutBoard:
    """A board of `layout` with two draw_photo pictures of its slots' shapes (corners of every kind)."""
    pictures = {}
    for index, name in enumerate(PICTURES):
        width, height = layout.cat if name == "cat" else layout.dog
        pictures[name] = draw_photo(2 * seed + index, size=(width * 5 // 4, height * 5 // 4), corners="any")
    return LayoutBoard(layout, **pictures)


def layout_scene(seed: int, layout: BoardLayout, table: str = "wood", difficulty: str = "hard") -> scenes.Scene:
    """render_scene(seed, difficulty=difficulty) of layout_board(seed, layout) on a table of kind `table`."""
    if table not in TABLES:
        raise ValueError(f"table must be one of {TABLES}, not {table!r}")
    board = layout_board(seed, layout)
    size = (640, 480)
    pose_rng, look_rng, table_rng, finger_rng, noise_rng = scenes._generators(seed)
    pose, look = sample_pose(pose_rng, difficulty, size, board), sample_look(look_rng, difficulty)
    occluded = ()
    if difficulty == "hard" and finger_rng.random() < 0.25:
        occluded = (int(finger_rng.choice([i for ids in PICTURES.values() for i in ids])),)
    if table == "wood":
        def make_table():
            return _table(board, [seed, *board.size])
    else:
        def make_table():
            return _cloth(board, seed, table)
        look = dataclasses.replace(look, clutter=True)
    return scenes._render(board, pose, look, size, missing=(), occluded=occluded, duplicates=(), table=make_table,
                          finger_rng=finger_rng, noise_rng=noise_rng, seed=seed, difficulty=difficulty)


def framed_seeds(seeds, layout: BoardLayout, difficulty: str = "hard") -> list[int]:
    """The seeds whose camera pose can frame a whole picture of layout_board(seed, layout)."""
    kept = []
    board = LayoutBoard(layout, cat=np.zeros((3, 4, 3), np.uint8), dog=np.zeros((3, 4, 3), np.uint8))  # geometry only
    for seed in seeds:
        if scenes.framed_from(scenes.scene_pose(seed, difficulty=difficulty, board=board), board=board):
            kept.append(seed)
    return kept


def _cloth(board: Board, seed: int, kind: str):
    """A table cloth around the board, in board units: (levels, origin) as table._table gives."""
    rng = np.random.default_rng(np.random.SeedSequence([seed, 8]))
    bw, bh = board.size
    origin = (-bw, -2.0 * bh)
    width, height = int(1.5 * bw), int(2.5 * bh)  # half a pixel per board unit, as the wood
    if kind == "dark weave":  # a dark fabric: fine threads in two directions and soft folds
        y, x = np.mgrid[0:height, 0:width].astype(np.float32)
        period = rng.uniform(2.5, 4.0)
        weave = np.sin(x * 2 * np.pi / period) * np.sin(y * 2 * np.pi / period)
        folds = _detail(rng, width, height, ((3, 1.0), (6, 0.5)))[:, :, 0]
        shade = 1 + 0.25 * weave + 0.15 * folds
        colour = rng.uniform(15, 60, 3).astype(np.float32)
        texture = colour * shade[:, :, None]
    else:  # "busy print": high-contrast blotches and stripes of many colours
        texture = rng.uniform(40, 200, 3).astype(np.float32) + 90 * _detail(rng, width, height, ((12, 1.0), (40, 0.6)))
        for _ in range(int(rng.integers(10, 20))):
            start = tuple(int(v) for v in rng.uniform(0, (width, height)))
            end = tuple(int(v) for v in rng.uniform(0, (width, height)))
            cv2.line(texture, start, end, tuple(float(v) for v in rng.uniform(0, 255, 3)), int(rng.integers(2, 6)))
    levels = [(0.5, np.clip(texture, 0, 255).astype(np.uint8))]
    while levels[-1][1].shape[1] > 64:
        levels.append((levels[-1][0] / 2, cv2.pyrDown(levels[-1][1])))
    return TextureLevels.of(levels), origin
