"""``ros2 run PKG EXECUTABLE [args...]``: start a package's executable in place of ros2.

The executable replaces this process (exec), so Ctrl-C, a SIGINT from a launcher and the exit
code all belong to the node itself, with nothing in between.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys

from course_lib.ros2cli.common import VerbParser


def main(argv: list[str]) -> int | str:
    parser = VerbParser(prog="ros2 run", description="Run a package specific executable")
    parser.add_argument("package_name", help="Name of the ROS package")
    parser.add_argument("executable_name", help="Name of the executable")
    parser.add_argument("argv", nargs=argparse.REMAINDER,
                        help="Pass arbitrary arguments to the executable")
    args = parser.parse_args(argv)
    from course_lib.ros import ament

    if args.package_name not in ament.packages():
        return f"Package '{args.package_name}' not found"  # ros2run's words
    try:
        path = ament.executable(args.package_name, args.executable_name)
    except ament.NoExecutable:
        return "No executable found"
    sys.stdout.flush()
    sys.stderr.flush()
    # exec keeps an ignored signal ignored: started with `&` from a script, ros2 inherited SIGINT
    # ignored, and the node would never see Ctrl-C or `kill -INT`. It starts with the defaults.
    for number in (signal.SIGINT, signal.SIGTERM):
        signal.signal(number, signal.SIG_DFL)
    os.execv(path, [str(path), *args.argv])
