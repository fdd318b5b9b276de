"""Photographs on the board: the reference crops recover the pictures whatever their corners (issue #31).

photos.photo_board puts photograph-like pictures on the board: with corners="dark" every marker
touches a nearly black picture corner, with "any" the picture corners are of every kind (near
black, brown, navy, mid-dark, grey, gradients, textures, light). A marker can merge with a dark
corner in the detector's threshold image and be missed. The reference crop (readmarker's
crop_pictures, also the catdog_warp assignment's solution: assignments/build.py writes it into
the notebook) must recover at least 99 % of the fully framed pictures of fixed seeded sets of
hard scenes, with no false picture; the detector's markers alone do not (the sets really show
the failure). benchmarks/bench_photos.py measures larger sets.

Issue 51 item 11: boards of other layouts (board_layouts: other picture sizes and aspect
ratios, marker sizes, margins, the dog below the cat) on textured tables. A missing marker is
predicted from its picture's own markers, not from the course board's layout, which put it
elsewhere and lost the picture.
"""

import cv2
import numpy as np
import pytest
from support.photo import photo_scenes, recovery, reference_crop

from course_lib.imaging import board_layouts, boards, marker_board, photos

crop = reference_crop()

#: Hard scenes of photo_board(seed, "dark") with at least one fully framed picture (24 pictures).
DARK_SEEDS = (4, 6, 9, 11, 12, 13, 14, 15, 18, 23, 24, 27, 29, 32, 35, 42, 44, 47, 48, 51, 52, 53)

#: Hard scenes of photo_board(seed), corners of every kind: the seeds below 100 whose pose can
#: frame a picture (37 scenes, 35 fully framed pictures). The reference before issue #31 (thinned
#: looks, then the pictures painted out) missed the cat of seed 72.
ANY_SEEDS = range(100)

BOARD_IDS = tuple(i for ids in marker_board.PICTURES.values() for i in ids)


@pytest.fixture(scope="module")
def dark_scenes():
    return list(photo_scenes(DARK_SEEDS, "dark"))


@pytest.fixture(scope="module")
def any_scenes():
    return list(photo_scenes(ANY_SEEDS, "any"))


def test_photographs_have_dark_corners_and_are_the_same_for_the_same_seed():
    photo = photos.draw_photo(3)
    assert photo.shape == (300, 400, 3) and photo.dtype.name == "uint8"
    assert (photo == photos.draw_photo(3)).all() and not (photo == photos.draw_photo(4)).all()
    assert photo[:4, :4].max() < 40 and photo[-4:, -4:].max() < 40, "corners nearly black"
    assert photo[120:180, 160:240].mean() > 60, "a picture, not a black frame"


def test_corners_are_of_the_kinds_asked_for_and_the_same_for_the_same_seed():
    photo = photos.draw_photo(1, corners=("near_black", "light", "brown", "navy"))
    tl, tr, br, bl = (photo[y:y + 4, x:x + 4].reshape(-1, 3).mean(axis=0)
                      for y, x in ((0, 0), (0, 396), (296, 396), (296, 0)))
    assert tl.max() < 40 and tr.min() > 130, (tl, tr)
    assert br[2] > br[1] > br[0] and 40 < br.mean() < 130, f"brown (BGR) {br}"
    assert bl[0] > bl[2] and bl[0] > bl[1] and bl.mean() < 100, f"navy (BGR) {bl}"
    assert photo[120:180, 160:240].std() > 5, "a picture between its corners"
    anything = photos.draw_photo(6, corners="any")
    assert (anything == photos.draw_photo(6, corners="any")).all() and not (anything == photos.draw_photo(6)).all()
    with pytest.raises(ValueError, match="four of"):
        photos.draw_photo(1, corners=("brown", "navy", "teal", "light"))


def test_the_detectors_markers_alone_miss_many_pictures(dark_scenes):
    result = recovery(lambda frame: crop.crop_pictures(frame, second_look=False), dark_scenes)
    assert result.framed == 24 and result.recovered <= 0.8 * result.framed, result


@pytest.mark.parametrize("corners", ["dark", "any"])
def test_the_reference_crop_recovers_99_percent_and_no_false_picture(corners, request):
    scene_list = request.getfixturevalue(f"{corners}_scenes")
    result = recovery(crop.crop_pictures, scene_list)
    assert result.framed >= 24, "the set exercises the claim"
    assert result.rate >= 0.99 and result.false == 0, result


def test_markers_the_detector_missed_are_found_where_the_board_predicts_them(any_scenes):
    """look_where_predicted finds them at their true corners and finds nothing that is not in view."""
    looked_for = found = 0
    errors = []
    for scene in any_scenes:
        grey = cv2.cvtColor(scene.frame, cv2.COLOR_BGR2GRAY)
        stock = crop.find_markers(scene.frame)
        new = crop.look_where_predicted(grey, stock)
        missed = [i for i in scene.detectable_ids if i not in stock]
        looked_for += len(missed)
        found += sum(i in new for i in missed)
        assert set(new) <= set(scene.visible_ids) - set(stock), (scene.seed, sorted(new))
        errors += [float(np.abs(new[i] - scene.marker_corners[i]).max()) for i in new]
    assert looked_for >= 10, "the set exercises the claim"
    assert found >= 0.9 * looked_for, (found, looked_for)
    assert np.mean(errors) < 1.0 and max(errors) < 3.0, errors


