"""The robot on the pip install: ``python -m course_lib install-robot`` (run by ``make setup``).

It builds tf2_msgs, which PyPI lacks (:mod:`course_lib.robot.interface_install`), and installs the
ROS package ``robot_sim`` (the folder ``robot_sim/`` beside this module) into the environment as
colcon installs an ament_python package: its marker in the ament index, ``share/robot_sim/``
(package.xml, launch/) and the executable ``lib/robot_sim/simulator``, which runs
:func:`course_lib.robot.simulator_node.main`. Then ``ros2 run robot_sim simulator`` and
``ros2 launch robot_sim husky.launch.xml world:=pillar`` find it as they find a package of a
sourced workspace. Running it again rewrites the same files.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

PACKAGE = "robot_sim"
SOURCE = Path(__file__).parent / PACKAGE
#: The package's executables and the module whose main() each runs.
EXECUTABLES = {"simulator": "course_lib.robot.simulator_node"}


def script_text(python: str, module: str) -> str:
    return (f"#!{python}\n# an executable of {PACKAGE}, installed by course_lib.robot.install (make setup)\n"
            f"import sys\n\nfrom {module} import main\n\nsys.exit(main())\n")


def install_package(prefix: Path | None = None) -> str:
    """Install robot_sim into `prefix` (default: this environment); what was done, in one line."""
    prefix = Path(sys.prefix if prefix is None else prefix).absolute()
    marker = prefix / "share" / "ament_index" / "resource_index" / "packages" / PACKAGE
    marker.parent.mkdir(parents=True, exist_ok=True)
    marker.write_text("")
    share = prefix / "share" / PACKAGE
    shutil.rmtree(share, ignore_errors=True)
    shutil.copytree(SOURCE, share, ignore=shutil.ignore_patterns("__pycache__"))
    lib = prefix / "lib" / PACKAGE
    lib.mkdir(parents=True, exist_ok=True)
    for name, module in EXECUTABLES.items():
        (lib / name).write_text(script_text(str(Path(sys.executable)), module))
        (lib / name).chmod(0o755)
    return f"install-robot: installed {PACKAGE} ({', '.join(EXECUTABLES)}) into {prefix}"


def main(argv: list[str] | None = None) -> int:
    """``python -m course_lib install-robot``: tf2_msgs (pip install only), then robot_sim."""
    from course_lib.robot import interface_install
    from course_lib.ros import rosenv

    if argv:
        print(f"python -m course_lib install-robot takes no arguments, got {' '.join(argv)}", file=sys.stderr)
        return 2
    if rosenv.detect_install().kind != "pip":
        print(f"install-robot: not needed, {rosenv.detect_install().describe()} has ROS's own tf2_msgs; "
              "build robot_sim in a workspace of that install")
        return 0
    if interface_install.main([]):
        # Not fatal for the rest of the set-up: the course works without the robot until a C compiler
        # and CMake are there (the custom-message lesson needs them too).
        print("install-robot: the robot simulator needs tf2_msgs: install a C compiler and CMake, then run "
              "`python -m course_lib install-robot` again", file=sys.stderr)
    print(install_package())
    return 0
