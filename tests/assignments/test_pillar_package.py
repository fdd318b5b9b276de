"""The pillar assignment's reference package (assignments/reference_ws/src/pillar): its plain
functions, its layout, and its node driving the simulated robot to the pillar.

The drive is one lock-step run over real DDS: the reference node as a process of its own (its
module run with the package's parameter file, as ``ros2 run`` with ``--params-file`` would), the
course's simulator in this process; the simulation waits for each scan's /cmd_vel, so the run is
counted in simulated seconds, and the wall clock only bounds a run that stops (60 s).
"""

import math
import os
import sys
import time
import xml.etree.ElementTree as ElementTree

import numpy as np
import pytest
import yaml
from support.from_source import reference_module

from course_lib import contract

SOURCE = contract.ROOT / "assignments" / "reference_ws" / "src" / "pillar"
pillar_node = reference_module("pillar.pillar_node")  # the package's modules, as colcon would install them
PILLAR_RADIUS, find_pillar, p_controller, pillar_in_odom = (
    pillar_node.PILLAR_RADIUS, pillar_node.find_pillar, pillar_node.p_controller, pillar_node.pillar_in_odom)

BACKSTOP = 60.0
ANGLE_MIN, INCREMENT = -3 * math.pi / 4, 1.5 * math.pi / 540


# ---- find_pillar ------------------------------------------------------------------------------

def test_find_pillar_gives_the_smallest_range_and_its_beams_angle_as_floats():
    ranges = np.full(541, np.inf, np.float32)
    ranges[400:410] = np.linspace(3.0, 2.0, 10)
    distance, angle = find_pillar(ranges, ANGLE_MIN, INCREMENT)
    assert distance == pytest.approx(2.0) and angle == pytest.approx(ANGLE_MIN + 409 * INCREMENT)
    assert angle > 0, "beams after the middle look to the left (counter-clockwise)"
    assert type(distance) is float and type(angle) is float  # a numpy float32 in a Twist is garbage


def test_find_pillar_passes_over_minus_inf_and_nan_and_finds_nothing_in_an_empty_scan():
    ranges = [math.inf] * 20
    ranges[3], ranges[7], ranges[12] = -math.inf, math.nan, 4.5
    assert find_pillar(ranges, -0.5, 0.05) == pytest.approx((4.5, -0.5 + 12 * 0.05))
    assert find_pillar([math.inf, math.nan, -math.inf], -0.5, 0.05) is None


def test_find_pillar_on_a_simulated_scan_points_at_the_pillar():
    from course_lib.robot import husky
    from course_lib.robot.simulation import Simulation

    sim = Simulation("pillar", seed=5)
    distance, angle = find_pillar(sim.scan(), sim.laser.angle_min, sim.laser.angle_increment)
    x, y = pillar_in_odom(distance, angle, husky.LASER_OFFSET[0], 0.0, 0.0)
    assert math.hypot(x - sim.pillar[0], y - sim.pillar[1]) < 0.05


# ---- p_controller and pillar_in_odom --------------------------------------------------------------

GAINS = dict(linear_gain=1.0, angular_gain=1.5, max_linear_speed=0.8, max_angular_speed=1.0, stop_distance=0.3)


@pytest.mark.parametrize("distance, angle, expected", [
    (0.5, 0.2, (0.2, 0.3)),          # within the limits: the gains times the errors
    (5.0, 2.0, (0.8, 1.0)),          # far and far to the left: both clamped
    (5.0, -2.0, (0.8, -1.0)),        # to the right: turning clockwise, clamped
    (0.2, 0.1, (0.0, 0.15)),         # nearer than the stop distance: no backing up
])
def test_p_controller_is_proportional_and_clamped(distance, angle, expected):
    command = p_controller(distance, angle, **GAINS)
    assert command == pytest.approx(expected)
    assert all(type(value) is float for value in command)


def test_pillar_in_odom_turns_and_moves_the_laser_reading():
    x, y = pillar_in_odom(1.0, math.pi / 2, 2.0, 1.0, math.pi / 2)  # laser facing +y, pillar to its left
    assert (x, y) == pytest.approx((2.0 - 1.0 - PILLAR_RADIUS, 1.0))


# ---- the package ------------------------------------------------------------------------------

