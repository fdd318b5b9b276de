"""The tutorial workspace, built once per test run with the real colcon and shared by the xdist
workers of the run (an interface build costs 40-60 s of processor time; the first worker that needs
the workspace builds it under a file lock, the others wait for it):

- tutorial_interfaces: lesson 01b's MsgTutorial and, beside it, the .msg, .srv and .action files
  of ros2interface's test_cli.py (Jazzy; its package ros2cli_test_interfaces, written anew from
  the lines that test expects), so that one rosidl build serves tests/course_lib/ros/test_workspace.py and
  tests/course_lib/ros2cli/test_ros2cli_interface_builds.py;
- tutorial_nodes: an ament_python package that uses MsgTutorial (hello_node, topic_publisher,
  topic_subscriber). Its two nodes are this workspace's own, not a copy of lesson 01b's or of the
  pubsub assignment's solution (assignments/reference_ws/src/pubsub): the publisher takes a `start`
  parameter and both use the topic `topic`, which tests/course_lib/ros/test_workspace.py remaps.

A test that builds in this workspace again holds `rebuilding()`; `built()` returns the
workspace and its sourced environment under the same lock, so no test reads it mid-build.
"""

from __future__ import annotations

import contextlib
import shutil
from pathlib import Path

from course_lib.ros import colcon, pkg_create, workspace

from . import course as course_support
from .from_source import REFERENCE_SOURCE

# Comments say at which nesting level they are, as in ros2cli_test_interfaces.
TEST_CLI_INTERFACES = {
    "ShortVaried": ("# A constant\n"
                    "bool BOOL_CONST=true # Comment - Nesting Level 1: 1 of 2\n\n"
                    "# Bool and array of bools\n"
                    "bool bool_value\n"
                    "bool[<=3] bool_values # Comment - Nesting Level 1: 2 of 2\n\n"
                    "# Trailing comment\n"),
    "ShortVariedNested": ("# A short, varied type\n"
                          "ShortVaried short_varied # Comment - Nesting Level 2: 1 of 1\n"
                          "# Trailing comment\n"),
    "ShortVariedMultiNested.srv": ("# Request\n"
                                   "ShortVariedNested short_varied_nested # Comment - Nesting Level 3: 1 of 2\n"
                                   "---\n"
                                   "# Response\n"
                                   "bool bool_value # Comment - Nesting Level 3: 2 of 2\n"),
    "ShortVariedMultiNested.action": ("# Goal definition\n"
                                      "ShortVariedNested short_varied_nested # Comment - Nesting Level 3: 1 of 2\n"
                                      "---\n"
                                      "# Result definition\n"
                                      "bool bool_value # Comment - Nesting Level 3: 2 of 2\n"
                                      "---\n"
                                      "# Feedback definition\n"
                                      "bool[3] bool_values\n"),
}

#: Lesson 01b's message, as the reference package tutorial_interfaces defines it.
MSG_TUTORIAL = (REFERENCE_SOURCE / "tutorial_interfaces" / "msg" / "MsgTutorial.msg").read_text()

PUBLISHER = '''import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

from tutorial_interfaces.msg import MsgTutorial


class TopicPublisher(Node):
    """Publish MsgTutorial at 10 Hz with a growing counter."""

    def __init__(self):
        super().__init__('topic_publisher')
        self.count = self.declare_parameter('start', 0).value
        self.publisher = self.create_publisher(MsgTutorial, 'topic', 100)
        self.timer = self.create_timer(0.1, self.publish)

    def publish(self):
        msg = MsgTutorial()
        msg.stamp = self.get_clock().now().to_msg()
        msg.data = self.count
        self.publisher.publish(msg)
        self.count += 1


def main(args=None):
    rclpy.init(args=args)
    node = None
    try:
        node = TopicPublisher()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
'''

SUBSCRIBER = '''import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

from tutorial_interfaces.msg import MsgTutorial


class TopicSubscriber(Node):
    """Log every field of each MsgTutorial received."""

    def __init__(self):
        super().__init__('topic_subscriber')
        self.subscription = self.create_subscription(MsgTutorial, 'topic', self.listen, 100)

    def listen(self, msg):
        self.get_logger().info(
            f'Received: stamp={msg.stamp.sec}.{msg.stamp.nanosec:09d} data={msg.data}')


def main(args=None):
    rclpy.init(args=args)
    node = None
    try:
        node = TopicSubscriber()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
'''


def make_tutorial_workspace(ws: Path) -> None:
    pkg_create.create_interface_package(ws, "tutorial_interfaces",
                                        {"MsgTutorial": MSG_TUTORIAL, **TEST_CLI_INTERFACES})
    package = pkg_create.create_package(ws, "tutorial_nodes", dependencies=["rclpy", "tutorial_interfaces"],
                                       node_name=["hello_node", "topic_publisher", "topic_subscriber"])
    (package / "tutorial_nodes" / "topic_publisher.py").write_text(PUBLISHER)
    (package / "tutorial_nodes" / "topic_subscriber.py").write_text(SUBSCRIBER)


def _folder(tmp_path_factory) -> Path:
    return course_support.shared_folder(tmp_path_factory) / "tutorial_ws"


@contextlib.contextmanager
def rebuilding(tmp_path_factory):
    """Hold the workspace's lock while a test builds in it again."""
    with course_support.locked(_folder(tmp_path_factory).with_suffix(".lock")):
        yield


def built(tmp_path_factory) -> tuple[Path, dict[str, str]]:
    """(the tutorial workspace, the environment of its sourced install/setup.bash), built with the
    real colcon by the first caller of this test run."""
    ws = _folder(tmp_path_factory)
    with rebuilding(tmp_path_factory):
        if not (ws / ".complete").is_file():
            shutil.rmtree(ws, ignore_errors=True)
            make_tutorial_workspace(ws)
            result = colcon.build(ws, timeout=600)
            print(f"\ncolcon built {result.finished} in {result.seconds:.1f} s")
            (ws / ".complete").touch()
        return ws, workspace.workspace_environment(ws)