#: Hard scenes of held-out layouts, (layout, seed), in each of which the course layout's
#: prediction (the reference before issue 51 item 11) lost a fully framed picture: a marker
#: merged with a dark picture corner, and the second look searched for it in the wrong place.
HELD_OUT = (("wide 16:9", 4), ("wide 16:9", 15), ("portrait 3:4", 6), ("portrait 3:4", 9), ("portrait 3:4", 15),
            ("square, small markers", 15), ("stacked, big markers", 0), ("stacked, big markers", 25))


def test_pictures_of_other_layouts_are_recovered_from_their_own_markers():
    """Each fully framed picture of HELD_OUT is cropped to the picture (crop_similarity to the
    expected crop), and nothing else is cropped; the detector's markers alone lose some."""
    scene_list = [board_layouts.layout_scene(seed, board_layouts.LAYOUTS[name],
                                             board_layouts.TABLES[seed % len(board_layouts.TABLES)])
                  for name, seed in HELD_OUT]
    alone = recovery(lambda frame: crop.crop_pictures(frame, second_look=False), scene_list)
    assert alone.recovered < alone.framed, "the set exercises the claim"
    result = recovery(crop.crop_pictures, scene_list)
    assert result.framed == 8 and result.recovered == result.framed and result.false == 0, result


def test_a_picture_whose_own_markers_leave_its_shape_open_is_recovered_by_the_thinned_look():
    """Seed 47 of the big cat and small dog: one cat marker is found, three merged with dark
    corners; one marker cannot fix the cat's shape, the course layout does not fit, so the
    thinned whole-frame look finds the others (find_board_markers' step 2)."""
    scene = board_layouts.layout_scene(47, board_layouts.LAYOUTS["big cat, small dog"], board_layouts.TABLES[47 % 3])
    stock = crop.find_markers(scene.frame)
    assert sum(i in stock for i in marker_board.PICTURES["cat"]) == 1 and "cat" in scene.fully_framed
    crops = crop.crop_pictures(scene.frame)
    assert marker_board.crop_similarity(crops["cat"], scene.expected_crops()["cat"]) >= marker_board.SAME_CROP_THRESHOLD


def _seen_markers(board, seed):
    """The board markers' corners under a seeded perspective (board units -> pixels), no image drawn."""
    rng = np.random.default_rng(seed)
    width, height = board.size
    corners = np.float32([[0, 0], [width, 0], [width, height], [0, height]])
    seen = np.float32([[40, 60], [600, 40], [620, 420], [20, 450]]) + rng.uniform(-30, 30, (4, 2)).astype(np.float32)
    homography = cv2.getPerspectiveTransform(corners, seen)
    return {i: cv2.perspectiveTransform(board.marker_square(i)[None].astype(np.float32), homography)[0]
            for i in BOARD_IDS}


@pytest.mark.parametrize("name", sorted(board_layouts.LAYOUTS))
def test_three_markers_of_a_picture_predict_the_fourth_whatever_the_layout(name):
    """picture_prediction puts a hidden marker where it is, from the three others, on every
    layout; the course board's layout (course_prediction) does so only on the course's."""
    board = board_layouts.LayoutBoard(board_layouts.LAYOUTS[name])
    markers = _seen_markers(board, seed=len(name))
    for picture, ids in marker_board.PICTURES.items():
        for hidden in ids:
            others = {i: markers[i] for i in ids if i != hidden}
            homography, squares, _ = crop.picture_prediction(others, picture)
            predicted = cv2.perspectiveTransform(squares[hidden][None], homography)[0]
            assert np.abs(predicted - markers[hidden]).max() < 0.05, (picture, hidden, predicted, markers[hidden])
    known = {i: c for i, c in markers.items() if i != 3}
    course = crop.course_prediction(known)
    if name == "course":
        homography, squares, _ = course["cat"]
        assert np.abs(cv2.perspectiveTransform(squares[3][None], homography)[0] - markers[3]).max() < 0.05
    else:
        assert course is None, "the course layout does not fit a board of another layout"


def test_the_course_layout_is_the_course_board_and_layouts_are_seeded():
    board, course = board_layouts.LayoutBoard(board_layouts.LAYOUTS["course"]), boards.Board()
    assert board.size == course.size
    for i in BOARD_IDS:
        assert (board.marker_square(i) == course.marker_square(i)).all()
    first = board_layouts.layout_scene(3, board_layouts.LAYOUTS["wide 16:9"], "dark weave", "easy")
    again = board_layouts.layout_scene(3, board_layouts.LAYOUTS["wide 16:9"], "dark weave", "easy")
    assert (first.frame == again.frame).all()
    with pytest.raises(ValueError, match="table must be one of"):
        board_layouts.layout_scene(3, board_layouts.LAYOUTS["course"], "marble")
