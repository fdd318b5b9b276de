"""course_lib.robot.simulator_node: the simulated robot over real DDS, in lock-step with a controller.

Every test runs the simulator and a controller node in one executor of their own context and ROS
domain; in lock-step the simulation waits for each scan's answer, so what happens is counted in
simulated seconds, and the wall clock only bounds a run that stops (60 s).
"""

import math
import threading
import time

import numpy as np
import pytest
import rclpy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import Log
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, qos_profile_sensor_data
from sensor_msgs.msg import LaserScan
from std_srvs.srv import Trigger
from tf2_msgs.msg import TFMessage

from course_lib.robot import husky
from course_lib.robot.simulator_node import RobotSimulator, pace_delay

BACKSTOP = 60.0


class PillarController(Node):
    """The lecture's P-controller: turn towards the nearest return, drive until 0.6 m from it."""

    def __init__(self, linear_gain=0.5, angular_gain=1.5, stop_at=0.6, reply_delay=0.0, **node_options):
        super().__init__("pillar_controller", **node_options)
        self.gains, self.stop_at, self.reply_delay = (linear_gain, angular_gain), stop_at, reply_delay
        self.cmd = self.create_publisher(Twist, "cmd_vel", 10)
        self.create_subscription(LaserScan, "scan", self.on_scan, qos_profile_sensor_data)

    def on_scan(self, scan: LaserScan) -> None:
        ranges = np.array(scan.ranges, dtype=float)
        ranges[~np.isfinite(ranges)] = np.inf
        nearest = int(np.argmin(ranges))
        distance, angle = float(ranges[nearest]), scan.angle_min + nearest * scan.angle_increment
        twist = Twist()
        if math.isfinite(distance):
            twist.linear.x = self.gains[0] * max(distance - self.stop_at, 0.0)
            twist.angular.z = self.gains[1] * angle
        time.sleep(self.reply_delay)  # a controller on a busy machine
        self.cmd.publish(twist)


class Replier(Node):
    """Answers every scan with one fixed Twist (which a test may change) and keeps what it hears."""

    def __init__(self, **node_options):
        super().__init__("replier", **node_options)
        self.reply = Twist()
        self.odom, self.logs, self.tf_static = [], [], []
        self.cmd = self.create_publisher(Twist, "cmd_vel", 10)
        self.create_subscription(LaserScan, "scan", lambda scan: self.cmd.publish(self.reply), 10)
        self.create_subscription(Odometry, "odom", self.odom.append, 10)
        self.create_subscription(Log, "/rosout", self.logs.append, 100)
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.create_subscription(TFMessage, "/tf_static", self.tf_static.append, latched)


class Run:
    """A simulator in lock-step and other nodes, spun in one executor of a context of their own."""

    def __init__(self, domain_id, **parameters):
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=domain_id)
        overrides = [Parameter(name, value=value) for name, value in
                     {"lock_step": True, "reply_timeout": BACKSTOP, **parameters}.items()]
        self.sim_node = RobotSimulator(context=self.context, parameter_overrides=overrides)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.sim_node)
        self.nodes = [self.sim_node]

    def add(self, node_class, **options):
        node = node_class(context=self.context, **options)
        self.executor.add_node(node)
        self.nodes.append(node)
        return node

    def until(self, condition, what: str) -> None:
        deadline = time.monotonic() + BACKSTOP
        while not condition():
            assert time.monotonic() < deadline, f"{what}: not within {BACKSTOP:g} s"
            self.executor.spin_once(timeout_sec=0.1)

    def close(self):
        if self.nodes:
            self.executor.shutdown()
            for node in self.nodes:
                node.destroy_node()
            self.nodes = []
            rclpy.try_shutdown(context=self.context)


@pytest.fixture
def run(domain_id):
    runs = []

    def start(**parameters):
        runs.append(Run(domain_id, **parameters))
        return runs[-1]
    yield start
    for each in runs:
        each.close()


