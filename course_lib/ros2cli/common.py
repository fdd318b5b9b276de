"""What every verb of the course's ``ros2`` shares: argument parsing that names what is not
supported in one line, ros2cli's discovery options, QoS options, and waiting until Ctrl-C."""

from __future__ import annotations

import argparse
import contextlib
import signal
import sys
import threading
import typing

#: The end of every "not supported" line.
FULL_INSTALL = "a full ROS 2 install (ros2cli) has more"

#: ros2cli's default --spin-time: how long a daemon-less ros2 spins before it answers.
DEFAULT_SPIN_TIME = 0.5

#: Seconds the graph must stay unchanged before a listing verb answers.
QUIET_SECONDS = 0.2

#: Seconds after its start up to which a listing verb waits for the nodes of the other ROS
#: processes on this machine (course_lib.ros.discovery.wait_for_discovery counts them; longer on a
#: busy machine).
COMPLETE_SECONDS = 4.0

#: Seconds discovery may take in a new process at most: the backstop of the discovery wait
#: (course_lib.ros.discovery), which ends as soon as the graph has stopped changing.
DISCOVERY_BACKSTOP = 5


class Unsupported(Exception):
    """A command, verb or option the course's ros2 does not have; str() is the one line to print."""


def unsupported(what: str, supported) -> Unsupported:
    return Unsupported(f"{what} is not supported by the course's ros2 (it supports: "
                       f"{', '.join(supported)}); {FULL_INSTALL}")


class Verb(typing.NamedTuple):
    """One verb of a command: its help line, the function adding its arguments, its main."""

    help: str
    add_arguments: typing.Callable[[argparse.ArgumentParser], None]
    main: typing.Callable[[argparse.Namespace], int | str | None]


class VerbParser(argparse.ArgumentParser):
    """An ArgumentParser whose unknown options raise Unsupported instead of a usage error."""

    def parse_args(self, args=None, namespace=None):
        parsed, extra = self.parse_known_args(args, namespace)
        options = [item for item in extra if item.startswith("-") and item != "-"]
        if options:
            raise unsupported(f"{self.prog}: {options[0].split('=')[0]}", self.supported_options())
        if extra:
            self.error(f"unrecognized arguments: {' '.join(extra)}")
        return parsed

    def supported_options(self) -> list[str]:
        return [" ".join(action.option_strings) for action in self._actions
                if action.option_strings and action.dest != "help"]


def run_group(prog: str, description: str, verbs: dict[str, Verb], argv: list[str],
              missing: typing.Iterable[str] = (), hidden_flag: str | None = None) -> int | str | None:
    """Parse ``argv`` (what follows ``ros2 COMMAND``) and run the chosen verb.

    Args:
        prog: "ros2 topic".
        description: the command's help line.
        verbs: the verbs the course supports.
        argv: the verb and its arguments.
        missing: verbs of the real ros2cli command that the course leaves out (for --help).
        hidden_flag: the command's own option that shows hidden names, given before the verb
            (``ros2 service --include-hidden-services type /_x``), if it has one.
    """
    defaults = {}
    if hidden_flag and argv and argv[0] == hidden_flag:
        defaults[hidden_flag.lstrip("-").replace("-", "_")] = True
        argv = argv[1:]
    if not argv or argv[0] in ("-h", "--help"):
        width = max(len(name) for name in verbs)
        lines = [f"usage: {prog} [-h] Call `{prog} <command> -h` for more detailed usage. ...", "",
                 description, "", "options:", "  -h, --help  show this help message and exit", "",
                 "Commands:"]
        lines += [f"  {name.ljust(width)}  {verb.help}" for name, verb in sorted(verbs.items())]
        lines += ["", f"  Call `{prog} <command> -h` for more detailed usage.", ""]
        if missing:
            lines.append(f"The course's ros2 has these; {FULL_INSTALL} ({', '.join(missing)}).")
        print("\n".join(lines))
        return 0
    name, rest = argv[0], argv[1:]
    if name not in verbs:
        raise unsupported(f"{prog} {name}", sorted(verbs))
    verb = verbs[name]
    parser = VerbParser(prog=f"{prog} {name}", description=verb.help)
    verb.add_arguments(parser)
    parser.set_defaults(**defaults)
    return verb.main(parser.parse_args(rest))


