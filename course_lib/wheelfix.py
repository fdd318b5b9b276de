"""Repair the pip-installed ROS 2 CMake files so colcon can build interface packages (issue 3)."""

import sys


def main(argv=None) -> int:
    print("repair-wheels: not implemented yet", file=sys.stderr)
    return 0
