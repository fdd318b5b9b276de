"""course_lib.robot.tf_buffer: tf2's lookups, their interpolation and their exceptions, and a listener
filled by the simulated robot over real DDS."""

import math
import time

import pytest
import rclpy
from geometry_msgs.msg import TransformStamped, Twist
from rclpy.duration import Duration
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.time import Time
from sensor_msgs.msg import LaserScan

from course_lib.robot import husky
from course_lib.robot.simulator_node import RobotSimulator
from course_lib.robot.tf_buffer import (
    Buffer,
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TransformException,
    TransformListener,
)


def transform(parent, child, x=0.0, y=0.0, yaw=0.0, seconds=0.0):
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = parent, child
    t.header.stamp = Time(nanoseconds=round(seconds * 1e9)).to_msg()
    t.transform.translation.x, t.transform.translation.y = x, y
    t.transform.rotation.z, t.transform.rotation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return t


def xy_yaw(t: TransformStamped):
    r = t.transform.rotation
    return (t.transform.translation.x, t.transform.translation.y,
            math.atan2(2 * (r.w * r.z + r.x * r.y), 1 - 2 * (r.y * r.y + r.z * r.z)))


@pytest.fixture
def robot_tree():
    """odom -> base_link moving (at 1 s and 2 s), base_link -> laser static."""
    buffer = Buffer()
    buffer.set_transform(transform("odom", "base_link", x=1.0, seconds=1.0), "test")
    buffer.set_transform(transform("odom", "base_link", x=2.0, yaw=math.pi / 2, seconds=2.0), "test")
    buffer.set_transform_static(transform("base_link", "laser", x=0.35), "test")
    return buffer


def test_a_lookup_chains_the_transforms_and_maps_source_to_target(robot_tree):
    found = robot_tree.lookup_transform("odom", "laser", Time(seconds=2))
    assert (found.header.frame_id, found.child_frame_id) == ("odom", "laser")
    # the laser 0.35 m ahead of base_link, which faces +y at (2, 0)
    assert xy_yaw(found) == pytest.approx((2.0, 0.35, math.pi / 2))


def test_the_other_way_round_is_the_inverse(robot_tree):
    found = robot_tree.lookup_transform("laser", "odom", Time(seconds=2))
    # odom's origin seen from the laser at (2, 0.35) facing +y: 0.35 behind it... turned
    assert xy_yaw(found) == pytest.approx((-0.35, 2.0, -math.pi / 2))


def test_between_two_stamps_the_transform_is_interpolated(robot_tree):
    x, y, yaw = xy_yaw(robot_tree.lookup_transform("odom", "base_link", Time(seconds=1.5)))
    assert (x, y, yaw) == pytest.approx((1.5, 0.0, math.pi / 4))


def test_time_zero_is_the_newest_common_time_and_static_transforms_hold_at_any_time(robot_tree):
    found = robot_tree.lookup_transform("odom", "laser", Time())
    assert Time.from_msg(found.header.stamp).nanoseconds == Time(seconds=2).nanoseconds
    assert robot_tree.lookup_transform("base_link", "laser", Time(seconds=100)).transform.translation.x == 0.35


def test_outside_the_stamps_is_extrapolation_into_the_future_or_the_past(robot_tree):
    with pytest.raises(ExtrapolationException, match=r"extrapolation into the future.  Requested time 3\.0+ but "
                                                     r"the latest data is at time 2\.0+"):
        robot_tree.lookup_transform("odom", "laser", Time(seconds=3))
    past = r"extrapolation into the past.*from frame \[laser\] to frame \[odom\]"
    with pytest.raises(ExtrapolationException, match=past):
        robot_tree.lookup_transform("odom", "laser", Time(seconds=0.5))


def test_an_unknown_frame_is_a_lookup_error_and_two_trees_a_connectivity_error(robot_tree):
    with pytest.raises(LookupException, match='"map" passed to lookupTransform argument target_frame does not exist'):
        robot_tree.lookup_transform("map", "laser", Time())
    robot_tree.set_transform_static(transform("world", "pillar", x=5.0), "test")
    with pytest.raises(ConnectivityException, match="Could not find a connection between 'odom' and 'pillar'"):
        robot_tree.lookup_transform("odom", "pillar", Time())
    with pytest.raises(InvalidArgumentException):
        robot_tree.lookup_transform("", "laser", Time())
    assert issubclass(LookupException, TransformException)
    assert not robot_tree.can_transform("odom", "pillar", Time())


def test_a_leading_slash_names_the_same_frame(robot_tree):
    assert robot_tree.lookup_transform("/odom", "laser", Time()).transform.translation.y == pytest.approx(0.35)


def test_the_listener_follows_the_simulated_robot(domain_id):
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain_id)
    try:
        overrides = [Parameter("lock_step", value=True), Parameter("world", value="walls")]
        sim_node = RobotSimulator(context=context, parameter_overrides=overrides)
        driver = Node("driver", context=context)
        buffer = Buffer()
        TransformListener(buffer, driver)
        cmd = driver.create_publisher(Twist, "cmd_vel", 10)
        turn = Twist()
        turn.angular.z = 0.5
        driver.create_subscription(LaserScan, "scan", lambda scan: cmd.publish(turn), 10)
        executor = SingleThreadedExecutor(context=context)
        for node in (sim_node, driver):
            executor.add_node(node)


        def newest_heard():
            if not buffer.can_transform("odom", "laser", Time()):
                return -1.0
            return Time.from_msg(buffer.lookup_transform("odom", "laser", Time()).header.stamp).nanoseconds / 1e9

        # until the listener holds the transform of the simulation's present, 2 simulated s or more on
        deadline = time.monotonic() + 60.0
        while not (sim_node.sim.time >= 2.0 and newest_heard() == pytest.approx(sim_node.now)):
            assert time.monotonic() < deadline, "2 simulated seconds within 60 s"
            executor.spin_once(timeout_sec=0.1)
        found = buffer.lookup_transform("odom", "laser", Time(), timeout=Duration(seconds=0))
        x, y, yaw = sim_node.sim.pose()
        laser_x = husky.LASER_OFFSET[0]
        assert xy_yaw(found) == pytest.approx((x + laser_x * math.cos(yaw), y + laser_x * math.sin(yaw), yaw), abs=1e-6)
        assert found.transform.translation.z == pytest.approx(husky.LASER_OFFSET[2])
        executor.shutdown()
        sim_node.destroy_node()
        driver.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)
