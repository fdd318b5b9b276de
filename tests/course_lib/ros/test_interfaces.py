"""Tests for course_lib.ros.interfaces: `ros2 interface show/package/packages` from the installed files."""

import pytest

from course_lib.ros import interfaces


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
    # rosidl_runtime_py's get_interface_path, as ros2interface's test_cli.py expects them
    # (test_show_not_an_interface, test_show_not_a_package).
    ("std_msgs/msg/Nope", r"^Could not find the interface '/.+/share/std_msgs/msg/Nope\.idl'$"),
    ("no_such_msgs/msg/X", r"^Unknown package 'no_such_msgs'$"),
    ("Twist", "package/msg/Type"),
])
def test_bad_names_get_ros2_interface_shows_words(name, message):
    with pytest.raises((LookupError, ValueError), match=message):
        interfaces.show(name)


def test_inside_a_kernel_a_notebook_hint_follows(monkeypatch):
    """Only where interfaces.packages() can be called is it named."""
    from course_lib.ros import node_logs

    monkeypatch.setattr(node_logs, "in_kernel", lambda: True)
    with pytest.raises(LookupError, match=r"^Unknown package 'no_such_msgs' \(in a notebook: interfaces\.packages"):
        interfaces.show("no_such_msgs/msg/X")
    with pytest.raises(LookupError, match=r"Nope\.idl' \(in a notebook: std_msgs has the msg types Bool, "):
        interfaces.show("std_msgs/msg/Nope")


def test_comments_like_ros2_interface_show():
    """By default the interface's own comments stay and nested types have none; 'none' drops all."""
    shown = interfaces.show("sensor_msgs/msg/Image").splitlines()
    assert shown[0] == "# This message contains an uncompressed image"
    assert "std_msgs/Header header # Header timestamp should be acquisition time of image" in shown
    assert not any(line.startswith("\t") and "#" in line for line in shown)
    bare = interfaces.show("sensor_msgs/msg/Image", comments="none").splitlines()
    assert bare[:2] == ["std_msgs/Header header", "\tbuiltin_interfaces/Time stamp"]
    assert "uint8[] data" in bare and not any("#" in line or not line.strip() for line in bare)
    every = interfaces.show("sensor_msgs/msg/Image", comments="all")
    assert "\t# Two-integer timestamp that is expressed as seconds and nanoseconds." in every.splitlines()


def test_services_show_both_halves_and_nest_their_messages():
    """A .srv shows request, the --- line and response, each with its nested messages."""
    lines = interfaces.show("rcl_interfaces/srv/SetParameters", comments="none").splitlines()
    assert lines == ["Parameter[] parameters", "\tstring name", "\tParameterValue value", "\t\tuint8 type",
                     *lines[4:13], "---", "SetParametersResult[] results", "\tbool successful", "\tstring reason"]
