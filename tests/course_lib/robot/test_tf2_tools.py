"""The tf2 tools on the pip install (course_lib.robot: static_transform_publisher, tf2_echo, view_frames,
frame_graph) say and do what tf2_ros and tf2_tools do: their arguments, words, layout and files."""

import math
import signal
import subprocess

import pytest
import yaml
from geometry_msgs.msg import TransformStamped
from support.process import wait_until
from support.ros2cli import ROS2, ros2

from course_lib.robot import frame_graph, tf2_echo
from course_lib.robot.static_transform_publisher import ArgumentError, parse_args, quaternion_from_rpy
from course_lib.robot.tf_buffer import Buffer
from course_lib.ros import rosenv
from course_lib.supervision import process_tree

STOP_STEPS = ((signal.SIGINT, 60.0), (signal.SIGKILL, 5.0))


# --- static_transform_publisher's arguments (tf2_ros/src/static_transform_broadcaster_program.cpp) ---

def test_new_style_flags_give_translation_rotation_and_frames():
    found = parse_args(["--x", "0.35", "--z", "0.4", "--yaw", str(math.pi / 2), "--frame-id", "base_link",
                        "--child-frame-id", "laser"])
    assert found["translation"] == (0.35, 0.0, 0.4)
    assert found["rotation"] == pytest.approx((0.0, 0.0, math.sqrt(0.5), math.sqrt(0.5)))
    assert (found["frame_id"], found["child_frame_id"]) == ("base_link", "laser")


def test_without_a_rotation_it_is_the_identity_and_a_quaternion_is_taken_as_given():
    assert parse_args(["--frame-id", "a", "--child-frame-id", "b"])["rotation"] == (0.0, 0.0, 0.0, 1.0)
    assert parse_args(["--qz", "1", "--qw", "0", "--frame-id", "a", "--child-frame-id", "b"])["rotation"] \
        == (0.0, 0.0, 1.0, 0.0)


def test_roll_pitch_yaw_is_tf2s_setRPY():
    x, y, z, w = quaternion_from_rpy(0.1, 0.2, 0.3)
    # tf2: yaw about z, then pitch about y, then roll about x
    assert (x, y, z, w) == pytest.approx((0.0342708, 0.1060205, 0.1435722, 0.9833474), abs=1e-6)


def test_the_old_positional_forms_are_yaw_pitch_roll_or_a_quaternion_with_the_deprecation_warning(capsys):
    eight = parse_args(["1", "2", "3", str(math.pi / 2), "0", "0", "a", "b"])
    assert eight["translation"] == (1.0, 2.0, 3.0) and eight["rotation"][2] == pytest.approx(math.sqrt(0.5))
    nine = parse_args(["1", "2", "3", "0", "0", "0", "1", "a", "b"])
    assert nine["rotation"] == (0.0, 0.0, 0.0, 1.0) and (nine["frame_id"], nine["child_frame_id"]) == ("a", "b")
    warned = capsys.readouterr().err
    assert warned.count("[WARN]") == 2
    assert warned.count("[]: Old-style arguments are deprecated; see --help for new-style arguments") == 2


@pytest.mark.parametrize(("args", "words"), [
    (["--roll", "1", "--qw", "1", "--frame-id", "a", "--child-frame-id", "b"],
     "Cannot specify both quaternion and Euler rotations"),
    (["--x", "1", "1", "2", "3", "0", "0", "0", "a", "b"],
     "Cannot specify both new-style (flags) and old-style (arguments)"),
    (["--frame-id", "a", "--child-frame-id", "b", "extra"], "Extra unparsed arguments on command-line"),
    (["--child-frame-id", "b"], "Frame id must not be empty"),
    (["--frame-id", "a"], "Child frame id must not be empty"),
    (["--frame-id", "a", "--child-frame-id"], "Not enough arguments for --child-frame-id"),
    (["--x", "one", "--frame-id", "a", "--child-frame-id", "b"], "Failed to parse --x argument as float"),
])
def test_wrong_arguments_get_upstreams_reason(args, words):
    with pytest.raises(ArgumentError) as raised:
        parse_args(args)
    assert str(raised.value) == words