def drive_to_pillar(run, seed, seconds=20.0, reply_delay=0.0, **parameters):
    """The simulation after `seconds` of the P-controller, which runs in a thread of its own."""
    sim_run = run(world="pillar", seed=seed, **parameters)
    controller = PillarController(context=sim_run.context, reply_delay=reply_delay)
    executor = SingleThreadedExecutor(context=sim_run.context)
    executor.add_node(controller)
    thread = threading.Thread(target=executor.spin, daemon=True)
    thread.start()
    sim = sim_run.sim_node.sim
    try:
        sim_run.until(lambda: sim.time >= seconds, f"{seconds:g} simulated seconds")
    finally:
        executor.shutdown()
        thread.join(BACKSTOP)
        controller.destroy_node()
        sim_run.close()
    return sim


def test_a_p_controller_reaches_the_pillar_and_does_the_same_twice(run):
    first = drive_to_pillar(run, seed=4)
    px, py = first.pillar
    x, y, _ = first.pose()
    gap = math.hypot(px - x, py - y) - first.pillar_radius
    # stopped with the laser 0.6 m from the pillar: base_link 0.95 m from it, the front 0.45 m
    assert gap == pytest.approx(0.6 + husky.LASER_OFFSET[0], abs=0.1)
    assert abs(first.velocity()[0]) < 0.02 and not first.touching()
    second = drive_to_pillar(run, seed=4)
    assert second.pose() == first.pose(), "lock-step: the same seed and controller drive the same way"


def test_a_slow_controller_drives_exactly_as_a_fast_one(run):
    """In lock-step the simulation waits for each answer: 20 ms more per answer changes nothing."""
    fast = drive_to_pillar(run, seed=2, seconds=3.0)
    slow = drive_to_pillar(run, seed=2, seconds=3.0, reply_delay=0.02)
    assert slow.pose() == fast.pose()


def test_it_publishes_scan_odom_tf_and_the_laser_mount(run):
    sim_run = run(world="walls")
    heard = sim_run.add(Replier)
    scans, tfs = [], []
    listener = sim_run.add(Node, node_name="listener")
    listener.create_subscription(LaserScan, "scan", scans.append, 10)
    listener.create_subscription(TFMessage, "/tf", tfs.append, 10)
    sim_run.until(lambda: len(scans) >= 5 and heard.odom and tfs and heard.tf_static, "scans, odom and TF")
    scan = scans[-1]
    assert scan.header.frame_id == husky.LASER_FRAME and len(scan.ranges) == 541
    assert scan.angle_min == pytest.approx(-3 * math.pi / 4) and scan.range_max == pytest.approx(20.0)
    assert scan.ranges[270] == pytest.approx(5.0 - husky.LASER_OFFSET[0], abs=0.05)  # straight ahead
    stamps = [s.header.stamp.sec + s.header.stamp.nanosec * 1e-9 for s in scans]
    assert np.allclose(np.diff(stamps), 0.05), stamps  # a scan every 1/20 simulated s
    (mount,) = heard.tf_static[-1].transforms
    assert (mount.header.frame_id, mount.child_frame_id) == (husky.BASE_FRAME, husky.LASER_FRAME)
    assert mount.transform.translation.x == pytest.approx(husky.LASER_OFFSET[0])
    (moved,) = tfs[-1].transforms
    assert (moved.header.frame_id, moved.child_frame_id) == (husky.ODOM_FRAME, husky.BASE_FRAME)
    assert (heard.odom[-1].header.frame_id, heard.odom[-1].child_frame_id) == ("odom", "base_link")


def test_commands_are_clamped_to_the_robots_limits(run):
    sim_run = run(world="pillar")
    heard = sim_run.add(Replier)
    heard.reply.linear.x, heard.reply.angular.z = 5.0, 0.0
    sim = sim_run.sim_node.sim
    sim_run.until(lambda: sim.time >= 3.0, "3 simulated seconds")
    assert sim.commanded == (husky.MAX_LINEAR, 0.0)
    assert heard.odom[-1].twist.twist.linear.x == pytest.approx(husky.MAX_LINEAR, abs=0.05)


