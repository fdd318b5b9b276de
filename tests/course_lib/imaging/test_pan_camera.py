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


def detected(pan: float) -> list[int]:
    """The markers OpenCV's ArUco detector (default parameters) finds in the frame at `pan`."""
    _, ids, _ = marker_board.detector().detectMarkers(pan_camera.frame_at(pan))
    return sorted(int(i) for i in ids.ravel()) if ids is not None else []


#: Every degree where a marker can be in view, and angles where markers touch the frame's border
#: band (at 14.5 the detector finds markers 1 and 4 at 3.7 pixels from the border, at 14.75 it
#: misses them at 1.6). A sweep every 0.1 degree from -40 to 40 (801 frames) agreed as well.
SWEEP = [*range(-34, 35), *(sign * pan for sign in (-1, 1) for pan in (14.5, 14.75, 24.5, 26.8, 31.6))]


def test_a_detector_finds_every_marker_in_view_and_no_other_but_uncertain_ones():
    """Over a sweep of pan angles, ArUco finds each marker of markers_in_view, and any other it
    finds is one of uncertain_markers: a node that looks with a detector is never wrong."""
    for pan in SWEEP:
        found, sure = set(detected(pan)), set(pan_camera.markers_in_view(pan))
        assert sure <= found <= sure | set(pan_camera.uncertain_markers(pan)), (pan, sorted(found), sorted(sure))


def test_the_answer_is_decisive_and_the_lessons_figure_agrees_with_its_title():
    """Uncertain markers are the exception (34 of the 1200 angles a tenth of a degree apart where
    the board can be in view), and at lesson 04's figure's angles the title (markers_in_view,
    framed_at) is what the detector finds."""
    uncertain = [k for k in range(-600, 600) if pan_camera.uncertain_markers(k / 10)]
    assert len(uncertain) <= 60, len(uncertain)
    assert detected(-25.0) == [1, 2, 3, 4] == list(pan_camera.markers_in_view(-25.0))
    assert pan_camera.framed_at(-25.0) == ("cat",)
    for pan in (-10.0, 0.0):
        assert detected(pan) == list(range(1, 9)) == list(pan_camera.markers_in_view(pan))
        assert pan_camera.framed_at(pan) == ("cat", "dog")


def test_pictures_of_uncertain_markers_are_maybe_framed_and_a_search_may_stop_there():
    """At -14.6 degrees the dog's markers 6 and 7 touch the frame's border band: the dog is maybe
    framed, so a search for it that steps onto -14.6 may stop there or, surely, at the next step."""
    assert pan_camera.uncertain_markers(-14.6) == (6, 7) and pan_camera.maybe_framed_at(-14.6) == ("dog",)
    assert pan_camera.framed_at(-14.6) == ("cat",)
    assert pan_camera.maybe_framed_at(0) == () and pan_camera.uncertain_markers(0) == ()
    pans = pan_camera.search_pans(-54.6, ["dog"])
    assert [round(p, 6) for p in pan_camera.search_stops(-54.6, ["dog"])] == [-14.6, -9.6] == [
        round(p, 6) for p in pans[-2:]]
    assert pan_camera.search_stops(-44.6, ["cat"]) == pan_camera.search_pans(-44.6, ["cat"])[-1:]


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
