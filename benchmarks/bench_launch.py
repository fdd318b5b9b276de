"""How long a two-node ``ros2 launch`` takes until both nodes are in the graph, in one run.

Not a test: the times depend on the machine and on what else runs, so this prints them instead
of asserting them. Side by side, each repeated --runs times (interleaved) on one ROS domain:

- ``ros2 launch`` of a two-node XML launch file, as the terminal runs it (``python -m
  course_lib.launch``, which the ``ros2`` command calls);
- ``launch.start()`` of the same file from Python (the notebook way);
- the two node executables started directly as two processes (what two ``ros2 run`` give,
  without the ros2 command's own start-up): the reference.

The clock starts when the command is issued and stops when a watcher node (already running in
this process) sees both nodes; then everything is stopped and the graph must be empty again.

    .venv/bin/python benchmarks/bench_launch.py [--runs 5]
"""

from __future__ import annotations

import argparse
import os
import platform
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # tests.support runs from the repository

from course_lib import launch  # noqa: E402
from course_lib.ros import rosenv  # noqa: E402
from tests.support.launch_demo import CHATTER_NODE, make_prefix  # noqa: E402

TWO_NODES = """<launch>
  <node pkg="bench_demo" exec="talker" name="talker"/>
  <node pkg="bench_demo" exec="listener" name="listener"/>
</launch>
"""
WANTED = {("talker", "/"), ("listener", "/")}


def seconds_until_up(watcher, began: float, timeout: float = 60.0) -> float:
    while not WANTED <= set(watcher.get_node_names_and_namespaces()):
        if time.monotonic() - began > timeout:
            raise TimeoutError("the two nodes did not appear within 60 s")
        time.sleep(0.01)
    return time.monotonic() - began


def wait_until_gone(watcher) -> None:
    deadline = time.monotonic() + 30
    while WANTED & set(watcher.get_node_names_and_namespaces()) and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(0.5)  # let discovery forget the old participants


def by_ros2_launch(watcher, path: Path, environment: dict) -> float:
    began = time.monotonic()
    process = subprocess.Popen([sys.executable, "-m", "course_lib.launch", str(path)], env=environment,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        return seconds_until_up(watcher, began)
    finally:
        process.send_signal(signal.SIGINT)
        process.wait(timeout=30)


def by_launch_start(watcher, path: Path, environment: dict) -> float:
    began = time.monotonic()
    running = launch.start(path)
    try:
        return seconds_until_up(watcher, began)
    finally:
        running.stop()


def by_two_processes(watcher, prefix: Path, environment: dict) -> float:
    began = time.monotonic()
    nodes = [subprocess.Popen([str(prefix / "lib" / "bench_demo" / name), "--ros-args", "-r", f"__node:={name}"],
                              env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
             for name in ("talker", "listener")]
    try:
        return seconds_until_up(watcher, began)
    finally:
        for node in nodes:
            node.send_signal(signal.SIGINT)
        for node in nodes:
            node.wait(timeout=30)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=5, help="runs of each way")
    args = parser.parse_args(argv)
    import rclpy
    from rclpy.context import Context

    with tempfile.TemporaryDirectory(prefix="bench-launch-") as scratch, rosenv.reserve_domain_id() as domain:
        prefix = make_prefix(Path(scratch), "bench_demo", {"talker": CHATTER_NODE, "listener": CHATTER_NODE},
                             {"launch/two.launch.xml": TWO_NODES})
        path = prefix / "share" / "bench_demo" / "launch" / "two.launch.xml"
        os.environ["AMENT_PREFIX_PATH"] = f"{prefix}{os.pathsep}{os.environ.get('AMENT_PREFIX_PATH', '')}"
        os.environ["ROS_DOMAIN_ID"] = str(domain.domain_id)
        environment = rosenv.ros_environment(domain_id=domain.domain_id)
        context = Context()
        rclpy.init(context=context, domain_id=domain.domain_id)
        try:
            watcher = rclpy.create_node("_bench_watcher", context=context, start_parameter_services=False)
            time.sleep(1.0)
            ways = {"ros2 launch (terminal)": lambda: by_ros2_launch(watcher, path, environment),
                    "launch.start() (notebook)": lambda: by_launch_start(watcher, path, environment),
                    "two node processes, no launch": lambda: by_two_processes(watcher, prefix, environment)}
            times = {name: [] for name in ways}
            for _ in range(args.runs):
                for name, way in ways.items():
                    times[name].append(way())
                    wait_until_gone(watcher)
        finally:
            context.try_shutdown()
    reference = statistics.median(times["two node processes, no launch"])
    print(f"{platform.node()}: Python {platform.python_version()}, {os.cpu_count()} CPUs, "
          f"RMW {os.environ.get('RMW_IMPLEMENTATION', 'default (Fast DDS)')}, median of {args.runs} runs\n")
    print(f"{'way':<32}{'both nodes in the graph after':>32}{'ratio':>10}")
    for name, values in times.items():
        median = statistics.median(values)
        print(f"{name:<32}{median:>30.2f} s{median / reference:>9.2f}×")
    return 0


if __name__ == "__main__":
    sys.exit(main())