def test_the_package_has_the_ament_python_layout_its_launch_file_and_parameters():
    root = ElementTree.parse(SOURCE / "package.xml").getroot()
    assert root.get("format") == "3" and root.findtext("name") == "pillar"
    assert {"rclpy", "sensor_msgs", "geometry_msgs", "visualization_msgs"} <= {d.text for d in root.iter("depend")}
    assert "pillar_node = pillar.pillar_node:main" in (SOURCE / "setup.py").read_text()
    assert "install_scripts=$base/lib/pillar" in (SOURCE / "setup.cfg").read_text()
    assert (SOURCE / "resource" / "pillar").is_file()
    parameters = yaml.safe_load((SOURCE / "config" / "pillar.yaml").read_text())["pillar_node"]["ros__parameters"]
    assert parameters["scan_topic"] == "/scan" and parameters["queue_size"] == 10
    assert set(GAINS) <= set(parameters)
    launch = ElementTree.parse(SOURCE / "launch" / "pillar.launch.xml").getroot()
    assert launch.find("include").get("file") == "$(find-pkg-share robot_sim)/launch/husky.launch.xml"
    node = launch.find("node")
    assert (node.get("pkg"), node.get("exec")) == ("pillar", "pillar_node")
    assert node.find("param").get("from") == "$(find-pkg-share pillar)/config/pillar.yaml"


# ---- the node drives the simulated robot ------------------------------------------------------------

def _lock_step_run(domain_id, seed: int, seconds: float):
    """The reference node (a process) and the simulator (here, lock-step) for `seconds` simulated
    seconds; returns the simulation, whether it touched the pillar at any tick, and the markers."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    from visualization_msgs.msg import Marker

    from course_lib.robot.simulator_node import RobotSimulator
    from course_lib.ros import processes

    node = processes.python_node("pillar.pillar_node:main", "--ros-args", "--params-file",
                                 str(SOURCE / "config" / "pillar.yaml"), domain_id=domain_id,
                                 env={"PYTHONPATH": os.pathsep.join([str(SOURCE), *sys.path])})
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain_id)
    overrides = [Parameter(name, value=value) for name, value in
                 {"world": "pillar", "seed": seed, "lock_step": True, "reply_timeout": BACKSTOP}.items()]
    sim_node = RobotSimulator(context=context, parameter_overrides=overrides)
    listener = rclpy.create_node("marker_listener", context=context)
    markers = []
    listener.create_subscription(Marker, "pillar_marker", markers.append, 100)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(sim_node)
    executor.add_node(listener)
    sim, touched = sim_node.sim, []
    deadline = time.monotonic() + BACKSTOP
    try:
        while sim.time < seconds:
            assert node.running(), f"the node ended ({node.describe_exit()}):\n{node.log_tail()}"
            assert time.monotonic() < deadline, f"not {seconds:g} simulated seconds within {BACKSTOP:g} s"
            executor.spin_once(timeout_sec=0.1)
            touched.append(sim.touching())
    finally:
        node.stop()
        executor.shutdown()
        for each in (sim_node, listener):
            each.destroy_node()
        rclpy.try_shutdown(context=context)
    return sim, any(touched), markers


@pytest.mark.timeout(180)
def test_the_node_marks_the_pillar_and_stops_near_it_without_touching_it(domain_id):
    """Seed 5 puts the pillar 4.6 m away, 0.53 rad to the left: in 15 simulated seconds the robot
    turns, drives there and stops with its laser 0.3-0.5 m from the pillar's surface."""
    from course_lib.robot import husky

    sim, touched, markers = _lock_step_run(domain_id, seed=5, seconds=15.0)
    px, py = sim.pillar
    x, y, yaw = sim.pose()
    laser_x, laser_y = x + husky.LASER_OFFSET[0] * math.cos(yaw), y + husky.LASER_OFFSET[0] * math.sin(yaw)
    gap = math.hypot(px - laser_x, py - laser_y) - sim.pillar_radius
    assert 0.3 <= gap <= 0.5 and abs(sim.velocity()[0]) < 0.05 and not touched, (gap, sim.velocity(), touched)
    assert len(markers) > 100 and {m.header.frame_id for m in markers} == {"odom"}
    errors = [math.hypot(m.pose.position.x - px, m.pose.position.y - py) for m in markers]
    # Near the pillar the nearest beam wanders over its arc with the laser's noise: a few cm. A
    # marker whose scan reached the node before that tick's /tf (two topics, each in its own
    # reader: on a busy machine) is placed with the tick before's transform, as the node is
    # written to do, up to 0.16 m off while it turns: the grader judges the share of markers
    # (pillar.MARKER_SHARE within MARKER_TOLERANCE), and so does this test, more strictly.
    assert np.percentile(errors, 90) < 0.1, errors
