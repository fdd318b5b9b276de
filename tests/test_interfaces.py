"""Tests for course_lib.interfaces: `ros2 interface show/package/packages` from the installed files."""

import pytest

from course_lib import interfaces


def test_show_expands_nested_types_like_the_cli():
    text = interfaces.show("geometry_msgs/msg/Twist")
    lines = text.splitlines()
    assert "Vector3  linear" in lines and "\tfloat64 x" in lines
    assert interfaces.show("geometry_msgs/msg/Twist", expand=False).count("float64") == 0


def test_header_nests_builtin_time_two_levels_deep():
    text = interfaces.show("sensor_msgs/msg/Image")
    assert "\t\tuint32 nanosec" in text.splitlines()
    assert "uint8[] data" in text


def test_ros1_spelling_is_accepted():
    assert interfaces.show("std_msgs/String") == interfaces.show("std_msgs/msg/String")


def test_packages_and_package_listing():
    assert {"std_msgs", "sensor_msgs", "geometry_msgs", "nav_msgs"} <= set(interfaces.packages())
    assert "nav_msgs/msg/Odometry" in interfaces.package("nav_msgs")


@pytest.mark.parametrize("name, message", [
    ("std_msgs/msg/Nope", "std_msgs has no msg 'Nope'; it has: Bool"),
    ("no_such_msgs/msg/X", "package 'no_such_msgs' is not installed"),
    ("Twist", "package/msg/Type"),
])
def test_bad_names_say_what_exists(name, message):
    with pytest.raises((LookupError, ValueError), match=message.replace("(", r"\(")):
        interfaces.show(name)