def test_help_is_asked_with_h_or_help():
    assert parse_args(["-h"]) is None and parse_args(["--frame-id", "a", "--help"]) is None


# --- tf2_echo's layout (tf2_ros/src/tf2_echo.cpp; the turtlesim tf2 tutorial shows it) ------------

def test_tf2_echo_prints_upstreams_layout():
    yaw = math.radians(-176.013)
    transform = TransformStamped()
    transform.header.stamp.sec, transform.header.stamp.nanosec = 1714913843, 708748879
    transform.transform.translation.x, transform.transform.translation.y = 4.541, 3.889
    r = transform.transform.rotation
    r.z, r.w = -math.sin(yaw / 2), -math.cos(yaw / 2)  # the sign the tutorial's quaternion has
    assert tf2_echo.format_transform(transform) == """At time 1714913843.708748879
- Translation: [4.541, 3.889, 0.000]
- Rotation: in Quaternion [0.000, 0.000, 0.999, -0.035]
- Rotation: in RPY (radian) [0.000, -0.000, -3.072]
- Rotation: in RPY (degree) [0.000, -0.000, -176.013]
- Matrix:
 -0.998  0.070  0.000  4.541
 -0.070 -0.998  0.000  3.889
  0.000  0.000  1.000  0.000
  0.000  0.000  0.000  1.000"""


def test_roll_pitch_yaw_come_back_from_the_matrix():
    q = quaternion_from_rpy(0.3, -0.4, 2.5)
    assert tf2_echo.roll_pitch_yaw(tf2_echo.rotation_matrix(*q)) == pytest.approx((0.3, -0.4, 2.5))


def test_tf2_echo_arguments_and_rate():
    assert tf2_echo.parse_rate(["a", "b"]) == 1.0 and tf2_echo.parse_rate(["a", "b", "10"]) == 10.0
    assert tf2_echo.parse_rate(["a", "b", "foo"]) == (
        "Failed to convert rate argument 'foo' to a floating-point number", 2)
    assert tf2_echo.parse_rate(["a"]) == (tf2_echo.USAGE, 1)


def test_can_transform_says_why_not_in_tf2s_words():
    buffer = Buffer()
    assert buffer.can_transform("odom", "laser", 0, return_debug_tuple=True) == (
        False, 'Invalid frame ID "odom" passed to canTransform argument target_frame - frame does not exist')


# --- view_frames' graph (tf2_tools/tf2_tools/view_frames.py) ------------------------------------------

FRAMES_YAML = """base_link: \n  parent: 'odom'\n  broadcaster: 'default_authority'\n  rate: 20.000
  most_recent_transform: 12.500000\n  oldest_transform: 2.500000\n  buffer_length: 10.000
laser: \n  parent: 'base_link'\n  broadcaster: 'default_authority'\n  rate: 10000.000
  most_recent_transform: 0.000000\n  oldest_transform: 0.000000\n  buffer_length: 0.000
"""


def test_the_gv_file_is_upstreams_digraph_and_reads_back(tmp_path):
    text = frame_graph.dot_text(yaml.safe_load(FRAMES_YAML), 13.25)
    assert text.splitlines()[1] == ('"odom" -> "base_link"[label=" Broadcaster: default_authority\\n'
                                    'Average rate: 20.0\\nBuffer length: 10.0\\n'
                                    'Most recent transform: 12.5\\nOldest transform: 2.5\\n"];')
    assert text.endswith('"Recorded at time: 13.25"[ shape=plaintext ] ;\n}->"odom";\n}')
    (tmp_path / "frames.gv").write_text(text)
    graph = frame_graph.read_gv(tmp_path / "frames.gv")
    assert [(p, c) for p, c, _ in graph["edges"]] == [("odom", "base_link"), ("base_link", "laser")]
    assert graph["edges"][1][2][1] == "Average rate: 10000.0" and graph["recorded"] == "13.25"
    assert frame_graph.dot_text({}, 0.0) == 'digraph G { "No tf data received" }'