def print_names(pairs: list[tuple[str, list[str]]], show_types: bool, count: bool) -> None:
    """(name, [type, ...]) pairs as ros2cli's list verbs print them: how many (-c), or each name,
    followed by its types in brackets (-t)."""
    if count:
        print(len(pairs))
        return
    for name, kinds in pairs:
        print(f"{name} [{', '.join(kinds)}]" if show_types else name)


def print_types(kinds: list[str]) -> int:
    """The types of one name as ros2cli's type verbs print them; exit code 1 (nothing printed)
    when the name is unknown."""
    for kind in kinds:
        print(kind)
    return 0 if kinds else 1


def print_types_of(name: str, pairs: typing.Callable[[], list[tuple[str, list[str]]]], spin_time: float) -> int:
    """ros2cli's type verbs (topic, service, action): wait until `name` shows among the (name,
    [type, ...]) `pairs()` or discovery has settled (wait_for_name), then print_types of it."""
    def kinds() -> list[str]:
        return dict(pairs()).get(name, [])

    wait_for_name(lambda: bool(kinds()), spin_time)
    return print_types(kinds())


def print_names_of_type(pairs: list[tuple[str, list[str]]], type_name: str, count: bool) -> None:
    """ros2cli's find verbs: the names whose types include `type_name`, or how many (-c)."""
    print_names([(name, kinds) for name, kinds in pairs if type_name in kinds], False, count)


# --- argument types (ros2topic's) ------------------------------------------------------

def positive_float(text: str) -> float:
    """An argparse type: a number above 0, in ros2topic's words when it is not."""
    import argparse

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError("Expects a floating point number") from None
    if value <= 0:
        raise argparse.ArgumentTypeError("Value must be positive")
    return value


def positive_int(text: str) -> int:
    """An argparse type: a whole number above 0."""
    import argparse

    try:
        value = int(text)
    except ValueError:
        value = -1
    if value <= 0:
        raise argparse.ArgumentTypeError("value must be a positive integer")
    return value


def nonnegative_int(text: str) -> int:
    """An argparse type: a whole number, 0 or more."""
    value = int(text)
    if value < 0:
        raise ValueError("Value must be positive or zero")
    return value


# --- discovery ----------------------------------------------------------------------------

def add_discovery_arguments(parser: argparse.ArgumentParser, daemon: bool = True) -> None:
    """ros2cli's node options: --spin-time and (where ros2cli has it) --no-daemon."""
    parser.add_argument(
        "--spin-time", type=float, default=DEFAULT_SPIN_TIME,
        help="Spin time in seconds to wait for discovery (only applies when not using an already running daemon)"
        if daemon else "Spin time in seconds to wait for discovery (default: %(default)s)")
    if daemon:
        parser.add_argument("--no-daemon", action="store_true", help="Do not spawn nor use an already running daemon")


def wait_for_whole_graph(spin_time: float) -> None:
    """Before a verb that lists the graph: wait for discovery the way ros2cli without its daemon
    does, spinning ``spin_time`` seconds, and longer where that would answer too early.

    Longer: until the graph has not changed for a moment, and, up to COMPLETE_SECONDS, until
    the nodes of every other ROS process on this machine show (on a busy machine a new process
    can take seconds to discover them all).
    """
    from course_lib.ros import discovery

    discovery.wait_for_discovery(minimum=spin_time, quiet=min(QUIET_SECONDS, spin_time),
                                 complete_within=COMPLETE_SECONDS)


def wait_for_name(shown: typing.Callable[[], bool], spin_time: float, timeout: float = 0.0) -> bool:
    """Before a verb that names a node or topic: wait until ``shown()``, or until discovery has
    settled (the graph no longer changes and every other ROS process here has shown its nodes)
    and ``spin_time`` + ``timeout`` seconds have passed, as ros2cli spins --spin-time and then
    waits --timeout for a node. An unknown name fails as soon as that, not after a fixed wait.

    Returns:
        shown(), at the end of the wait.
    """
    from course_lib.ros import discovery

    discovery.wait_for_discovery(minimum=spin_time + timeout, quiet=min(QUIET_SECONDS, spin_time),
                                 complete_within=COMPLETE_SECONDS, until=shown)
    return bool(shown())


def wait_for_nothing() -> None:
    """Before a verb that needs nothing from the graph to begin (a type was given): no wait."""
    from course_lib.ros import discovery

    discovery.wait_for_discovery(minimum=0.0, quiet=0.0, complete_within=0.0)


# --- QoS options (ros2 topic echo / pub) -------------------------------------------------

