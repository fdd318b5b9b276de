"""The robot simulator as a ROS 2 node: ``/cmd_vel`` in; ``/scan``, ``/odom``, ``/tf``,
``/tf_static`` and ``/clock`` out; a ``~/reset`` service.

    ros2 run robot_sim simulator --ros-args -p world:=pillar -p seed:=3
    python -m course_lib.robot.simulator_node --ros-args -p lock_step:=true

Its parameters, their defaults and what they set: PARAMETERS (``ros2 param describe``).

Each tick (``1/scan_rate`` simulated seconds) the node publishes the simulated time on /clock,
odom -> base_link on /tf, the odometry on /odom and then the scan on /scan, all stamped with the
simulated time (it never goes back: a reset restarts the robot, not the clock). A /cmd_vel holds
until the next one: clamped to the robot's limits, or, when a value is NaN or infinite, refused
with an error in the log and the robot stopped.

Two ways to run (parameter ``lock_step``):

- real time (default): a tick every ``1/scan_rate`` s of wall time, ``real_time_factor`` times
  faster if it is not 1; how a robot behaves, and what a student watches.
- lock-step: the simulation waits, after each scan, for the /cmd_vel that answers it, and then
  advances one tick; it starts once /scan has a subscriber and /cmd_vel a publisher, and pauses
  while either is missing. A controller that answers each scan with one /cmd_vel (and runs on
  simulated time, ``use_sim_time``) then sees the same scans, and drives the same way, however
  busy the machine: as fast as the slowest of the two keeps up. What happens to a scan that waits
  for its answer is up to ``on_unanswered``: here a scan nobody answers within ``reply_timeout``
  wall seconds is passed over with a warning and counted (``passed_over``; a backstop, not a
  pace: a wall-clock timeout depends on the machine's load). The checks judge by the controller's
  processor time instead and never pass a scan over (course_lib.checks.lock_step): when the
  controller is to blame they ``halt`` the simulation for good, with the reason.
  ``max_real_time_factor`` caps the pace: with N > 0 the simulated time runs at most N times as
  fast as the wall clock (1: never faster than real time, to watch a drive), the next tick
  waiting, after its answer, for the wall time :func:`pace_delay` computes; 0 (the default): as
  fast as the slowest keeps up. ``held_back`` adds up the wall seconds the cap waited.
"""

from __future__ import annotations

import array
import math
import time

import rclpy
from geometry_msgs.msg import TransformStamped, Twist
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.clock import Clock, ClockType
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile
from rosgraph_msgs.msg import Clock as ClockMessage
from sensor_msgs.msg import LaserScan
from std_srvs.srv import Trigger
from tf2_msgs.msg import TFMessage

from course_lib.robot import husky
from course_lib.robot.simulation import Laser, Simulation

#: The node's parameters: default and what it sets (``ros2 param describe /robot_simulator NAME``).
PARAMETERS = {
    "world": ("pillar", "the world: pillar, walls or maze, or the path of an MJCF file that includes husky.xml"),
    "seed": (0, "places the pillar (pillar world) and draws the laser's noise"),
    "scan_rate": (20.0, "scans, and simulation ticks, per simulated second"),
    "lock_step": (False, "wait after each scan for the /cmd_vel that answers it, instead of running in real time"),
    "real_time_factor": (1.0, "real time: simulated seconds per wall second"),
    "max_real_time_factor": (0.0, "lock-step: simulated seconds per wall second at most; 0: as fast as the "
                                  "slowest keeps up"),
    "reply_timeout": (5.0, "lock-step: wall seconds after which a scan nobody answers is passed over"),
    "beams": (Laser.beams, "the laser's beams over its 270 degrees"),
    "noise": (Laser.noise, "the standard deviation of the laser's Gaussian noise (m)"),
}


def pace_delay(simulated: float, wall: float, factor: float) -> float:
    """Wall seconds to wait before showing simulated time `simulated` when `wall` wall seconds have
    passed (both counted from the same start) and the simulation may run at most `factor` times
    as fast as the wall clock; 0 when `factor` is 0 (no cap) or the simulation is behind."""
    if factor <= 0:
        return 0.0
    return max(0.0, simulated / factor - wall)


