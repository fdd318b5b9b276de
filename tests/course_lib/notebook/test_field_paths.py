"""Tests for course_lib.notebook.field_paths: rqt_plot's topic/field paths, and the errors of paths
that name no number (without a graph: the message type is given)."""

import pytest
from geometry_msgs.msg import PoseStamped

from course_lib.notebook.field_paths import resolve_field_path


@pytest.mark.parametrize("path, message", [
    ("/pose", r"does not hold one number: plot one of its fields, e\.g\. /pose/header/stamp/sec"),
    ("/pose/pose/position", r"is a message \(geometry_msgs/msg/Point\).*e\.g\. /pose/pose/position/x"),
    ("/pose/pose/nope", r"has no field 'nope'; its fields: position, orientation"),
    ("/pose/header/frame_id", r"/pose/header/frame_id is a string, not a number"),
    ("/pose/pose/position/x[0]", r"is a double, not an array: drop the \[0\]"),
])
def test_a_path_that_names_no_number_is_refused_with_the_fields_there_are(path, message):
    with pytest.raises(ValueError, match=message):
        resolve_field_path(None, path, msg_type=PoseStamped)


def test_array_elements_are_plotted_by_index():
    from sensor_msgs.msg import LaserScan

    name, topic, cls, read = resolve_field_path(None, "/scan/ranges[1]", msg_type=LaserScan)
    assert (name, topic, cls) == ("/scan/ranges[1]", "/scan", LaserScan)
    assert read(LaserScan(ranges=[1.0, 2.5])) == 2.5
    with pytest.raises(ValueError,
                       match=r"is an array \(sequence<float>\): plot one element, e\.g\. /scan/ranges\[0\]"):
        resolve_field_path(None, "/scan/ranges", msg_type=LaserScan)
