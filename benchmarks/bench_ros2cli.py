"""How long the course's ``ros2`` command takes to answer, next to the floor any ROS process pays.

Not a test: times depend on the machine and on what else runs, so this prints numbers instead of
asserting them. Compare rows measured in the same run.

    .venv/bin/python benchmarks/bench_ros2cli.py [--runs 5]

Two live nodes (a talker with parameters and a listener, each in a process of its own) run in
a reserved ROS domain. Each command runs --runs times as a new process, as a student types it,
alternating with the others; the table shows the median wall time and processor time (user and
system, which the machine's load moves much less; the test suite is bound by it) and their ratios
to the floor:
a new Python process that imports rclpy and creates one node (what every ros2 command pays
before it can look at the graph). ``python -c pass`` shows what the interpreter alone costs.

The graph verbs ask the course's ros2 daemon (course_lib.ros2cli.daemon), as ros2cli's do: the
row "daemon start" is a first graph verb with no daemon running (it starts one and waits for its
answer), the rows marked "(daemon warm)" ask a running one, and the rows marked "--no-daemon"
discover the graph themselves like ros2cli without its daemon: --spin-time (0.5 s) at least,
longer while the graph still changes or shows fewer nodes than there are other ROS processes on
the machine. The rows "fails: ..." name something that does not exist.

Goals (issue #50): warm rows at most 0.6 s of wall time and 2x the floor's processor time, a
missing name failing within 1 s, the first call within 3 s.
"""

from __future__ import annotations

import argparse
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from course_lib.ros import processes, rosenv  # noqa: E402

NODES = '''
import sys
import rclpy
from rclpy.node import Node
from std_msgs.msg import String

rclpy.init(args=sys.argv)
node = Node(sys.argv[1])
node.declare_parameter('rate', 10.0)
if sys.argv[1] == 'bench_talker':
    publisher = node.create_publisher(String, 'bench_chatter', 10)
    node.create_timer(0.1, lambda: publisher.publish(String(data='hello')))
else:
    node.create_subscription(String, 'bench_chatter', lambda msg: None, 10)
try:
    rclpy.spin(node)
except KeyboardInterrupt:
    pass
'''

FLOOR = ("import rclpy; from rclpy.node import Node; rclpy.init(); "
         "Node('_floor', start_parameter_services=False)")


def commands(ros2: str) -> list[tuple[str, list[str]]]:
    return [
        ("python -c pass", [sys.executable, "-c", "pass"]),
        ("python -c 'import rclpy'", [sys.executable, "-c", "import rclpy"]),
        ("floor: python, import rclpy, one node", [sys.executable, "-c", FLOOR]),
        ("ros2 --help", [ros2, "--help"]),
        ("daemon start: ros2 node list, no daemon running", [ros2, "node", "list"]),
        ("ros2 node list --no-daemon", [ros2, "node", "list", "--no-daemon"]),
        ("ros2 node list (daemon warm)", [ros2, "node", "list"]),
        ("ros2 topic list (daemon warm)", [ros2, "topic", "list"]),
        ("ros2 service list (daemon warm)", [ros2, "service", "list"]),
        ("ros2 topic type /bench_chatter (daemon warm)", [ros2, "topic", "type", "/bench_chatter"]),
        ("ros2 topic info /bench_chatter (daemon warm)", [ros2, "topic", "info", "/bench_chatter"]),
        ("fails: ros2 topic type /no_such_topic (daemon warm)", [ros2, "topic", "type", "/no_such_topic"]),
        ("fails: ros2 node info /no_such_node (daemon warm)", [ros2, "node", "info", "/no_such_node"]),
        ("ros2 topic echo /bench_chatter --once", [ros2, "topic", "echo", "/bench_chatter", "--once"]),
        ("ros2 param get /bench_talker rate", [ros2, "param", "get", "/bench_talker", "rate"]),
        # Failures: ros2cli's own test wants `topic echo` of a topic nobody publishes to end within
        # 2 s on an idle machine (ros2topic's test_cli.py, test_topic_echo_no_publisher).
        ("fails: ros2 topic echo /no_such_topic", [ros2, "topic", "echo", "/no_such_topic"]),
        ("fails: ros2 param list /no_such_node", [ros2, "param", "list", "/no_such_node"]),
    ]


def _children_cpu() -> float:
    """Processor seconds (user and system) of this process's ended children so far."""
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    return used.ru_utime + used.ru_stime


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5, help="runs of each command (default 5)")
    args = parser.parse_args(argv)
    load = os.getloadavg()[0]
    ros2 = str(Path(sys.executable).parent / "ros2")
    if not Path(ros2).is_file():
        sys.exit(f"{ros2} is missing: run `make setup` (it installs the course's ros2 on the pip install)")
    script = Path(tempfile.mkdtemp(prefix="bench_ros2cli_")) / "nodes.py"
    script.write_text(NODES)
    with rosenv.reserve_domain_id() as reservation:
        env = rosenv.ros_environment(domain_id=reservation.domain_id)
        env.pop("COURSE_LIB_UNDER_TEST", None)
        nodes = [processes.NodeProcess([sys.executable, str(script), name], domain_id=reservation.domain_id).start()
                 for name in ("bench_talker", "bench_listener")]
        try:
            for process, name in zip(nodes, ("bench_talker", "bench_listener"), strict=True):
                process.wait_for_node(name, timeout=60)
            times: dict[str, list[float]] = {label: [] for label, _ in commands(ros2)}
            processor: dict[str, list[float]] = {label: [] for label, _ in commands(ros2)}
            answers: dict[str, str] = {}
            for _ in range(args.runs):
                for label, command in commands(ros2):
                    if label.startswith("daemon start"):
                        subprocess.run([ros2, "daemon", "stop"], env=env, capture_output=True, timeout=120)
                    began, used = time.perf_counter(), _children_cpu()
                    done = subprocess.run(command, env=env, capture_output=True, text=True, timeout=120)
                    times[label].append(time.perf_counter() - began)
                    processor[label].append(_children_cpu() - used)
                    if (done.returncode != 0) != label.startswith("fails: "):
                        sys.exit(f"{label} ended with exit code {done.returncode}: {done.stderr}")
                    answers[label] = done.stdout
        finally:
            subprocess.run([ros2, "daemon", "stop"], env=env, capture_output=True, timeout=120)
            for process in nodes:
                process.stop()
    floor = statistics.median(times["floor: python, import rclpy, one node"])
    floor_cpu = statistics.median(processor["floor: python, import rclpy, one node"])
    print(f"Python {platform.python_version()}, {platform.machine()}, {os.cpu_count()} cores, "
          f"median of {args.runs} runs, load average before: {load:.2f}\n")
    print("| command | median wall time | ratio to the floor | median processor time | ratio to the floor |")
    print("|---|---:|---:|---:|---:|")
    for label, _ in commands(ros2):
        median, cpu = statistics.median(times[label]), statistics.median(processor[label])
        print(f"| {label} | {median:.2f} s | {median / floor:.2f} | {cpu:.2f} s | {cpu / floor_cpu:.2f} |")
    for label in ("daemon start: ros2 node list, no daemon running", "ros2 node list (daemon warm)"):
        listed = answers[label].split()
        print(f"\n{label} answered {listed} (both nodes: {listed == ['/bench_listener', '/bench_talker']})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
