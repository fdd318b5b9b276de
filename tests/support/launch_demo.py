"""A ROS package in a temporary prefix, for launch tests and benchmarks: no colcon build needed.

make_prefix() lays out what ``colcon build`` would install (the ament index marker,
lib/<package>/ executables, share/<package>/ files), which is all ``ros2 run``, ``ros2 launch``
and ``$(find-pkg-share)`` look at; put the prefix on AMENT_PREFIX_PATH to use it.
"""

from __future__ import annotations

import sys
import textwrap
from pathlib import Path

import pytest
import yaml

#: An rclpy node (a module with main(), as setup.py's entry points want) named after its
#: executable: it publishes "Hello World: N" on chatter at 10 Hz, listens on heard, declares
#: whatever parameters it is given, prints COURSE_GREETING from its environment to stdout and
#: logs "started" (to stderr, like every ROS log line).
CHATTER_SOURCE = """import os
import sys

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import String


class Chatter(Node):
    def __init__(self):
        super().__init__(os.path.basename(sys.argv[0]), automatically_declare_parameters_from_overrides=True)
        self.count = 0
        self.publisher = self.create_publisher(String, 'chatter', 10)
        self.subscription = self.create_subscription(String, 'heard', lambda msg: None, 10)
        self.timer = self.create_timer(0.1, self.talk)
        print(f"COURSE_GREETING={os.environ.get('COURSE_GREETING')}", flush=True)
        self.get_logger().info('started')

    def talk(self):
        self.count += 1
        self.publisher.publish(String(data=f'Hello World: {self.count}'))


def main(args=None):
    rclpy.init(args=args)
    node = None
    try:
        node = Chatter()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
"""

#: The same node as an executable script of this interpreter (what lib/<package>/ holds).
CHATTER_NODE = f"#!{sys.executable}\n{CHATTER_SOURCE}"


def make_prefix(prefix: Path, package: str, executables: dict[str, str], share: dict[str, str]) -> Path:
    """Install `package` into `prefix`: executables {name: script text} in lib/<package>/ and
    files {relative path: text} in share/<package>/. Returns the prefix."""
    index = prefix / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True, exist_ok=True)
    (index / package).write_text("")
    for relative, text in share.items():
        path = prefix / "share" / package / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    lib = prefix / "lib" / package
    lib.mkdir(parents=True, exist_ok=True)
    for name, text in executables.items():
        (lib / name).write_text(text)
        (lib / name).chmod(0o755)
    return prefix


#: Runs a test once with each launch file format.
BOTH = pytest.mark.parametrize("form", ["xml", "yaml"])


def write(folder: Path, form: str, xml: str, yaml_text: str, name: str = "test") -> Path:
    """Write the XML or the YAML form of a launch file and return its path."""
    path = folder / (f"{name}.launch.xml" if form == "xml" else f"{name}.launch.yaml")
    path.write_text(textwrap.dedent(xml if form == "xml" else yaml_text).strip() + "\n")
    return path


def params_of(command: list[str]) -> list[dict]:
    """The parameter files a command line passes, read back."""
    return [yaml.safe_load(Path(command[i + 1]).read_text())
            for i, part in enumerate(command) if part == "--params-file"]
