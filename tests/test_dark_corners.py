"""Markers touching dark picture corners: the reference crops recover the pictures (issue: dark corners).

dark_corners.dark_corner_board puts photograph-like pictures with nearly black corners on the board, so
every marker touches a dark corner and can merge with it in the detector's threshold image.
Both reference implementations (readmarker's crop_pictures and the catdog_warp assignment's
solution cell in assignments/build.py) must recover at least 98 % of the fully framed pictures
of a fixed seeded set of hard scenes, with no false picture; the detector's markers alone do
not (the set really shows the failure). benchmarks/bench_dark_corners.py measures a larger set.
"""

import sys
import types
from pathlib import Path

import pytest

from course_lib import dark_corners, marker_board, scenes

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "assignments" / "reference_ws" / "src" / "readmarker"))
sys.path.insert(0, str(ROOT / "assignments"))

from readmarker.crop import crop_pictures  # noqa: E402

#: Hard scenes of dark_corner_board(seed) with at least one fully framed picture (24 pictures).
SEEDS = (4, 6, 9, 11, 12, 13, 14, 15, 18, 23, 24, 27, 29, 32, 35, 42, 44, 47, 48, 51, 52, 53)


def assignment_solution():
    """crop_pictures of the catdog_warp solution cell, as a module."""
    import build

    source = build.MARKER_MODULE.strip().split("\n", 1)[1]  # without the %%writefile line
    module = types.ModuleType("marker_reader_solution")
    exec(compile(source, "marker_reader_solution", "exec"), module.__dict__)
    return module.crop_pictures


@pytest.fixture(scope="module")
def dark_scenes():
    return [scenes.render_scene(seed, difficulty="hard", board=dark_corners.dark_corner_board(seed)) for seed in SEEDS]


def recovery(crop, scene_list):
    """(fully framed pictures, recovered, false pictures) of a crop function on the scenes."""
    framed = recovered = false = 0
    for scene in scene_list:
        crops = crop(scene.frame)
        expected = scene.expected_crops()
        visible = set(scene.visible_ids)
        for name, markers in marker_board.PICTURES.items():
            good = name in crops and marker_board.crop_similarity(crops[name], expected[name]) >= marker_board.SAME_CROP_THRESHOLD
            framed += name in scene.fully_framed
            recovered += name in scene.fully_framed and good
            false += name in crops and (not good or not visible.issuperset(markers))
    return framed, recovered, false


def test_photographs_have_dark_corners_and_are_the_same_for_the_same_seed():
    photo = dark_corners.draw_photo(3)
    assert photo.shape == (300, 400, 3) and photo.dtype.name == "uint8"
    assert (photo == dark_corners.draw_photo(3)).all() and not (photo == dark_corners.draw_photo(4)).all()
    assert photo[:4, :4].max() < 40 and photo[-4:, -4:].max() < 40, "corners nearly black"
    assert photo[120:180, 160:240].mean() > 60, "a picture, not a black frame"


def test_the_detectors_markers_alone_miss_many_pictures(dark_scenes):
    framed, recovered, false = recovery(lambda frame: crop_pictures(frame, second_look=False), dark_scenes)
    assert framed == 24 and recovered <= 0.8 * framed, (framed, recovered)


@pytest.mark.parametrize("implementation", ["readmarker", "assignment solution"])
def test_the_reference_crops_recover_98_percent_and_no_false_picture(dark_scenes, implementation):
    crop = crop_pictures if implementation == "readmarker" else assignment_solution()
    framed, recovered, false = recovery(crop, dark_scenes)
    assert recovered >= 0.98 * framed and false == 0, (framed, recovered, false)
