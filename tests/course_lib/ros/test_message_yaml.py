"""Tests for course_lib.ros.message_yaml: messages printed like ros2 topic echo, filled like ros2 topic pub."""

import pytest
from sensor_msgs.msg import Image
from std_msgs.msg import String

from course_lib.ros import message_yaml


def test_format_message_prints_like_ros2_topic_echo():
    """YAML with quoting where needed, nested fields indented, long arrays cut with '...'."""
    assert message_yaml.format_message(String(data="a: b")) == "data: 'a: b'\n"
    image = Image(height=1, width=200, encoding="mono8", step=200, data=bytes(range(200)))
    text = message_yaml.format_message(image, truncate_length=3)
    assert "header:\n  stamp:\n    sec: 0\n" in text
    assert "data:\n- 0\n- 1\n- 2\n- '...'\n" in text
    assert message_yaml.message_to_dict(image, truncate_length=None)["data"] == list(range(200))


def test_echo_options_shorten_strings_and_arrays_like_ros2_topic_echo():
    """Long strings are cut like arrays; --no-arr and --no-str leave only types and lengths."""
    image = Image(height=1, width=4, encoding="mono8", step=4, data=bytes(4))
    assert message_yaml.message_to_dict(String(data="abcdef"), truncate_length=3) == {"data": "abc..."}
    assert message_yaml.message_to_dict(String(data="abcdef"), no_str=True) == {"data": "<string length: <6>>"}
    assert message_yaml.message_to_dict(image, no_arr=True)["data"] == "<sequence type: uint8, length: 4>"
    assert message_yaml.message_to_dict(image, no_arr=True)["encoding"] == "mono8"


def test_fill_message_reads_values_the_way_ros2_topic_pub_does():
    """Nested dicts, lists of messages, ints for floats, and `header: auto` become a message."""
    from geometry_msgs.msg import PolygonStamped

    msg = PolygonStamped()
    setters = message_yaml.fill_message(msg, {"header": "auto", "polygon": {"points": [{"x": 1, "y": 2.5}, {}]}})
    assert [(point.x, point.y) for point in msg.polygon.points] == [(1.0, 2.5), (0.0, 0.0)]
    assert len(setters) == 1
    setters[0](message_yaml.message_class("builtin_interfaces/msg/Time")(sec=7))
    assert msg.header.stamp.sec == 7
    image = Image()
    message_yaml.fill_message(image, {"data": [1, 2, 3], "encoding": "mono8"})
    assert list(image.data) == [1, 2, 3] and image.encoding == "mono8"


@pytest.mark.parametrize("values, message", [
    ({"dta": 5}, "has no field 'dta'; its fields are: data"),
    ({"data": "five"}, "data is a int32 and cannot take 'five'"),
    ([5], "The message is a std_msgs/msg/Int32 and needs a dictionary of its fields"),
])
def test_fill_message_names_the_field_that_does_not_fit(values, message):
    from std_msgs.msg import Int32

    with pytest.raises(ValueError, match=message):
        message_yaml.fill_message(Int32(), values)


def test_message_class_reads_both_name_forms_and_names_the_missing_package():
    """'std_msgs/msg/String' and 'std_msgs/String' both work; a missing package names its pip."""
    assert message_yaml.message_class("std_msgs/msg/String") is String
    assert message_yaml.message_class("std_msgs/String") is String
    with pytest.raises(ValueError, match="ros-jazzy-nope-msgs"):
        message_yaml.message_class("nope_msgs/msg/Thing")
    with pytest.raises(ValueError, match="package/msg/Type"):
        message_yaml.message_class("String")
