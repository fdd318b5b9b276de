"""``ros2 run pillar pillar_node --ros-args --params-file config/pillar.yaml``: drive to the pillar.

For every scan on the topic of the parameter ``scan_topic`` the node finds the pillar (the nearest
finite return, :func:`find_pillar`), publishes a sphere marker at the pillar's centre in the odom
frame on ``pillar_marker``, and answers the scan with one ``/cmd_vel``: the P-controller of
:func:`p_controller`, with the gains, speed limits and stop distance of its parameters.
"""

import math

import numpy as np
import rclpy
from geometry_msgs.msg import Twist
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.time import Time
from sensor_msgs.msg import LaserScan
from visualization_msgs.msg import Marker

from course_lib.robot.tf_buffer import Buffer, TransformException, TransformListener
from course_lib.ros import sigterm

#: The pillar's radius (m): the laser sees its surface, the marker goes to its centre.
PILLAR_RADIUS = 0.2
#: The parameters the node reads from its parameter file (config/pillar.yaml), and their types.
PARAMETERS = {'scan_topic': Parameter.Type.STRING, 'queue_size': Parameter.Type.INTEGER,
              'linear_gain': Parameter.Type.DOUBLE, 'angular_gain': Parameter.Type.DOUBLE,
              'max_linear_speed': Parameter.Type.DOUBLE, 'max_angular_speed': Parameter.Type.DOUBLE,
              'stop_distance': Parameter.Type.DOUBLE}
#: The parameters of the P-controller (p_controller's arguments after distance and angle).
GAINS = ('linear_gain', 'angular_gain', 'max_linear_speed', 'max_angular_speed', 'stop_distance')


def find_pillar(ranges, angle_min, angle_increment):
    """The nearest return of a scan: (distance, angle) of its smallest finite range, as floats.

    Args:
        ranges: the scan's ranges (m), beam i at angle_min + i * angle_increment; +inf, -inf
            (REP 117: nothing within range, too close) and NaN (no reading) are not returns.
        angle_min, angle_increment: the scan's angles (rad, counter-clockwise from straight ahead).

    Returns:
        (distance, angle) in m and rad, or None when no range is finite.
    """
    ### BEGIN SOLUTION
    values = np.asarray(ranges, dtype=np.float64)
    returns = np.flatnonzero(np.isfinite(values))
    if returns.size == 0:
        return None
    beam = int(returns[np.argmin(values[returns])])
    return float(values[beam]), float(angle_min + beam * angle_increment)
    ### END SOLUTION


def p_controller(distance, angle, linear_gain, angular_gain, max_linear_speed, max_angular_speed,
                 stop_distance):
    """The P-controller's command (linear m/s, angular rad/s) for the pillar at (distance, angle).

    Forward at linear_gain times the distance beyond stop_distance (never backwards), turning at
    angular_gain times the angle, each clamped to its maximum.
    """
    ### BEGIN SOLUTION
    linear = linear_gain * max(distance - stop_distance, 0.0)
    angular = angular_gain * angle
    return (float(min(linear, max_linear_speed)),
            float(min(max(angular, -max_angular_speed), max_angular_speed)))
    ### END SOLUTION


def pillar_in_odom(distance, angle, laser_x, laser_y, laser_yaw):
    """The pillar's centre (x, y) in the odom frame, seen at (distance, angle) by a laser at
    (laser_x, laser_y) turned by laser_yaw in odom."""
    ### BEGIN SOLUTION
    reach = distance + PILLAR_RADIUS
    heading = laser_yaw + angle
    return laser_x + reach * math.cos(heading), laser_y + reach * math.sin(heading)
    ### END SOLUTION


class PillarNode(Node):
    """The node ``pillar_node``: scan in, marker and /cmd_vel out."""

    def __init__(self):
        super().__init__('pillar_node')
        ### BEGIN SOLUTION
        # Declared without defaults: a parameter missing from the file is an error that names it.
        for name, kind in PARAMETERS.items():
            self.declare_parameter(name, kind)
        self.settings = {name: self.get_parameter(name).value for name in PARAMETERS}
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.cmd_pub = self.create_publisher(Twist, '/cmd_vel', 10)
        self.marker_pub = self.create_publisher(Marker, 'pillar_marker', 10)
        self.scan_sub = self.create_subscription(LaserScan, self.settings['scan_topic'], self.on_scan,
                                                 self.settings['queue_size'])
        ### END SOLUTION

    def on_scan(self, scan):
        """Answer the scan with one /cmd_vel (zero when no pillar is seen) and mark the pillar."""
        ### BEGIN SOLUTION
        found = find_pillar(scan.ranges, scan.angle_min, scan.angle_increment)
        twist = Twist()
        if found is not None:
            distance, angle = found
            gains = {name: self.settings[name] for name in GAINS}
            twist.linear.x, twist.angular.z = p_controller(distance, angle, **gains)
            self.publish_marker(scan.header, distance, angle)
        self.cmd_pub.publish(twist)
        ### END SOLUTION

    def publish_marker(self, header, distance, angle):
        """A sphere at the pillar's centre in the odom frame (nothing while TF is not known yet)."""
        ### BEGIN SOLUTION
        try:  # where the laser was when it scanned, else the newest (its /tf may come later)
            laser = self.tf_buffer.lookup_transform('odom', header.frame_id, Time.from_msg(header.stamp))
        except TransformException:
            try:
                laser = self.tf_buffer.lookup_transform('odom', header.frame_id, Time())
            except TransformException as error:
                self.get_logger().warning(f'No marker: {error}', throttle_duration_sec=5.0)
                return
        t, q = laser.transform.translation, laser.transform.rotation
        yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
        x, y = pillar_in_odom(distance, angle, t.x, t.y, yaw)
        marker = Marker()
        marker.header.frame_id, marker.header.stamp = 'odom', header.stamp
        marker.ns, marker.id = 'pillar', 0
        marker.type, marker.action = Marker.CYLINDER, Marker.ADD
        marker.pose.position.x, marker.pose.position.y, marker.pose.position.z = x, y, 0.5
        marker.pose.orientation.w = 1.0
        marker.scale.x = marker.scale.y = 2 * PILLAR_RADIUS
        marker.scale.z = 1.0
        marker.color.r, marker.color.g, marker.color.a = 1.0, 0.5, 0.8
        self.marker_pub.publish(marker)
        ### END SOLUTION


def main(args=None):
    sigterm.end_spin_as_ctrl_c()  # `kill` ends the node as Ctrl-C does (see course_lib.ros.sigterm)
    rclpy.init(args=args)
    node = None
    try:
        node = PillarNode()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
