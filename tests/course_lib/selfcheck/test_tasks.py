"""Tests for course_lib.selfcheck.tasks: stubs get 'not done yet', wrong answers a specific hint.
(The exercises' checks: test_node_exercises.py, test_launch_exercise.py, test_brightness_package.py, beside
this file.)"""

import pytest
from rclpy.node import Node
from std_msgs.msg import Int32, String

from course_lib import selfcheck
from course_lib.ros import discovery, session


@pytest.fixture
def my_node(monkeypatch):
    monkeypatch.setattr(discovery, "SETTLE_SECONDS", 0)  # in-process nodes need no discovery wait
    session.start()
    node = session.add_node(Node("my_node"))
    yield node
    session.stop()


@pytest.mark.parametrize("stub", [None, ..., "...", ""])
def test_task1_stub_is_not_done_yet(stub):
    verdict = selfcheck.task1_node_name(stub)
    assert not verdict and "Not done yet" in str(verdict) and "graph.node_list()" in str(verdict)


def test_task1_accepts_the_listed_name(my_node):
    verdict = selfcheck.task1_node_name("/my_node")
    assert verdict and str(verdict).startswith("✔")


def test_task1_missing_slash_gets_the_namespace_hint(my_node):
    verdict = selfcheck.task1_node_name("my_node")
    assert not verdict and "Write '/my_node'" in str(verdict)


def test_task1_someone_elses_node(my_node):
    session.add_node(Node("other"))
    verdict = selfcheck.task1_node_name("/other")
    assert not verdict and "not yours" in str(verdict)


def test_task1_node_not_running(monkeypatch):
    monkeypatch.setattr(discovery, "SETTLE_SECONDS", 0)
    session.start()
    try:
        verdict = selfcheck.task1_node_name("/my_node")
    finally:
        session.stop()
    assert not verdict and "is it still running?" in str(verdict)


def test_task2_verdicts():
    assert "Not done yet" in str(selfcheck.task2_echo(None))
    assert "Nothing was echoed" in str(selfcheck.task2_echo([]))
    assert "carries std_msgs/msg/String" in str(selfcheck.task2_echo([Int32(data=3)]))
    assert "which the talker did not send" in str(selfcheck.task2_echo([String(data="hi")]))
    assert selfcheck.task2_echo([String(data="Hello World: 7")])
    assert selfcheck.task2_echo(String(data="Hello World: 7")), "a single message (not a list) is fine too"


def test_task2_stub_hint_does_not_give_the_answer_away():
    """The hint points at how to find the topic, not at the finished call."""
    hint = str(selfcheck.task2_echo(None))
    assert "topic_list()" in hint and "/chatter" not in hint and "topic_echo(" not in hint


def test_task2_what_the_listener_heard_is_not_an_echo():
    """listener.heard[0] is the right topic's text but the wrong object: the verdict says so."""
    verdict = selfcheck.task2_echo("Hello World: 3")
    assert not verdict and "not a ROS message" in str(verdict) and "listener.heard" in str(verdict)
    assert "right topic" not in str(verdict)


# --- Task 3 (lesson 02): publish brightness only when it changes by more than a threshold -----

def _publish_on_change(last_sent, current, threshold):
    return last_sent is None or abs(int(current) - int(last_sent)) > threshold


@pytest.mark.parametrize("stub", [None, lambda last, current, threshold: None])
def test_task3_stub_is_not_done_yet(stub):
    verdict = selfcheck.task3_brightness_on_change(stub)
    assert not verdict and "Not done yet" in str(verdict)


def test_task3_accepts_a_correct_filter():
    assert selfcheck.task3_brightness_on_change(_publish_on_change)


@pytest.mark.parametrize("wrong, named", [
    (lambda last, current, threshold: abs(int(current) - int(last)) > threshold, "last_sent is None"),
    (lambda last, current, threshold: last is None or int(current) - int(last) > threshold, "a drop of 6 counts too"),
    (lambda last, current, threshold: last is None or abs(int(current) - int(last)) >= threshold, "use >, not >="),
    (lambda last, current, threshold: last is None or abs(current - last) > threshold, "uint8 arithmetic wraps"),
    (lambda last, current, threshold: 1 / 0, "raised ZeroDivisionError"),
    (lambda last, current, threshold: not last or abs(int(current) - int(last)) > threshold, "not `not last_sent`"),
])
def test_task3_names_what_is_wrong(wrong, named):
    verdict = selfcheck.task3_brightness_on_change(wrong)
    assert not verdict and named in str(verdict)


