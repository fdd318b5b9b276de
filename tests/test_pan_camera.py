"""Tests for course_lib.pan_camera: what the camera on a pan head sees at an angle."""

import math

import pytest

from course_lib.imaging import marker_board, pan_camera, scenes


def test_both_pictures_are_framed_straight_ahead_and_nothing_far_to_the_side():
    assert pan_camera.framed_at(0) == ("cat", "dog")
    assert pan_camera.markers_in_view(0) == tuple(range(1, 9))
    assert pan_camera.markers_in_view(pan_camera.START_PAN) == ()
    assert pan_camera.markers_in_view(180) == pan_camera.markers_in_view(-180) == ()


def test_turning_right_from_the_start_frames_the_cat_before_the_dog():
    """The search the lesson and the assignment make: steps of STEP_DEGREES from START_PAN."""
    pans = [pan_camera.START_PAN + k * pan_camera.STEP_DEGREES for k in range(40)]
    first_cat = next(p for p in pans if "cat" in pan_camera.framed_at(p))
    first_both = next(p for p in pans if pan_camera.framed_at(p) == ("cat", "dog"))
    assert pan_camera.START_PAN < first_cat < first_both < 10


def test_the_answer_matches_a_rendered_frame():
    """ArUco finds every marker the geometry says is in view (it may find smaller ones too:
    markers below scenes.MIN_MARKER_SIDE do not count, as in every scene of the course)."""
    for pan in (-15.0, 0.0, 10.0):
        _, ids, _ = marker_board.detector().detectMarkers(pan_camera.frame_at(pan))
        found = sorted(int(i) for i in ids.ravel()) if ids is not None else []
        assert set(pan_camera.markers_in_view(pan)) <= set(found), (pan, found)


def test_angles_wrap_and_bad_ones_name_the_fix():
    assert pan_camera.wrap(190) == -170 and pan_camera.wrap(-180) == -180
    with pytest.raises(ValueError, match="finite number of degrees"):
        pan_camera.wrap(math.nan)
    with pytest.raises(ValueError, match="use 'cat' or 'dog'"):
        pan_camera.markers_of(["cow"])
    assert pan_camera.markers_of([]) == tuple(range(1, 9)) and pan_camera.markers_of(["dog"]) == (5, 6, 7, 8)


def test_framed_from_is_the_pictures_of_detectable_from():
    pose = pan_camera.pose_at(-10)
    assert scenes.framed_from(pose) == ("cat",) and set(scenes.detectable_from(pose)) >= {1, 2, 3, 4}
