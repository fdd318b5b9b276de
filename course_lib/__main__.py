"""Command line of course_lib: ``python -m course_lib COMMAND``.

Commands:
    doctor            check the ROS 2 environment and run a live pub/sub round trip
    build WS [ARGS]   run the real ``colcon build`` in workspace WS with the right environment
    repair-wheels     make the pip-installed ROS 2 CMake files usable in this environment
    install-ros2      put the course's `ros2` command into this environment (pip install only)
    underlay          write local_setup.{sh,bash,zsh} into this environment (a ROS underlay)
    install-robot     build tf2_msgs (not on PyPI) and install the simulated robot's ROS package
                      robot_sim into this environment (pip install only)
    env               print the notebook session's ROS variables as shell exports
                      (eval "$(python -m course_lib env)"; make lab does it for JupyterLab)
"""

from __future__ import annotations

import sys

USAGE = __doc__.split("Commands:")[1]


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv or argv[0] in ("-h", "--help", "help"):
        print("usage: python -m course_lib COMMAND\n\ncommands:" + USAGE)
        return 0 if argv else 2
    command, rest = argv[0], argv[1:]
    if command == "doctor":
        from course_lib.notebook import doctor
        return doctor.main(rest)
    if command == "build":
        from course_lib.ros import colcon
        return colcon.main_build(rest)
    if command == "env":
        from course_lib.ros import rosenv
        return rosenv.main_env(rest)
    if command == "repair-wheels":
        from course_lib.ros import wheelfix
        return wheelfix.main(rest)
    if command == "underlay":
        from course_lib.ros import underlay
        return underlay.main(rest)
    if command == "install-robot":
        from course_lib.robot import install
        return install.main(rest)
    if command == "install-ros2":
        from course_lib.ros2cli import install
        return install.main(rest)
    print(f"unknown command {command!r}; commands:{USAGE}", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main())