def test_a_nan_command_is_refused_with_an_error_and_the_robot_stops(run):
    sim_run = run(world="pillar")
    heard = sim_run.add(Replier)
    heard.reply.linear.x = 0.8
    sim = sim_run.sim_node.sim
    sim_run.until(lambda: sim.time >= 2.0, "2 simulated seconds")
    heard.reply.linear.x = math.nan
    sim_run.until(lambda: sim.time >= 4.0, "4 simulated seconds")
    assert sim.commanded == (0.0, 0.0)
    assert abs(sim.velocity()[0]) < 0.01
    errors = [log.msg for log in heard.logs if log.level == Log.ERROR]
    assert errors and "Refused /cmd_vel" in errors[0] and "not finite" in errors[0]


def test_reset_puts_the_robot_back_and_the_clock_goes_on(run):
    sim_run = run(world="pillar")
    heard = sim_run.add(Replier)
    heard.reply.linear.x = 0.5
    sim_node = sim_run.sim_node
    sim_run.until(lambda: sim_node.sim.time >= 2.0, "2 simulated seconds")
    client = heard.create_client(Trigger, "/robot_simulator/reset")
    future = client.call_async(Trigger.Request())
    sim_run.until(future.done, "the reset's answer")
    assert future.result().success and "pillar at" in future.result().message
    before = len(heard.odom)
    sim_run.until(lambda: len(heard.odom) > before + 2, "odometry after the reset")
    after = heard.odom[-1]
    assert after.pose.pose.position.x < 0.2
    assert after.header.stamp.sec >= 2, "the clock does not go back"


def test_pace_delay_holds_the_simulation_at_most_factor_times_the_wall_clock():
    assert pace_delay(simulated=1.0, wall=0.2, factor=2.0) == pytest.approx(0.3)  # 1 s at x2 is due at 0.5 s
    assert pace_delay(simulated=1.0, wall=0.7, factor=2.0) == 0.0  # behind the wall clock: no wait
    assert pace_delay(simulated=1.0, wall=0.1, factor=0.5) == pytest.approx(1.9)  # slower than real time
    assert pace_delay(simulated=100.0, wall=0.0, factor=0.0) == 0.0  # 0: no cap


def test_max_real_time_factor_caps_the_lock_step_pace_in_simulated_terms(run):
    """At most N simulated seconds per wall second: a one-sided bound, which a busy machine (slower,
    never faster) cannot break. Half real time: without the cap a lock-step run here goes 30 times
    real time or more, and even a machine 50 times slower is ahead of the cap, which then waits."""
    factor = 0.5
    sim_run = run(world="walls", max_real_time_factor=factor)
    sim_run.add(Replier)
    scans = []  # (wall, simulated) per scan as it arrives
    listener = sim_run.add(Node, node_name="listener")
    listener.create_subscription(LaserScan, "scan", lambda scan: scans.append(
        (time.monotonic(), scan.header.stamp.sec + scan.header.stamp.nanosec * 1e-9)), 100)
    sim_run.until(lambda: len(scans) >= 2 and scans[-1][1] - scans[0][1] >= 0.5, "0.5 simulated seconds")
    (wall0, sim0), (wall1, sim1) = scans[0], scans[-1]
    assert (sim1 - sim0) / (wall1 - wall0) <= factor * 1.05, f"{sim1 - sim0:.2f} simulated s in {wall1 - wall0:.3f} s"
    assert 0 < sim_run.sim_node.held_back <= time.monotonic() - wall0 + 0.1


def test_the_cap_changes_the_pace_not_the_drive(run):
    capped = drive_to_pillar(run, seed=2, seconds=3.0, max_real_time_factor=10.0)
    free = drive_to_pillar(run, seed=2, seconds=3.0)
    assert capped.pose() == free.pose()


def test_without_a_cap_nothing_is_held_back(run):
    sim_run = run(world="walls")
    sim_run.add(Replier)
    sim_run.until(lambda: sim_run.sim_node.sim.time >= 1.0, "1 simulated second")
    assert sim_run.sim_node.held_back == 0.0
