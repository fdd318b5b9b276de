"""The robot on the pip install: ``python -m course_lib install-robot`` (run by ``make setup``).

It builds tf2_msgs, which PyPI lacks (:mod:`course_lib.robot.interface_install`), and installs ROS
packages into the environment as colcon installs an ament_python package: a marker in the ament
index, ``share/PKG/`` and executables in ``lib/PKG/`` that run a module's main(). ``robot_sim``
(the folder beside this module: ``ros2 run robot_sim simulator``, ``ros2 launch robot_sim
husky.launch.xml world:=pillar``) is an ament_python package that colcon builds on a full ROS
install; here it gets the files its setup.py installs (SHARED, and the executables). Then the
stand-ins of tools that PyPI lacks, under upstream's package and executable names: tf2_ros's
``static_transform_publisher`` and ``tf2_echo``, tf2_tools' ``view_frames`` and
``teleop_twist_keyboard``. ``ros2 run`` finds them as it finds a package of a sourced workspace.
Running it again rewrites the same files.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

PACKAGE = "robot_sim"
SOURCE = Path(__file__).parent / PACKAGE
#: Each package's executables and the module whose main() each runs.
PACKAGES = {
    PACKAGE: {"simulator": "course_lib.robot.simulator_node"},
    "tf2_ros": {"static_transform_publisher": "course_lib.robot.static_transform_publisher",
                "tf2_echo": "course_lib.robot.tf2_echo"},
    "tf2_tools": {"view_frames": "course_lib.robot.view_frames"},
    "teleop_twist_keyboard": {"teleop_twist_keyboard": "course_lib.robot.teleop_keyboard"},
}
EXECUTABLES = PACKAGES[PACKAGE]
#: What robot_sim's setup.py installs into share/robot_sim (its data_files besides the ament index's marker).
SHARED = ("package.xml", "launch", "worlds")
#: What a stand-in's package.xml says it is (it has no folder of its own: it is all code).
STAND_IN_XML = """<?xml version="1.0"?>
<package format="3">
  <name>{name}</name>
  <version>0.0.0</version>
  <description>The course's stand-in for {name}'s executables on the pip install ({executables}),
    which run course_lib.robot; installed by course_lib.robot.install (make setup).
    A full ROS install has the real one.</description>
  <maintainer email="course@example.com">ROS 2 and OpenCV course</maintainer>
  <license>Apache-2.0</license>
  <exec_depend>rclpy</exec_depend>
  <export>
    <build_type>ament_python</build_type>
  </export>
</package>
"""


def script_text(python: str, module: str, package: str = PACKAGE) -> str:
    return (f"#!{python}\n# an executable of {package}, installed by course_lib.robot.install (make setup)\n"
            f"import sys\n\nfrom {module} import main\n\nsys.exit(main())\n")


def install_package(prefix: Path | None = None) -> str:
    """Install robot_sim and the stand-ins into `prefix` (default: this environment); what was done, in one line."""
    prefix = Path(sys.prefix if prefix is None else prefix).absolute()
    for package, executables in PACKAGES.items():
        marker = prefix / "share" / "ament_index" / "resource_index" / "packages" / package
        marker.parent.mkdir(parents=True, exist_ok=True)
        marker.write_text("")
        share = prefix / "share" / package
        shutil.rmtree(share, ignore_errors=True)
        if package == PACKAGE:
            share.mkdir(parents=True)
            for name in SHARED:
                if (SOURCE / name).is_dir():
                    shutil.copytree(SOURCE / name, share / name, ignore=shutil.ignore_patterns("__pycache__"))
                else:
                    shutil.copy(SOURCE / name, share)
        else:
            share.mkdir(parents=True)
            (share / "package.xml").write_text(STAND_IN_XML.format(name=package, executables=", ".join(executables)))
        lib = prefix / "lib" / package
        lib.mkdir(parents=True, exist_ok=True)
        for name, module in executables.items():
            (lib / name).write_text(script_text(str(Path(sys.executable)), module, package))
            (lib / name).chmod(0o755)
    installed = "; ".join(f"{package} ({', '.join(executables)})" for package, executables in PACKAGES.items())
    return f"install-robot: installed {installed} into {prefix}"


def main(argv: list[str] | None = None) -> int:
    """``python -m course_lib install-robot``: tf2_msgs (pip install only), then robot_sim."""
    from course_lib.robot import interface_install
    from course_lib.ros import rosenv

    if argv:
        print(f"python -m course_lib install-robot takes no arguments, got {' '.join(argv)}", file=sys.stderr)
        return 2
    if rosenv.detect_install().kind != "pip":
        print(f"install-robot: not needed, {rosenv.detect_install().describe()} has ROS's own tf2_msgs; build "
              f"robot_sim in a workspace: mkdir -p robot_ws/src && ln -s {SOURCE} robot_ws/src/ && "
              "python -m course_lib build robot_ws, then source robot_ws/install/setup.bash")
        return 0
    if interface_install.main([]):
        # Not fatal for the rest of the set-up: the course works without the robot until a C compiler
        # and CMake are there (the custom-message lesson needs them too).
        print("install-robot: the robot simulator needs tf2_msgs: install a C compiler and CMake, then run "
              "`python -m course_lib install-robot` again", file=sys.stderr)
    print(install_package())
    return 0
