"""Scoring a crop function on scenes of photo boards: pictures recovered and false pictures.

Shared by tests/course_lib/imaging/test_photos.py (small seeded sets, asserting the bounds) and
benchmarks/bench_photos.py (large seeded sets, printing the rates). The reference crop is
readmarker's crop_pictures, which is also the catdog_warp assignment's solution.
"""

from __future__ import annotations

import dataclasses
import time

from course_lib.imaging import marker_board, photos, scenes

from .from_source import REFERENCE_SOURCE, reference_module

READMARKER = REFERENCE_SOURCE / "readmarker"


def reference_crop():
    """readmarker.crop (the module), imported from its source as colcon would install it."""
    return reference_module("readmarker.crop")


def photo_scenes(seeds, corners="any", difficulty="hard"):
    """render_scene(seed, board=photo_board(seed, corners)) for the seeds whose camera pose can
    frame a whole picture (for hard scenes; other poses are not drawn, they would test nothing)."""
    for seed in seeds:
        if difficulty == "hard" and not scenes.framed_from(scenes.scene_pose(seed, difficulty=difficulty)):
            continue
        board = None if corners is None else photos.photo_board(seed, corners)
        yield scenes.render_scene(seed, difficulty=difficulty, board=board)


def layout_scenes(seeds, layout, difficulty="hard"):
    """board_layouts.layout_scene(seed, layout, table) for the seeds whose pose can frame a whole
    picture, the table taking turns by seed (wood, dark weave, busy print)."""
    from course_lib.imaging import board_layouts

    for seed in board_layouts.framed_seeds(seeds, layout, difficulty):
        yield board_layouts.layout_scene(seed, layout, board_layouts.TABLES[seed % len(board_layouts.TABLES)],
                                         difficulty)


@dataclasses.dataclass
class Recovery:
    """What a crop function made of some scenes.

    framed: fully framed pictures (scene.fully_framed), which a right crop function must return;
    recovered: of those, the ones returned and crop_similarity >= SAME_CROP_THRESHOLD to the
    expected crop; false: pictures returned although one of their markers is not in view, or
    whose crop is not the picture (a warp where the picture is not, or the other picture);
    missed: (seed, picture) of the framed pictures not recovered; seconds: processor time of
    the crop function.
    """

    framed: int = 0
    recovered: int = 0
    false: int = 0
    missed: list = dataclasses.field(default_factory=list)
    seconds: float = 0.0
    scenes: int = 0

    @property
    def rate(self) -> float:
        return self.recovered / self.framed if self.framed else 1.0


def recovery(crop_pictures, scene_list) -> Recovery:
    """Score crop_pictures(frame) -> {name: crop} on the scenes."""
    result = Recovery()
    for scene in scene_list:
        started = time.process_time()
        crops = crop_pictures(scene.frame)
        result.seconds += time.process_time() - started
        result.scenes += 1
        expected = scene.expected_crops()
        visible = set(scene.visible_ids)
        for name, markers in marker_board.PICTURES.items():
            good = (name in crops and marker_board.crop_similarity(crops[name], expected[name])
                    >= marker_board.SAME_CROP_THRESHOLD)
            if name in scene.fully_framed:
                result.framed += 1
                result.recovered += good
                if not good:
                    result.missed.append((scene.seed, name))
            result.false += name in crops and (not good or not visible.issuperset(markers))
    return result
