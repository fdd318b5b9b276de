"""How fast the simulated robot runs, in one run, side by side:

- the simulation alone (course_lib.robot.simulation): processor time of a MuJoCo step and of a scan;
- lock-step: the simulator node as a process (``python -m course_lib.robot.simulator_node``,
  ``lock_step:=true``) and a P-controller towards the pillar in this process, answering each scan;
  simulated seconds per processor second of both processes together (the goal: 20 or more);
- real time: the simulator node as a process at its default 20 Hz, a subscriber here counting the
  scans that arrive for --seconds: the rate delivered and the share of the scans published (the
  stamps say how many were published in between).

Not a test: the numbers depend on the machine; this prints them.

    .venv/bin/python benchmarks/bench_sim.py [--seconds 10] [--simulated 60]
"""

from __future__ import annotations

import argparse
import math
import platform
import subprocess
import sys
import time

import numpy as np
import psutil
import rclpy
from geometry_msgs.msg import Twist
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan

from course_lib.robot.simulation import Simulation
from course_lib.ros import rosenv
from course_lib.supervision import process_tree


class PillarController(Node):
    """Turn towards the nearest return and drive until 0.6 m from it: one /cmd_vel per scan."""

    def __init__(self, context):
        super().__init__("pillar_controller", context=context)
        self.cmd = self.create_publisher(Twist, "cmd_vel", 10)
        self.create_subscription(LaserScan, "scan", self.on_scan, 10)
        self.create_subscription(Clock, "/clock", self.on_clock, 10)
        self.sim_time = 0.0
        self.scans = []

    def on_clock(self, msg: Clock) -> None:
        self.sim_time = msg.clock.sec + msg.clock.nanosec * 1e-9

    def on_scan(self, scan: LaserScan) -> None:
        self.scans.append(scan.header.stamp.sec + scan.header.stamp.nanosec * 1e-9)
        ranges = np.array(scan.ranges, dtype=float)
        ranges[~np.isfinite(ranges)] = np.inf
        nearest = int(np.argmin(ranges))
        twist = Twist()
        if math.isfinite(ranges[nearest]):
            twist.linear.x = 0.5 * max(float(ranges[nearest]) - 0.6, 0.0)
            twist.angular.z = 1.5 * (scan.angle_min + nearest * scan.angle_increment)
        self.cmd.publish(twist)


def simulation_alone(steps=20000, scans=2000) -> list[tuple[str, str, str]]:
    sim = Simulation("pillar", seed=1)
    sim.command(0.5, 0.2)
    start = time.process_time()
    for _ in range(steps):
        sim.step(sim.timestep)
    step_cost = (time.process_time() - start) / steps
    start = time.process_time()
    for _ in range(scans):
        sim.scan()
    scan_cost = (time.process_time() - start) / scans
    return [("simulation alone", "MuJoCo step (2 ms simulated)", f"{step_cost * 1e6:.1f} µs"),
            ("simulation alone", f"scan of {sim.laser.beams} beams (mj_multiRay + noise)", f"{scan_cost * 1e3:.3f} ms"),
            ("simulation alone", "simulated s per processor s (physics only)", f"{sim.timestep / step_cost:.0f}×")]


def start_simulator(domain_id: int, *parameters: str) -> subprocess.Popen:
    args = [sys.executable, "-m", "course_lib.robot.simulator_node", "--ros-args"]
    for parameter in parameters:
        args += ["-p", parameter]
    return subprocess.Popen(args, env=rosenv.ros_environment(domain_id), start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def spin_until(executor, condition, backstop=120.0) -> None:
    deadline = time.monotonic() + backstop
    while not condition() and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.1)


def lock_step(domain_id: int, simulated: float) -> list[tuple[str, str, str]]:
    process = start_simulator(domain_id, "lock_step:=true", "world:=pillar", "seed:=1", "reply_timeout:=60.0")
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain_id)
    try:
        controller = PillarController(context)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(controller)
        spin_until(executor, lambda: controller.sim_time > 0.0)
        child, start_wall = psutil.Process(process.pid), time.monotonic()
        start_cpu, start_sim = time.process_time() + sum(child.cpu_times()[:2]), controller.sim_time
        spin_until(executor, lambda: controller.sim_time >= start_sim + simulated)
        cpu = time.process_time() + sum(child.cpu_times()[:2]) - start_cpu
        wall, done = time.monotonic() - start_wall, controller.sim_time - start_sim
        executor.shutdown()
        controller.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)
        process_tree.stop_group(process)
    return [("lock-step", "simulated s per processor s (simulator + controller)", f"{done / cpu:.1f}×"),
            ("lock-step", "simulated s per wall s", f"{done / wall:.1f}×"),
            ("lock-step", f"processor s for {done:.0f} simulated s", f"{cpu:.2f} s")]


def real_time(domain_id: int, seconds: float) -> list[tuple[str, str, str]]:
    process = start_simulator(domain_id, "world:=walls")
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain_id)
    try:
        node = Node("scan_counter", context=context)
        stamps = []
        node.create_subscription(LaserScan, "scan",
                                 lambda s: stamps.append(s.header.stamp.sec + s.header.stamp.nanosec * 1e-9), 10)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        spin_until(executor, lambda: len(stamps) > 0)
        start, first = time.monotonic(), len(stamps)
        spin_until(executor, lambda: time.monotonic() - start >= seconds, backstop=seconds + 60)
        window = stamps[first:]
        wall = time.monotonic() - start
        executor.shutdown()
        node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)
        process_tree.stop_group(process)
    published = round((window[-1] - window[0]) * 20.0) + 1
    return [("real time", "scans received per wall s (20 Hz asked)", f"{len(window) / wall:.1f} Hz"),
            ("real time", "scans received of published",
             f"{len(window)} of {published} ({100 * len(window) / published:.0f} %)"),
            ("real time", "simulated s per wall s", f"{(window[-1] - window[0]) / wall:.2f}")]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0, help="wall seconds of the real-time window")
    parser.add_argument("--simulated", type=float, default=60.0, help="simulated seconds of the lock-step run")
    args = parser.parse_args(argv)
    rows = simulation_alone()
    with rosenv.reserve_domain_id() as reservation:
        rows += lock_step(reservation.domain_id, args.simulated)
        rows += real_time(reservation.domain_id, args.seconds)
    print(f"Python {platform.python_version()}, {psutil.cpu_count()} cores, load average "
          f"{psutil.getloadavg()[0]:.1f}, the pillar world (seed 1) and the walls world, 541 beams, 20 Hz\n")
    print("| mode | measurement | value |\n|---|---|---:|")
    for row in rows:
        print("| " + " | ".join(row) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