def yaw_quaternion(yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a turn by `yaw` about z."""
    return 0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)


class RobotSimulator(Node):
    """The simulated robot's node (see the module's docstring)."""

    def __init__(self, **node_options):
        super().__init__("robot_simulator", **node_options)
        values = {name: self.declare_parameter(name, default, ParameterDescriptor(description=words)).value
                  for name, (default, words) in PARAMETERS.items()}
        world, seed = values["world"], values["seed"]
        self.scan_rate, self.lock_step = values["scan_rate"], values["lock_step"]
        self.real_time_factor, self.max_real_time_factor = values["real_time_factor"], values["max_real_time_factor"]
        self.reply_timeout = values["reply_timeout"]
        self.sim = Simulation(world, seed=seed, laser=Laser(beams=values["beams"], noise=values["noise"]))
        self.clock_offset = 0.0  # simulated seconds before the last reset
        self.scans = 0  # scans published
        self.passed_over = 0  # lock-step: scans nobody answered, stepped over (on_unanswered)
        self.halted: str | None = None  # lock-step: why the simulation stopped for good (halt)
        self.held_back = 0.0  # lock-step: wall seconds max_real_time_factor held the next tick back
        self._pace_start: tuple[float, float] | None = None  # lock-step: (wall, simulated) when it (re)started
        self._pace_timer = None  # lock-step: the timer of a tick the cap holds back
        self.last_scan: LaserScan | None = None
        self._state = self._state_messages()

        self.clock_pub = self.create_publisher(ClockMessage, "/clock", 10)
        self.tf_pub = self.create_publisher(TFMessage, "/tf", 100)
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.tf_static_pub = self.create_publisher(TFMessage, "/tf_static", latched)
        self.odom_pub = self.create_publisher(Odometry, "odom", 10)
        # Reliable: a subscriber of either reliability (the default, or sensor-data QoS) gets it.
        self.scan_pub = self.create_publisher(LaserScan, "scan", 10)
        self.cmd_sub = self.create_subscription(Twist, "cmd_vel", self.on_cmd_vel, 10)
        self.reset_srv = self.create_service(Trigger, "~/reset", self.on_reset)

        self.tf_static_pub.publish(TFMessage(transforms=[self.laser_transform()]))
        # Wall-clock timers, also when a launch file sets use_sim_time for every node.
        self.steady = steady = Clock(clock_type=ClockType.STEADY_TIME)
        self.awaiting_reply_since = None  # lock-step: when the scan that waits for its answer went out
        if self.lock_step:
            self.timer = self.create_timer(min(0.1, self.reply_timeout), self.on_lock_step_timer, clock=steady)
        else:
            self.wall_start = time.monotonic()
            self.timer = self.create_timer(1.0 / (self.scan_rate * self.real_time_factor), self.on_tick, clock=steady)
        cap = f", at most x{self.max_real_time_factor:g} real time" if self.max_real_time_factor > 0 else ""
        pace = (f"lock-step{cap}: waiting for a /scan subscriber and a /cmd_vel publisher" if self.lock_step
                else f"real time x{self.real_time_factor:g}")
        self.get_logger().info(f"Robot in world '{world}' (seed {seed}){self.pillar_words()}, {pace}")

    @property
    def now(self) -> float:
        """Simulated seconds since the node started (over resets)."""
        return self.clock_offset + self.sim.time

    def pillar_words(self) -> str:
        return "" if self.sim.pillar is None else ", pillar at ({:.2f}, {:.2f})".format(*self.sim.pillar)

    # --- commands and services -------------------------------------------------------------------

    def on_cmd_vel(self, msg: Twist) -> None:
        try:
            self.sim.command(msg.linear.x, msg.angular.z)
        except ValueError as error:
            self.get_logger().error(f"Refused /cmd_vel: {error}. The robot stops.")
            self.sim.command(0.0, 0.0)
        if self.lock_step and self.awaiting_reply_since is not None and self.halted is None:
            self.advance()

    def on_reset(self, request, response):
        self.clock_offset += self.sim.time
        self.sim.reset()
        response.success = True
        response.message = f"Robot back at the start{self.pillar_words()}"
        self.get_logger().info(response.message)
        return response

    # --- time ----------------------------------------------------------------------------------

    def on_tick(self) -> None:
        """Real time: simulate up to where the wall clock (times the factor) says, then publish."""
        due = (time.monotonic() - self.wall_start) * self.real_time_factor
        behind = due - self.now
        # A process that was stopped (or starved) does not make the robot jump: at most a tick.
        self.sim.step(min(max(behind, 0.0), 1.0 / self.scan_rate))
        self.publish_state()

    def on_lock_step_timer(self) -> None:
        """Lock-step: start (or pause) with the graph; ask on_unanswered about a scan that waits."""
        if self.halted is not None or self._pace_timer is not None:
            return
        connected = self.scan_pub.get_subscription_count() > 0 and self.cmd_sub.get_publisher_count() > 0
        if self.awaiting_reply_since is None:
            if connected:
                self._pace_start = (time.monotonic(), self.now)  # a pause does not earn a burst
                self.publish_state()
                self.awaiting_reply_since = time.monotonic()
        elif not connected:
            self.awaiting_reply_since = None
        else:
            self.on_unanswered(time.monotonic() - self.awaiting_reply_since)

    def on_unanswered(self, waited: float) -> None:
        """Lock-step: the last scan has waited `waited` wall seconds for its /cmd_vel (called about
        every 0.1 s). Here: after ``reply_timeout`` s, pass it over with a warning and step on."""
        if waited > self.reply_timeout:
            self.passed_over += 1
            self.get_logger().warning(f"No /cmd_vel within {self.reply_timeout:g} s of the scan at t={self.now:.2f} s: "
                                      f"going on without it ({self.passed_over} scans passed over so far)")
            self.advance()

    def halt(self, reason: str) -> None:
        """Lock-step: stop simulating for good (no more scans; /cmd_vel is ignored), saying why."""
        self.halted, self.awaiting_reply_since = reason, None
        self.timer.cancel()
        self._cancel_pace_timer()
        self.get_logger().error(f"Simulation halted at t={self.now:.2f} s: {reason}")

    def advance(self) -> None:
        """Lock-step: the scan is answered (or passed over): tick now, or, when max_real_time_factor
        says the simulation is ahead of the wall clock, once that many wall seconds have passed."""
        wall, simulated = self._pace_start or (time.monotonic(), self.now)
        delay = pace_delay(self.now + 1.0 / self.scan_rate - simulated, time.monotonic() - wall,
                           self.max_real_time_factor)
        if delay <= 0:
            self.tick()
            return
        self.awaiting_reply_since = None
        self.held_back += delay
        self._pace_timer = self.create_timer(delay, self.on_pace_timer, clock=self.steady)

    def on_pace_timer(self) -> None:
        self._cancel_pace_timer()
        if self.halted is None:
            self.tick()

    def _cancel_pace_timer(self) -> None:
        if self._pace_timer is not None:
            self.destroy_timer(self._pace_timer)
            self._pace_timer = None

    def tick(self) -> None:
        """Lock-step: advance one tick and publish what the robot senses there."""
        self.sim.step(1.0 / self.scan_rate)
        self.publish_state()
        self.awaiting_reply_since = time.monotonic()

    # --- what the robot publishes ----------------------------------------------------------------

    def publish_state(self) -> None:
        clock, moved, tf, odom, scan = self._state
        nanoseconds = round(self.now * 1e9)
        now = clock.clock  # the one stamp of all four messages
        now.sec, now.nanosec = nanoseconds // 10**9, nanoseconds % 10**9
        if self.heard(self.clock_pub):
            self.clock_pub.publish(clock)
        x, y, yaw = self.sim.pose()
        linear, angular = self.sim.velocity()
        translation, rotation = moved.transform.translation, moved.transform.rotation
        translation.x, translation.y = x, y
        rotation.x, rotation.y, rotation.z, rotation.w = yaw_quaternion(yaw)
        self.tf_pub.publish(tf)
        position, twist = odom.pose.pose.position, odom.twist.twist
        position.x, position.y = x, y
        twist.linear.x, twist.angular.z = linear, angular
        if self.heard(self.odom_pub):
            self.odom_pub.publish(odom)
        scan.ranges = array.array("f", self.sim.scan().tobytes())
        self.last_scan = scan
        self.scans += 1
        self.scan_pub.publish(scan)

    def heard(self, publisher) -> bool:
        """Whether publish_state publishes on `publisher` (/clock, /odom) this tick: always here."""
        return True

    def _state_messages(self) -> tuple[ClockMessage, TransformStamped, TFMessage, Odometry, LaserScan]:
        """What publish_state sends, built once and updated in place each tick (building four
        messages anew cost more than publishing them): /clock's message, whose stamp the others
        share, the moved transform, /tf's message holding it, the odometry (sharing its rotation)
        and the scan, all stamped with the simulated time."""
        clock = ClockMessage()
        moved, odom = TransformStamped(), Odometry()
        for message in (moved, odom):
            message.header.stamp, message.header.frame_id = clock.clock, husky.ODOM_FRAME
            message.child_frame_id = husky.BASE_FRAME
        odom.pose.pose.orientation = moved.transform.rotation
        laser = self.sim.laser
        scan = LaserScan()
        scan.header.stamp, scan.header.frame_id = clock.clock, husky.LASER_FRAME
        scan.angle_min, scan.angle_max, scan.angle_increment = laser.angle_min, laser.angle_max, laser.angle_increment
        scan.scan_time = 1.0 / self.scan_rate
        scan.range_min, scan.range_max = laser.range_min, laser.range_max
        return clock, moved, TFMessage(transforms=[moved]), odom, scan

    def laser_transform(self) -> TransformStamped:
        mount = TransformStamped()
        mount.header.frame_id, mount.child_frame_id = husky.BASE_FRAME, husky.LASER_FRAME
        t = mount.transform.translation
        t.x, t.y, t.z = husky.LASER_OFFSET
        mount.transform.rotation.w = 1.0
        return mount


def main(args=None):
    rclpy.init(args=args)
    node = None
    try:
        node = RobotSimulator()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
