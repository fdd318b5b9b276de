"""``ros2 launch PKG FILE [name:=value ...]`` and ``ros2 launch PATH [name:=value ...]``.

The ``ros2`` command calls ``main(argv)`` with what follows the word ``launch``; ``python -m
course_lib.launch`` does the same. Flags, messages and exit codes follow ros2launch; flags it
has that this one does not are refused in one line that names those it has.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
from pathlib import Path

from ament_index_python import get_search_paths

from course_lib.launch import actions, parser, substitutions
from course_lib.launch.entities import LaunchFileError
from course_lib.launch.runner import Launch, find_in_package
from course_lib.ros import ament

_NOT_SUPPORTED = {"print": "-p/--print", "launch_prefix": "--launch-prefix",
                  "launch_prefix_filter": "--launch-prefix-filter", "debug": "-d/--debug"}
_SUPPORTED = "-s/--show-args, -a/--show-all-subprocesses-output, -n/--noninteractive"


def _argument_parser() -> argparse.ArgumentParser:
    arguments = argparse.ArgumentParser(prog="ros2 launch", description="Run a launch file")
    arguments.add_argument("-n", "--noninteractive", action="store_true",
                           help="Run the launch system non-interactively, with no terminal associated")
    arguments.add_argument("-d", "--debug", action="store_true", help=argparse.SUPPRESS)
    group = arguments.add_mutually_exclusive_group()
    group.add_argument("-p", "--print", "--print-description", action="store_true", help=argparse.SUPPRESS)
    group.add_argument("-s", "--show-args", "--show-arguments", action="store_true",
                       help="Show arguments that may be given to the launch file.")
    arguments.add_argument("-a", "--show-all-subprocesses-output", action="store_true",
                           help="Show all launched subprocesses' output (as if each had output=\"both\").")
    arguments.add_argument("--launch-prefix", help=argparse.SUPPRESS)
    arguments.add_argument("--launch-prefix-filter", help=argparse.SUPPRESS)
    arguments.add_argument("package_name", help="Name of the ROS package which contains the launch file "
                                                "(or the path of a launch file)")
    arguments.add_argument("launch_file_name", nargs="?", help="Name of the launch file")
    arguments.add_argument("launch_arguments", nargs="*",
                           help="Arguments to the launch file; '<name>:=<value>' (for duplicates, last one wins)")
    return arguments


class PackageNotFound(LookupError):
    """``ros2 launch PKG FILE`` names a package that is not installed."""

    def __init__(self, package: str):
        super().__init__(package)
        self.package = package


def parse_launch_arguments(texts: list[str]) -> dict[str, str]:
    """{name: value} of ``name:=value`` texts (the last of a name wins).

    Raises:
        ValueError: a text not in that form (the message shows the form).
    """
    parsed = {}
    for text in texts:
        count = text.count(":=")
        if count == 0 or text.startswith(":=") or (count == 1 and text.endswith(":=")):
            raise ValueError(f"malformed launch argument '{text}', expected format '<name>:=<value>'")
        name, value = text.split(":=", 1)
        parsed[name] = value
    return parsed


def print_arguments(path) -> None:
    """``ros2 launch -s``: the file's arguments, with descriptions and defaults, as ros2launch prints them."""
    description = parser.load_description(path)
    declared = actions.declared_arguments(description, None, Path(os.path.abspath(path)))
    print("Arguments (pass arguments as '<name>:=<value>'):")
    for argument, _passed, conditional in declared:
        text = f"\n    '{argument.name}':{'*' if conditional else ''}\n        "
        text += argument.description
        if argument.default is not None:
            text += f"\n        (default: {substitutions.describe(argument.default)})"
        print(text)
    if not declared:
        print("\n  No arguments.")
    elif any(conditional for _, _, conditional in declared):
        print("\n* argument(s) which are only used if specific conditions occur")


def main(argv: list[str] | None = None) -> int:
    """Run ``ros2 launch`` with these arguments (those after the word ``launch``); the exit code."""
    options = _argument_parser().parse_args(sys.argv[1:] if argv is None else argv)
    for option, flag in _NOT_SUPPORTED.items():
        if getattr(options, option):
            print(f"ros2 launch: {flag} is not supported by the course's ros2 launch (it supports {_SUPPORTED}); "
                  "a full ROS 2 install has it", file=sys.stderr)
            return 2
    texts = list(options.launch_arguments)
    try:
        if os.path.isfile(options.package_name):
            path = options.package_name
            if options.launch_file_name is not None:
                texts.insert(0, options.launch_file_name)
        elif options.launch_file_name is None:
            if options.package_name not in ament.packages():
                raise PackageNotFound(options.package_name)
            print(f"ros2 launch: no launch file '{options.package_name}' here; give a launch file's path, or a "
                  "package name and the name of a launch file in it", file=sys.stderr)
            return 1
        else:
            if options.package_name not in ament.packages():
                raise PackageNotFound(options.package_name)
            path = find_in_package(options.package_name, options.launch_file_name)
        arguments = parse_launch_arguments(texts)
        if options.show_args:
            print_arguments(path)
            return 0
    except PackageNotFound as error:  # ros2launch's words, with ament_index_python's
        print(f"Package '{error.package}' not found: package '{error.package}' not found, searching: "
              f"{get_search_paths()}", file=sys.stderr)
        return 1
    except (LookupError, FileNotFoundError, ValueError, LaunchFileError) as error:
        print(error, file=sys.stderr)
        return 1
    return run(path, arguments, force_output="both" if options.show_all_subprocesses_output else None,
               noninteractive=options.noninteractive)


def run(path, arguments: dict, force_output: str | None = None, noninteractive: bool = False) -> int:
    """Run a launch file in the foreground until its processes end or a signal stops it; the
    exit code (0, or 1 after a launch file error or SIGTERM/SIGQUIT, as ros2 launch).

    Like ros2 launch, it handles SIGINT, SIGTERM and SIGQUIT itself, whatever it inherited: a
    program started with ``&`` from a script inherits SIGINT ignored, and Python then gives it
    no KeyboardInterrupt. SIGINT stops the processes (launch.Launch.stop: SIGINT, SIGTERM,
    SIGKILL, each in its time); a second one is logged and ignored.
    """
    received: list[int] = []
    launch = Launch(path, arguments, screen=lambda line: print(line, flush=True), force_output=force_output)

    def on_signal(number, _frame):
        _log_signal(launch, number, again=number == signal.SIGINT and signal.SIGINT in received)
        received.append(number)

    handled = (signal.SIGINT, signal.SIGTERM, signal.SIGQUIT)
    previous = {number: signal.signal(number, on_signal) for number in handled}
    try:
        try:
            launch.prepare()
        except LaunchFileError as error:
            launch.error("launch", f"Caught exception in launch (see debug for traceback): {error}")
            launch.stop()
            return 1
        launch.start()
        while not received and not launch.wait(0.1):
            pass
        launch.stop(announce_sigint=noninteractive or received[:1] != [signal.SIGINT])
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
    return 1 if received and received[0] != signal.SIGINT else 0


def _log_signal(launch: Launch, number: int, again: bool) -> None:
    """ros2 launch's log lines for a signal it received."""
    if number == signal.SIGINT:
        launch.warning("launch", "user interrupted with ctrl-c (SIGINT)" + (" again, ignoring..." if again else ""))
        return
    name = signal.Signals(number).name
    launch.error("launch", f"user interrupted with ctrl-\\ ({name}), terminating...")
    launch.error("launch", f"using {name} can result in orphaned processes")
    launch.error("launch", "make sure no processes launched are still running")