def test_task3_shows_a_numpy_answer_as_python_shows_it():
    """uint8 arithmetic that wraps answers np.True_: the verdict says True (and keeps np.uint8 for the arguments)."""
    verdict = str(selfcheck.task3_brightness_on_change(lambda last, current, threshold:
                                                       last is None or abs(current - last) > threshold))
    assert "returned True, expected False" in verdict and "np.True_" not in verdict, verdict
    assert "np.uint8(103)" in verdict, verdict


# --- Task 4 (lesson 03): order four shuffled corners ------------------------------------------

def _order_by_angle(points):
    import numpy as np

    points = np.asarray(points, dtype=float)
    centre = points.mean(axis=0)
    points = points[np.argsort(np.arctan2(points[:, 1] - centre[1], points[:, 0] - centre[0]))]
    return np.roll(points, -int(np.argmin(points.sum(axis=1))), axis=0)


def _sum_and_difference(points):
    """The well-known shortcut: top-left has the smallest x + y, top-right the smallest y - x, ..."""
    import numpy as np

    points = np.asarray(points, dtype=float)
    total, difference = points.sum(axis=1), points[:, 1] - points[:, 0]
    return points[[total.argmin(), difference.argmin(), total.argmax(), difference.argmax()]]


def test_task4_stub_and_correct_answer():
    assert "Not done yet" in str(selfcheck.task4_order_corners(None))
    assert "Not done yet" in str(selfcheck.task4_order_corners(lambda points: None))
    assert selfcheck.task4_order_corners(_order_by_angle)


@pytest.mark.parametrize("wrong, named", [
    (lambda p: _order_by_angle(p)[[0, 3, 2, 1]], "anticlockwise"),
    (lambda p: __import__("numpy").roll(_order_by_angle(p), 1, axis=0), "starts at the bottom-left"),
    (lambda p: _order_by_angle(p) * 2, "not the four points it was given"),
    (lambda p: [1, 2, 3], "numpy array of shape (4, 2)"),
    (lambda p: [tuple(corner) for corner in _order_by_angle(p)], "numpy array of shape (4, 2)"),
    (lambda p: _sum_and_difference(p), "picks one point twice"),
])
def test_task4_names_what_is_wrong(wrong, named):
    verdict = selfcheck.task4_order_corners(wrong)
    assert not verdict and named in str(verdict)


def test_task4_catches_taking_the_two_highest_points_as_the_top():
    import numpy as np

    def two_highest_are_top(points):
        points = np.asarray(points)
        by_y = points[np.argsort(points[:, 1])]
        top, bottom = by_y[:2][np.argsort(by_y[:2, 0])], by_y[2:][np.argsort(by_y[2:, 0])]
        return np.array([top[0], top[1], bottom[1], bottom[0]])

    verdict = selfcheck.task4_order_corners(two_highest_are_top)
    assert not verdict and "long rectangle tilted by 30 degrees" in str(verdict)


# ---- lesson 03: the cat/dog corner mapping ----------------------------------------------------

def corners_using(marker_corner):
    """A picture_corners_of that takes corner marker_corner[k] of the k-th marker of the picture."""
    import numpy as np

    from course_lib.imaging import marker_board

    def picture_corners_of(markers, picture):
        return np.array([markers[m][c] for m, c in zip(marker_board.PICTURES[picture], marker_corner, strict=True)])
    return picture_corners_of


@pytest.mark.parametrize("answer, expected", [
    (lambda markers, picture: None, "Not done yet"),
    (corners_using((0, 0, 0, 0)), "you took corner 0 of marker 1, which does not touch the picture"),
    (lambda markers, picture: corners_using((2, 3, 0, 1))(markers, "dog" if picture == "cat" else "cat"),
     "you took a corner of marker 5; that corner lies on marker 1"),
    (lambda markers, picture: [[0, 0]] * 4, "no corner of a marker"),
    (corners_using((2, 3, 0, 1)), "✔"),
])
def test_picture_corner_check_fails_the_stub_and_wrong_corners_and_passes_the_convention(answer, expected):
    verdict = selfcheck.task_picture_corners(answer)
    assert bool(verdict) == (expected == "✔") and expected in str(verdict), str(verdict)


