"""course_lib.robot.install and interface_install: what make setup installs for the robot works as on a
full ROS install: tf2_msgs imports and shows, `ros2 run robot_sim simulator` and `ros2 launch
robot_sim husky.launch.xml world:=...` start the simulator, whose scans show the world asked for;
and robot_sim is a package that the real colcon builds into the same files."""

import configparser
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from sensor_msgs.msg import LaserScan
from support.ros2cli import ROS2, ros2

from course_lib.robot import husky, install, interface_install
from course_lib.ros import colcon, rosenv, workspace
from course_lib.supervision import process_tree

pytestmark = pytest.mark.skipif(rosenv.detect_install().kind != "pip",
                                reason="make setup installs these on the pip install only")

# 60 s for Ctrl-C to end the process (a busy machine's slow exit is no failure)
STOP_STEPS = ((signal.SIGINT, 60.0), (signal.SIGKILL, 5.0))


def test_tf2_msgs_is_installed_from_the_courses_sources_and_imports_in_a_new_process(domain_id):
    assert interface_install.installed_key("tf2_msgs", Path(sys.prefix)) \
        == interface_install.source_key("tf2_msgs"), "make setup installs the current sources"
    env = rosenv.ros_environment(domain_id)
    code = ("from tf2_msgs.msg import TFMessage, TF2Error; from tf2_msgs.srv import FrameGraph; "
            "from tf2_msgs.action import LookupTransform; "
            "print(TFMessage.get_fields_and_field_types(), TF2Error.EXTRAPOLATION_ERROR)")
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert "'transforms': 'sequence<geometry_msgs/TransformStamped>'" in done.stdout and done.stdout.endswith("3\n")
    shown = ros2("interface", "show", "tf2_msgs/action/LookupTransform", "--no-comments", env=env).stdout
    assert "string target_frame\nstring source_frame\nbuiltin_interfaces/Time source_time" in shown


def test_the_package_is_what_colcon_would_install(tmp_path):
    install.install_package(tmp_path)
    assert (tmp_path / "share/ament_index/resource_index/packages/robot_sim").is_file()
    assert (tmp_path / "share/robot_sim/package.xml").is_file()
    assert (tmp_path / "share/robot_sim/launch/husky.launch.xml").is_file()
    script = tmp_path / "lib/robot_sim/simulator"
    assert script.read_text().startswith(f"#!{sys.executable}\n") and "simulator_node import main" in script.read_text()
    # the stand-ins of tools PyPI lacks, under upstream's package and executable names
    for package, executable in (("tf2_ros", "static_transform_publisher"), ("tf2_ros", "tf2_echo"),
                                ("tf2_tools", "view_frames"), ("teleop_twist_keyboard", "teleop_twist_keyboard")):
        assert (tmp_path / "share/ament_index/resource_index/packages" / package).is_file()
        assert f"<name>{package}</name>" in (tmp_path / "share" / package / "package.xml").read_text()
        assert (tmp_path / "lib" / package / executable).stat().st_mode & 0o111


def first_scan(domain_id, command: list[str], env: dict | None = None) -> LaserScan:
    """Start `command` (a ros2 command line; in the course's environment, or `env`) and return the
    first scan it publishes; then Ctrl-C it."""
    env = rosenv.ros_environment(domain_id) if env is None else env
    process = subprocess.Popen([str(ROS2), *command], env=env, start_new_session=True,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, stdin=subprocess.DEVNULL)
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain_id)
    scans = []
    try:
        node = Node("scan_reader", context=context)
        node.create_subscription(LaserScan, "/scan", scans.append, 10)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        deadline = time.monotonic() + 60.0
        while not scans and time.monotonic() < deadline and process.poll() is None:
            executor.spin_once(timeout_sec=0.1)
        executor.shutdown()
        node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)
        code = process_tree.stop_group(process, STOP_STEPS)
        output = process.stdout.read()
    assert scans, f"no scan within 60 s; `ros2 {' '.join(command)}` printed:\n{output}"
    assert code in (0, -signal.SIGINT), f"exit code {code} after Ctrl-C:\n{output}"
    return scans[0]


def test_ros2_run_starts_the_simulator_with_its_parameters(domain_id):
    scan = first_scan(domain_id, ["run", "robot_sim", "simulator", "--ros-args", "-p", "world:=walls"])
    # the walls world: the east wall's face 5 m ahead of base_link
    assert scan.ranges[len(scan.ranges) // 2] == pytest.approx(5.0 - husky.LASER_OFFSET[0], abs=0.05)


def test_ros2_launch_starts_the_world_asked_for(domain_id):
    scan = first_scan(domain_id, ["launch", "robot_sim", "husky.launch.xml", "world:=maze"])
    # the maze's start: the wall to the cell on the left 1.15 m from the laser
    assert scan.ranges[len(scan.ranges) * 5 // 6] == pytest.approx(1.15, abs=0.05)


def _files(root: Path) -> list[str]:
    return sorted(str(path.relative_to(root)) for path in root.rglob("*") if path.is_file())


@pytest.mark.slow
def test_colcon_builds_robot_sim_into_what_make_setup_installs_and_ros2_launch_runs_the_build(tmp_path, domain_id):
    """On a full ROS install a student builds robot_sim with colcon (ament_python): its share/ holds
    what make setup installs here (package.xml, the launch file, the worlds), the ament index knows
    it, its `simulator` runs course_lib's node, and `ros2 launch` of the build starts a world of
    the build's share/."""
    ws = tmp_path / "ws"
    shutil.copytree(install.SOURCE, ws / "src" / install.PACKAGE, ignore=shutil.ignore_patterns("__pycache__"))
    colcon.build(ws, timeout=300)
    built = ws / "install" / install.PACKAGE
    install.install_package(tmp_path / "prefix")
    colcon_hooks = {f"package.{ext}" for ext in ("bash", "dsv", "ps1", "sh", "zsh")}  # colcon's, for `source`
    shared = [f for f in _files(built / "share" / install.PACKAGE)
              if not f.startswith("hook/") and f not in colcon_hooks]
    assert shared == _files(tmp_path / "prefix" / "share" / install.PACKAGE)
    assert {"package.xml", "launch/husky.launch.xml", "worlds/husky.xml", "worlds/pillar.xml"} <= set(shared)
    assert (built / "share/ament_index/resource_index/packages" / install.PACKAGE).is_file()
    (entry_points,) = built.glob("lib/python*/site-packages/robot_sim-*.egg-info/entry_points.txt")
    scripts = configparser.ConfigParser()
    scripts.read(entry_points)
    assert dict(scripts["console_scripts"]) == {name: f"{module}:main" for name, module in install.EXECUTABLES.items()}
    assert all((built / "lib" / install.PACKAGE / name).stat().st_mode & 0o111 for name in install.EXECUTABLES)

    env = workspace.workspace_environment(ws, domain_id=domain_id)  # the build first, as after `source`
    walls = built / "share" / install.PACKAGE / "worlds" / "walls.xml"
    scan = first_scan(domain_id, ["launch", "robot_sim", "husky.launch.xml", f"world:={walls}"], env=env)
    assert scan.ranges[len(scan.ranges) // 2] == pytest.approx(5.0 - husky.LASER_OFFSET[0], abs=0.05)