def test_the_tree_is_drawn_top_down_with_parents_over_children():
    places = frame_graph.layout([("odom", "base_link", []), ("base_link", "laser", []), ("base_link", "camera", [])])
    assert places["odom"][1] == 0 and places["laser"][1] == places["camera"][1] == 2
    assert places["base_link"][0] == pytest.approx((places["laser"][0] + places["camera"][0]) / 2)


# --- the three as `ros2 run` starts them ------------------------------------------------------------

def test_ros2_run_publishes_echoes_and_draws_a_static_transform(domain_id, tmp_path):
    """About 3 CPU-s: three short ROS processes."""
    env = rosenv.ros_environment(domain_id)
    publisher = subprocess.Popen(
        [str(ROS2), "run", "tf2_ros", "static_transform_publisher", "--x", "0.35", "--z", "0.4", "--yaw", "1.5707963",
         "--frame-id", "base_link", "--child-frame-id", "laser"], env=env, start_new_session=True,
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, stdin=subprocess.DEVNULL)
    echo = subprocess.Popen([str(ROS2), "run", "tf2_ros", "tf2_echo", "base_link", "laser", "5"], env=env,
                            start_new_session=True, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                            stdin=subprocess.DEVNULL)
    try:
        lines = []
        wait_until(lambda: (lines.append(echo.stdout.readline()) or "- Matrix:\n" in lines) or echo.poll() is not None)
        for _ in range(4):
            lines.append(echo.stdout.readline())
        printed = "".join(lines[lines.index("- Matrix:\n") - 5:])
        assert printed.startswith("At time 0.0\n- Translation: [0.350, 0.000, 0.400]\n"
                                  "- Rotation: in Quaternion [0.000, 0.000, 0.707, 0.707]\n"), printed
        assert "- Rotation: in RPY (degree) [0.000, -0.000, 90.000]\n" in printed
        drawn = ros2("run", "tf2_tools", "view_frames", "-t", "0", "-o", str(tmp_path / "frames"), env=env)
        assert "[view_frames]: Listening to tf data for 0.0 seconds..." in drawn.stderr
        assert f"Exporting graph in {tmp_path / 'frames'}.pdf file..." in drawn.stderr
        assert frame_graph.read_gv(tmp_path / "frames.gv")["edges"][0][:2] == ("base_link", "laser")
        assert (tmp_path / "frames.pdf").read_bytes().startswith(b"%PDF")
    finally:
        process_tree.stop_group(echo, STOP_STEPS)
        code = process_tree.stop_group(publisher, STOP_STEPS)
        said = publisher.stdout.read()
    assert "Spinning until stopped - publishing transform\ntranslation: ('0.350000', '0.000000', '0.400000')\n" \
           "rotation: ('0.000000', '0.000000', '0.707107', '0.707107')\nfrom 'base_link' to 'laser'" in said
    assert "[static_transform_publisher_" in said and code in (0, -signal.SIGINT)


def test_wrong_arguments_print_the_usage_and_exit_1(domain_id):
    env = rosenv.ros_environment(domain_id)
    done = ros2("run", "tf2_ros", "static_transform_publisher", "--frame-id", "a", env=env, check=False)
    assert done.returncode == 1 and done.stdout.startswith("usage: static_transform_publisher [--x X]")
    assert "[ERROR]" in done.stderr and "[]: error parsing command line arguments: Child frame id must not be empty" \
        in done.stderr
    echo = ros2("run", "tf2_ros", "tf2_echo", "base_link", env=env, check=False)
    assert echo.returncode == 1 and echo.stdout.startswith("Usage: tf2_echo source_frame target_frame [echo_rate]\n\n")