def add_qos_arguments(parser: argparse.ArgumentParser, verb: str, default_profile: str) -> None:
    """--qos-profile, --qos-depth, --qos-history, --qos-reliability, --qos-durability."""
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSPresetProfiles, ReliabilityPolicy

    parser.add_argument("--qos-profile", default=default_profile, choices=QoSPresetProfiles.short_keys(),
                        help=f"Quality of service preset profile to {verb} with (default: {default_profile})")
    parser.add_argument("--qos-depth", metavar="N", type=int, help=f"Queue size setting to {verb} with")
    parser.add_argument("--qos-history", choices=HistoryPolicy.short_keys(),
                        help=f"History of samples setting to {verb} with")
    parser.add_argument("--qos-reliability", choices=ReliabilityPolicy.short_keys(),
                        help=f"Quality of service reliability setting to {verb} with")
    parser.add_argument("--qos-durability", choices=DurabilityPolicy.short_keys(),
                        help=f"Quality of service durability setting to {verb} with")


def qos_overridden(args: argparse.Namespace) -> bool:
    return any(getattr(args, name) is not None
               for name in ("qos_depth", "qos_history", "qos_reliability", "qos_durability"))


def qos_from_arguments(args: argparse.Namespace):
    """The QoS profile the --qos-* options describe (a preset with overrides), as ros2cli builds it."""
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSPresetProfiles, ReliabilityPolicy

    profile = QoSPresetProfiles.get_from_short_key(args.qos_profile)
    if args.qos_history:
        profile.history = HistoryPolicy.get_from_short_key(args.qos_history)
    if args.qos_reliability:
        profile.reliability = ReliabilityPolicy.get_from_short_key(args.qos_reliability)
    if args.qos_durability:
        profile.durability = DurabilityPolicy.get_from_short_key(args.qos_durability)
    if args.qos_depth is not None and args.qos_depth >= 0:
        profile.depth = args.qos_depth
    elif profile.durability == DurabilityPolicy.TRANSIENT_LOCAL and profile.depth == 0:
        profile.depth = 1
    return profile


# --- running until Ctrl-C ----------------------------------------------------------------

def loop_limit(seconds: float | None) -> float | None:
    """How long a wait that the user bounds to ``seconds`` (None: until Ctrl-C) may last.

    Live, just ``seconds``. Under the test suite or the grader, also at most
    course_lib.ros.run_limits.time_limit after the DISCOVERY_BACKSTOP that discovery may take in a new
    process, so that a ``!ros2 topic hz`` cell cannot hang a notebook run.
    """
    from course_lib.ros.run_limits import time_limit

    limit = time_limit(seconds)
    return limit + DISCOVERY_BACKSTOP if limit is not None and limit != seconds else limit


def wait_until(done: typing.Callable[[], bool], seconds: float | None = None) -> bool:
    """Wait until ``done()`` or ``seconds`` pass (None: until Ctrl-C), within loop_limit."""
    from course_lib.ros import session

    return session.wait_for(done, timeout=loop_limit(seconds), poll=0.02)


def wait_for_answer(done: typing.Callable[[], bool]) -> bool:
    """Wait until ``done()``: the answer of a server this verb has found. Live, as long as it
    takes (Ctrl-C ends it); under grading within the loop limit, as every wait; under test within
    course_lib.ros.run_limits.answer_limit (the loop limit, about 7 s, could decide a test on a busy
    machine)."""
    from course_lib.ros import session
    from course_lib.ros.run_limits import answer_limit

    return session.wait_for(done, timeout=answer_limit(loop_limit(None)), poll=0.02)


@contextlib.contextmanager
def signals_received(numbers=(signal.SIGINT, signal.SIGTERM)):
    """While the block runs, the signals ``numbers`` are noted, not raised: the block yields the
    list they are appended to, and a verb polls it to end cleanly (close a bag) the way rosbag2
    defers Ctrl-C and SIGTERM. Whatever this process inherited: started with ``&`` from a script
    it has SIGINT ignored, and the verb must stop all the same. The previous handlers come back
    at the end (nothing is handled outside the main thread, where Python cannot)."""
    received: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield received
        return
    previous = {number: signal.signal(number, lambda number, _frame: received.append(number))
                for number in numbers}
    try:
        yield received
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)


def say(text: str = "", error: bool = False) -> None:
    """Print a line as ros2cli does (stdout, or stderr for failures)."""
    print(text, file=sys.stderr if error else sys.stdout)
