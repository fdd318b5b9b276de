"""Tests for course_lib.imaging.marker_board: the marker convention, crop corners and crop similarity."""

import cv2
import numpy as np
import pytest

from course_lib.imaging import marker_board, pictures, scenes

BOARD_IDS = (1, 2, 3, 4, 5, 6, 7, 8)


def test_picture_corners_come_from_the_named_marker_corners():
    markers = {i: np.arange(8, dtype=np.float32).reshape(1, 4, 2) + 100 * i for i in BOARD_IDS}
    cat = marker_board.picture_corners(markers, "cat")
    assert cat.dtype == np.float32 and cat.shape == (4, 2)
    np.testing.assert_array_equal(cat, [markers[1][0, 2], markers[2][0, 3], markers[3][0, 0], markers[4][0, 1]])
    del markers[7]
    assert marker_board.picture_corners(markers, "dog") is None
    with pytest.raises(KeyError, match="cat"):
        marker_board.picture_corners(markers, "cow")


def test_crop_corners_put_the_top_left_corner_at_pixel_zero():
    np.testing.assert_array_equal(marker_board.crop_corners((320, 240)), [[0, 0], [319, 0], [319, 239], [0, 239]])
    with pytest.raises(ValueError, match="width, height"):
        marker_board.crop_corners(320)


@pytest.mark.parametrize("seed, difficulty", [(0, "easy"), (1, "easy"), (9, "hard"), (15, "hard")])
def test_corner_order_mistakes_and_swapped_pictures_score_below_the_threshold(seed, difficulty):
    scene = scenes.render_scene(seed, difficulty=difficulty)
    expected = scene.expected_crops()
    target = marker_board.crop_corners()
    assert scene.fully_framed, "pick seeds where a picture is fully framed"
    for name in scene.fully_framed:
        other = "dog" if name == "cat" else "cat"
        corners = scene.picture_corners(name)
        wrong = {
            "mirrored": corners[[1, 0, 3, 2]],
            "upside down": corners[[3, 2, 1, 0]],
            "rotated 90": np.roll(corners, 1, axis=0),
            "rotated 180": np.roll(corners, 2, axis=0),
            "rotated 270": np.roll(corners, 3, axis=0),
            "other picture": scene.picture_corners(other),
        }
        for mistake, bad_corners in wrong.items():
            crop = cv2.warpPerspective(scene.frame, cv2.getPerspectiveTransform(bad_corners, target),
                                       marker_board.DEFAULT_SIZE)
            score = marker_board.crop_similarity(crop, expected[name])
            assert score < marker_board.SAME_CROP_THRESHOLD - 0.2, f"{name} {mistake}: {score:.3f}"


def test_crop_similarity_ignores_brightness_but_not_content():
    cat = pictures.draw_cat()
    assert marker_board.crop_similarity(cat, cat) == pytest.approx(1.0)
    darker = cv2.convertScaleAbs(cat, alpha=0.6, beta=20)
    assert marker_board.crop_similarity(darker, cat) > 0.98
    assert marker_board.crop_similarity(cv2.resize(cat, (640, 480)), cat) > 0.98
    flat = np.full_like(cat, 128)
    assert marker_board.crop_similarity(flat, cat) == 0.0
    assert marker_board.crop_similarity(255 - cat, cat) == 0.0
    assert marker_board.crop_similarity(pictures.draw_dog(), cat) < 0.5
    with pytest.raises(ValueError, match="height, width"):
        marker_board.crop_similarity(np.zeros(5), cat)
