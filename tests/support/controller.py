"""A lock-step controller process for the tests of course_lib.checks.lock_step: the lecture's
P-controller (turn towards the nearest return, drive until 0.6 m from it), answering every scan
with one /cmd_vel, except as its arguments say:

    python -m controller_support [--sleep-at N --sleep S] [--loop-at N] [--silent-from N]

--sleep-at N --sleep S: sleep S wall seconds before answering scan N (counted from 1);
--loop-at N: compute endlessly on scan N; --silent-from N: answer no scan from scan N on.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
import rclpy
from geometry_msgs.msg import Twist
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from sensor_msgs.msg import LaserScan


class Controller(Node):
    def __init__(self, options: argparse.Namespace):
        super().__init__("lock_step_controller")
        self.options, self.scans = options, 0
        self.cmd = self.create_publisher(Twist, "cmd_vel", 10)
        self.create_subscription(LaserScan, "scan", self.on_scan, 10)

    def on_scan(self, scan: LaserScan) -> None:
        self.scans += 1
        if self.scans == self.options.loop_at:
            while True:
                pass
        if self.options.silent_from and self.scans >= self.options.silent_from:
            return
        if self.scans == self.options.sleep_at:
            time.sleep(self.options.sleep)
        ranges = np.array(scan.ranges, dtype=float)
        ranges[~np.isfinite(ranges)] = np.inf
        nearest = int(np.argmin(ranges))
        distance, angle = float(ranges[nearest]), scan.angle_min + nearest * scan.angle_increment
        twist = Twist()
        if math.isfinite(distance):
            twist.linear.x = 0.5 * max(distance - 0.6, 0.0)
            twist.angular.z = 1.5 * angle
        self.cmd.publish(twist)


def main(args=None):
    parser = argparse.ArgumentParser()
    for flag in ("--sleep-at", "--loop-at", "--silent-from"):
        parser.add_argument(flag, type=int, default=0)
    parser.add_argument("--sleep", type=float, default=0.0)
    rclpy.init(args=args)
    node = None
    try:
        node = Controller(parser.parse_args(rclpy.utilities.remove_ros_args()[1:]))
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
