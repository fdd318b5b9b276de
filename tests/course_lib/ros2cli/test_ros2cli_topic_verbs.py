"""``ros2 topic type|find|bw|delay`` (course_lib/ros2cli/topic.py), run as the installed
``.venv/bin/ros2`` against a publisher of stamped points and strings in a process of its own,
held to ros2topic's verb sources and test_cli.py (Jazzy)."""

import re
import signal
import subprocess
import sys
import types

import pytest
from support.ros2cli import ROS2, node_script, ros2_together

from course_lib.ros import processes, rosenv

STAMPED_TALKER = node_script('''
import sys

import rclpy
from geometry_msgs.msg import PointStamped
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import String


class StampedTalker(Node):
    """Publishes a stamped point on /stamped and 'hello world' on /words and /_hidden_words at 20 Hz."""

    def __init__(self):
        super().__init__('stamped_talker')
        self.points = self.create_publisher(PointStamped, 'stamped', 10)
        self.words = [self.create_publisher(String, name, 10) for name in ('words', '_hidden_words')]
        self.create_timer(0.05, self.tick)

    def tick(self):
        point = PointStamped()
        point.header.stamp = self.get_clock().now().to_msg()
        self.points.publish(point)
        for publisher in self.words:
            publisher.publish(String(data='hello world'))

''', 'StampedTalker()')


@pytest.fixture(scope="module")
def talker(tmp_path_factory):
    script = tmp_path_factory.mktemp("stamped") / "stamped_talker.py"
    script.write_text(STAMPED_TALKER)
    with rosenv.reserve_domain_id() as reservation:
        with processes.NodeProcess([sys.executable, str(script)], name="stamped_talker",
                                   domain_id=reservation.domain_id) as process:
            process.wait_for_node("/stamped_talker", timeout=30)
            yield types.SimpleNamespace(env=rosenv.ros_environment(domain_id=reservation.domain_id))


def test_type_and_find(talker):
    """ros2topic's test_cli.py: test_topic_type (the type alone), test_hidden_topic_type (a hidden
    topic: no output, exit code 1; it shows with `ros2 topic --include-hidden-topics type`),
    test_find_topic_type, test_find_not_a_topic_typename (no output, exit code 0); find -c and
    --include-hidden-topics as find.py has them."""
    kind, no_kind, hidden, hidden_kind, find, find_count, find_none, find_hidden = ros2_together(
        ["topic", "type", "/stamped"], ["topic", "type", "/not_a_topic"], ["topic", "type", "/_hidden_words"],
        ["topic", "--include-hidden-topics", "type", "/_hidden_words"], ["topic", "find", "std_msgs/msg/String"],
        ["topic", "find", "-c", "geometry_msgs/msg/PointStamped"],
        ["topic", "find", "std_msgs/msg/NotAMessageTypeName"],
        ["topic", "find", "--include-hidden-topics", "std_msgs/msg/String"], env=talker.env)
    assert (kind.returncode, kind.stdout) == (0, "geometry_msgs/msg/PointStamped\n")
    assert (no_kind.returncode, no_kind.stdout, no_kind.stderr) == (1, "", "")
    assert (hidden.returncode, hidden.stdout) == (1, "")
    assert (hidden_kind.returncode, hidden_kind.stdout) == (0, "std_msgs/msg/String\n")
    assert (find.returncode, find.stdout) == (0, "/words\n")
    assert (find_count.returncode, find_count.stdout) == (0, "1\n")
    assert (find_none.returncode, find_none.stdout) == (0, "")
    assert (find_hidden.returncode, find_hidden.stdout) == (0, "/_hidden_words\n/words\n")


def first_report(talker, args: list[str], lines: int) -> tuple[list[str], int, str]:
    """Run `ros2 topic ARGS` until it has printed ``lines`` lines, then Ctrl-C it; (lines, exit code, stderr)."""
    with subprocess.Popen([str(ROS2), "topic", *args], env=talker.env, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True, stdin=subprocess.DEVNULL) as command:
        printed = []
        while len(printed) < lines:
            line = command.stdout.readline()
            if not line:
                break
            printed.append(line.rstrip("\n"))
        command.send_signal(signal.SIGINT)
        _, errors = command.communicate(timeout=60)
    return printed, command.returncode, errors


def test_bw(talker):
    """bw.py: 'Subscribed to [TOPIC]', then once a second 'N B/s from M messages' and
    '\\tMessage size mean: ... min: ... max: ...' (B below 1000 B/s); test_cli.py's test_bw reads
    the same lines (test_topic_bw). A String of 'hello world' is 20 bytes serialized."""
    printed, code, errors = first_report(talker, ["bw", "/words"], 3)
    assert printed[0] == "Subscribed to [/words]", errors
    assert re.fullmatch(r"\d+ B/s from \d+ messages", printed[1]), printed
    assert printed[2] == "\tMessage size mean: 20 B min: 20 B max: 20 B"
    assert code == 2, errors


def test_delay(talker):
    """delay.py: 'average delay: S' then '\\tmin: Ss max: Ss std dev: Ss window: N'; a message
    without a header ends with (test_topic_delay reads the two lines) 'msg does not have header' (exit code 1)."""
    printed, code, errors = first_report(talker, ["delay", "/stamped"], 2)
    assert re.fullmatch(r"average delay: -?\d+\.\d{3}", printed[0]), (printed, errors)
    assert re.fullmatch(r"\tmin: -?\d+\.\d{3}s max: -?\d+\.\d{3}s std dev: \d+\.\d{5}s window: \d+", printed[1])
    assert code == 2, errors
    no_header = subprocess.run([str(ROS2), "topic", "delay", "/words"], env=talker.env, capture_output=True,
                               text=True, timeout=120, stdin=subprocess.DEVNULL)
    assert (no_header.returncode, no_header.stderr) == (1, "msg does not have header\n")
