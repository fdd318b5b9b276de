"""``ros2 COMMAND ...``: pick the command's module and turn its outcome into an exit code."""

from __future__ import annotations

import argparse
import importlib
import os
import signal
import sys
import threading

from course_lib.ros2cli.common import FULL_INSTALL, Unsupported, unsupported

#: The commands the course's ros2 has, with ros2cli's help line for each.
COMMANDS = {
    "action": "Various action related sub-commands",
    "bag": "Various rosbag related sub-commands",
    "daemon": "Various daemon related sub-commands",
    "doctor": "Check ROS setup and other potential issues",
    "interface": "Show information about ROS interfaces",
    "launch": "Run a launch file",
    "node": "Various node related sub-commands",
    "param": "Various param related sub-commands",
    "pkg": "Various package related sub-commands",
    "run": "Run a package specific executable",
    "service": "Various service related sub-commands",
    "topic": "Various topic related sub-commands",
    "wtf": "Use `wtf` as alias to `doctor`",
}

#: Commands that run another command's module, as ros2doctor's `wtf` runs `doctor`.
ALIASES = {"wtf": "doctor"}

#: Commands of a full ros2cli install that the course's ros2 leaves out (named in --help).
LEFT_OUT = ("component", "lifecycle", "multicast")


#: ros2cli's one option before the command (Jazzy), with its help text.
BUFFERING_OPTION = "--use-python-default-buffering"
BUFFERING_HELP = ("Do not force line buffering in stdout and instead use the python default buffering, which might "
                  "be affected by PYTHONUNBUFFERED/-u and depends on whatever stdout is interactive or not")


def parser() -> argparse.ArgumentParser:
    """The top-level parser, laid out as ros2cli's: usage, description, options, the Commands
    section (its "Call ..." line last); what the course's ros2 leaves out follows, as an epilog."""
    top = argparse.ArgumentParser(
        prog="ros2", description="ros2 is an extensible command-line tool for ROS 2.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=f"This is the course's ros2 for the pip install of ROS 2 (course_lib.ros2cli): the commands above,\n"
               f"with the verbs and options the course teaches; {FULL_INSTALL}\n({', '.join(LEFT_OUT)}).")
    top.add_argument(BUFFERING_OPTION, action="store_true", default=False, help=BUFFERING_HELP)
    width = max(map(len, COMMANDS))
    commands = top.add_subparsers(
        title="Commands", description="".join(f"{name.ljust(width)}  {text}\n" for name, text in COMMANDS.items()),
        metavar="Call `ros2 <command> -h` for more detailed usage.", dest=" command")
    for name in COMMANDS:
        commands.add_parser(name, add_help=False)
    return top


def usage() -> str:
    return parser().format_help().rstrip("\n")


def main(argv: list[str] | None = None) -> int:
    """Run ``ros2`` with ``argv`` (sys.argv[1:] when None) and return its exit code.

    Like ros2cli: a verb's failure message goes to stderr with exit code 1, Ctrl-C ends with
    exit code 2 (ros2cli returns signal.SIGINT) and no traceback, and anything the course's
    ros2 does not support is one line on stderr (exit code 2).
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == [BUFFERING_OPTION]:
        argv = argv[1:]
    else:
        try:
            sys.stdout.reconfigure(line_buffering=True)  # ros2cli prints line by line, also into pipes
        except AttributeError:  # stdout replaced by something without reconfigure (a notebook)
            pass
    previous = _handle_signals()
    try:
        outcome = _dispatch(argv)
    except Unsupported as error:
        print(error, file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return int(signal.SIGINT)
    except Terminated:
        return int(signal.SIGTERM)
    except SystemExit as end:  # argparse's --help and usage errors
        return end.code if isinstance(end.code, int) else (0 if end.code is None else 1)
    except BrokenPipeError:  # `ros2 topic echo /t | head -3`: the reader has gone
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no error at exit's flush
        return 0
    except (RuntimeError, LookupError, ValueError, TimeoutError, FileNotFoundError) as error:
        interrupted = _interruption(error)
        if interrupted is not None:  # Ctrl-C came first; cleaning up after it failed
            return interrupted
        outcome = str(error)
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
    if isinstance(outcome, str):
        print(outcome, file=sys.stderr)
        return 1
    return outcome or 0


def _interruption(error: BaseException) -> int | None:
    """The exit code of the signal during whose handling ``error`` was raised, or None.

    Ctrl-C raises KeyboardInterrupt wherever the verb is; unwinding, the verb unsubscribes and
    destroys what it made, and rclpy may refuse that half-way ("cannot use Destroyable because
    destruction was requested", seen once in about 50 runs of ``ros2 topic bw`` stopped by Ctrl-C
    on a busy machine). The new error then replaces the KeyboardInterrupt, which Python keeps as
    its ``__context__``: the command was still ended by the signal (ros2cli's exit code 2)."""
    while error is not None:  # Python breaks cycles when it sets __context__
        if isinstance(error, KeyboardInterrupt):
            return int(signal.SIGINT)
        if isinstance(error, Terminated):
            return int(signal.SIGTERM)
        error = error.__context__
    return None


class Terminated(Exception):
    """SIGTERM reached the command (ros2cli ends with exit code 15 then, like rclpy's shutdown)."""


def _terminated(_number, _frame):
    raise Terminated


def _handle_signals() -> dict:
    """Make SIGINT raise KeyboardInterrupt and SIGTERM Terminated, whatever this process
    inherited: started with ``&`` from a script, it inherits SIGINT ignored, and Python then
    gives it no KeyboardInterrupt (ros2cli's rclpy installs its handlers the same way). The
    previous handlers, to put back; none where signals cannot be handled (not the main thread)."""
    if threading.current_thread() is not threading.main_thread():
        return {}
    return {signal.SIGINT: signal.signal(signal.SIGINT, signal.default_int_handler),
            signal.SIGTERM: signal.signal(signal.SIGTERM, _terminated)}


def _dispatch(argv: list[str]) -> int | str | None:
    if not argv or argv[0] in ("-h", "--help"):
        print(usage())
        return 0
    command, rest = argv[0], argv[1:]
    if command.startswith("-"):
        raise unsupported(f"ros2 {command}", ["-h", "--help", BUFFERING_OPTION])
    if command not in COMMANDS:
        raise unsupported(f"ros2 {command}", sorted(COMMANDS))
    module = importlib.import_module(f"course_lib.ros2cli.{ALIASES.get(command, command)}")
    return module.main(rest, prog=f"ros2 {command}") if command in ALIASES else module.main(rest)
