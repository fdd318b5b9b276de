"""``ros2 topic list|echo|hz|bw|delay|info|type|find|pub``, from course_lib.ros.graph and its tool node."""

from __future__ import annotations

import time

from course_lib.ros2cli.common import (
    DISCOVERY_BACKSTOP,
    Verb,
    add_discovery_arguments,
    add_qos_arguments,
    loop_limit,
    print_names,
    print_names_of_type,
    print_types,
    print_types_of,
    qos_from_arguments,
    qos_overridden,
    run_group,
    say,
    wait_for_name,
    wait_for_nothing,
    wait_for_whole_graph,
    wait_until,
)
from course_lib.ros2cli.common import nonnegative_int as _nonnegative_int
from course_lib.ros2cli.common import positive_float as _positive_float
from course_lib.ros2cli.common import positive_int as _positive_int

#: Verbs of ros2cli's ``ros2 topic`` that the course leaves out.
LEFT_OUT = ()
#: ros2topic's default --window of ``bw`` and of ``delay``.
BW_WINDOW = 100
DELAY_WINDOW = 10000
#: Seconds ``ros2 topic pub`` waits at most, after its last message, for reliable subscriptions
#: to acknowledge what it sent (it ends as soon as they have).
ACK_SECONDS = 10.0


def _topic_shown(topic: str):
    """A function telling whether the graph shows ``topic`` (hidden or not) with its type."""
    from course_lib.ros import graph, session

    name = session.tool_node().resolve_topic_name(topic)
    return lambda: any(other == name for other in graph.topic_list(include_hidden=True))


def _daemon_says_not_shown(args) -> bool:
    """True when the daemon answers and its graph has no topic ``args.topic_name``: a verb that
    needs the topic's type fails at once (ros2cli's echo asks its daemon for it)."""
    from course_lib.ros2cli import daemon

    return daemon.graph_answer(args, "topic_shown", name=args.topic_name) is False


def _not_published_yet(topic: str) -> None:
    say(f"WARNING: topic [{topic}] does not appear to be published yet")


# --- ros2 topic list ---------------------------------------------------------------------

def _list_arguments(parser) -> None:
    add_discovery_arguments(parser)
    parser.add_argument("-t", "--show-types", action="store_true", help="Additionally show the topic type")
    parser.add_argument("-c", "--count-topics", action="store_true",
                        help="Only display the number of topics discovered")
    parser.add_argument("--include-hidden-topics", action="store_true", help="Consider hidden topics as well")
    parser.add_argument("-v", "--verbose", action="store_true", help="List full details about each topic")


def _topic_pairs(args, include_hidden: bool) -> list[tuple[str, list[str]]]:
    """(name, [type, ...]) of every topic, from the daemon, else after discovery in this process."""
    from course_lib.ros2cli import daemon

    pairs = daemon.graph_answer(args, "topics", include_hidden=include_hidden)
    if pairs is not daemon.DIRECT:
        return [(name, kinds) for name, kinds in pairs]
    from course_lib.ros import graph

    wait_for_whole_graph(args.spin_time)
    return graph.topic_list(types=True, include_hidden=include_hidden)


def _topic_info(args, name: str, verbose: bool, settled: bool = False):
    """The graph_info.TopicInfo of topic ``name``, from the daemon, else from this process's graph
    (after discovery unless ``settled``: waited for already); None when the graph has no such topic."""
    from course_lib.ros import graph
    from course_lib.ros2cli import daemon

    answer = daemon.graph_answer(args, "topic_info", name=name, verbose=verbose)
    if answer is not daemon.DIRECT:
        return None if answer is None else daemon.topic_info_of(answer)
    if not settled:
        wait_for_whole_graph(args.spin_time)  # counts and endpoints: all of them, not the first found
    if not _topic_shown(name)():
        return None
    # The wait is for the endpoints' node names, which DDS may announce a moment after them.
    return graph.topic_info(name, verbose=verbose, timeout=args.spin_time + DISCOVERY_BACKSTOP)


def _list(args) -> None:
    pairs = _topic_pairs(args, args.include_hidden_topics)
    if pairs and args.verbose and not args.count_topics:
        counts = {name: _topic_info(args, name, verbose=False, settled=True) for name, _ in pairs}
        for title, count_of, noun in (("Published", "publisher_count", "publisher"),
                                      ("Subscribed", "subscription_count", "subscriber")):
            print(f"{title} topics:")
            for name, kinds in pairs:
                count = getattr(counts[name], count_of)
                if count:
                    print(f" * {name} [{', '.join(kinds)}] {count} {noun}{'s' if count > 1 else ''}")
            print()
    else:
        print_names(pairs, args.show_types, args.count_topics)


# --- ros2 topic echo ---------------------------------------------------------------------

def _echo_arguments(parser) -> None:
    add_discovery_arguments(parser)
    parser.add_argument("topic_name", help="Name of the ROS topic to listen to (e.g. '/chatter')")
    parser.add_argument("message_type", nargs="?", help="Type of the ROS message (e.g. 'std_msgs/msg/String')")
    add_qos_arguments(parser, "subscribe", "sensor_data")
    parser.add_argument("--field", help="Echo a selected field of a message. Use '.' to select sub-fields")
    parser.add_argument("--full-length", "-f", action="store_true",
                        help="Output all elements for arrays, bytes, and strings")
    parser.add_argument("--truncate-length", "-l", type=_nonnegative_int, default=128,
                        help="The length to truncate arrays, bytes, and string to (default: 128)")
    parser.add_argument("--no-arr", action="store_true", help="Don't print array fields of messages")
    parser.add_argument("--no-str", action="store_true", help="Don't print string fields of messages")
    parser.add_argument("--no-lost-messages", action="store_true",
                        help="Don't report when a message is lost (the course's ros2 never does)")
    parser.add_argument("--once", action="store_true", help="Print the first message received and then exit.")
    parser.add_argument("--timeout", metavar="N", type=_positive_float,
                        help="Set a timeout in seconds for waiting")


def _echo(args) -> int | str | None:
    from course_lib.ros import graph, message_yaml

    field = None if args.field is None else [part for part in args.field.split(".") if part]
    if field == []:
        return f"Invalid field value '{args.field}'"
    if args.message_type is not None:
        wait_for_nothing()
        try:
            message_yaml.message_class(args.message_type)
        except ValueError:
            return "The passed message type is invalid"
    elif _daemon_says_not_shown(args) or not wait_for_name(_topic_shown(args.topic_name), args.spin_time):
        _not_published_yet(args.topic_name)
        return "Could not determine the type for the passed topic"
    truncate = None if args.full_length else args.truncate_length
    seen = {"messages": 0, "bad field": False}  # counts only: an echo may run for hours

    def show(msg):
        if seen["bad field"] or (seen["messages"] and args.once):
            return
        for part in field or ():
            try:
                msg = getattr(msg, part)
            except AttributeError as error:
                say(f"Invalid field '{'.'.join(field)}': {error}", error=True)
                seen["bad field"] = True
                return
        seen["messages"] += 1
        if hasattr(msg, "get_fields_and_field_types"):
            print(message_yaml.format_message(msg, truncate, args.no_arr, args.no_str), end="---\n")
        else:
            print(msg, end="\n---\n")

    qos = qos_from_arguments(args) if qos_overridden(args) else None  # None: what the publishers offer
    with graph.subscription(args.topic_name, show, args.message_type, 0.0, qos):
        wait_until(lambda: seen["bad field"] or (args.once and seen["messages"] > 0), args.timeout)
    return 1 if seen["bad field"] else None


# --- ros2 topic hz -----------------------------------------------------------------------

def _hz_arguments(parser) -> None:
    parser.add_argument("topic_name", help="Name of the ROS topic to listen to (e.g. '/chatter')")
    parser.add_argument("--window", "-w", dest="window_size", type=_positive_int, default=10000, metavar="WINDOW",
                        help="window size, in # of messages, for calculating rate (default: 10000)")
    parser.add_argument("--wall-time", action="store_true",
                        help="calculates rate using wall time (the course's ros2 always does)")
    add_discovery_arguments(parser, daemon=False)


def _hz(args) -> None:
    from rclpy.qos import qos_profile_sensor_data

    from course_lib.ros import graph, rates

    shown = wait_for_name(_topic_shown(args.topic_name), args.spin_time)
    arrivals: list[float] = []
    printed_at = [None]

    def report() -> bool:
        # Like ros2cli: from the second message on, print once a second while messages come.
        del arrivals[:-(args.window_size + 1)]
        if len(arrivals) < 2:
            return False
        if printed_at[0] is None:
            printed_at[0] = arrivals[0]
        if arrivals[-1] >= printed_at[0] + 1.0:
            print(rates.rate_statistics(list(arrivals)))
            printed_at[0] = arrivals[-1]
        return False

    def measure(timeout: float | None) -> None:
        with graph.subscription(args.topic_name, lambda _: arrivals.append(time.monotonic()),
                                timeout=timeout, qos=qos_profile_sensor_data, raw=True):
            wait_until(report)

    if not shown:  # like ros2cli: say so once, then wait for the topic as long as it takes
        _not_published_yet(args.topic_name)
    measure(0.0 if shown else None)


# --- ros2 topic bw / delay ---------------------------------------------------------------

def _window_arguments(parser, default: int) -> None:
    parser.add_argument("topic", help="Topic name to monitor")
    parser.add_argument("--window", "-w", type=_positive_int, default=default, metavar="WINDOW",
                        help=f"maximum window size, in # of messages, for calculating rate (default: {default})")
    add_discovery_arguments(parser, daemon=False)


def _subscribe_for_seconds(args, callback, report, raw: bool, announce: bool) -> str | None:
    """Like ros2topic's bw and delay: find the topic's type (waiting for it as long as it takes,
    after a warning), subscribe with the sensor-data QoS and call ``report()`` once a second
    until Ctrl-C; report() may return the text of a failure that ends the verb. ``announce``:
    say "Subscribed to [TOPIC]" first (bw does)."""
    from rclpy.qos import qos_profile_sensor_data

    from course_lib.ros import graph

    shown = wait_for_name(_topic_shown(args.topic), args.spin_time)
    if not shown:
        _not_published_yet(args.topic)
    with graph.subscription(args.topic, callback, timeout=0.0 if shown else None, qos=qos_profile_sensor_data,
                            raw=raw) as name:
        if announce:
            print(f"Subscribed to [{name}]")
        limit = loop_limit(None)
        started = time.monotonic()
        while limit is None or time.monotonic() - started < limit:
            wait_until(lambda: False, 1.0)
            failure = report()
            if failure:
                return failure
    return None


def _bytes(size: float, per_second: float) -> str:
    """ros2topic bw's units: B below 1000 B/s, KB below 1 MB/s, else MB (powers of 1000)."""
    if per_second < 1000:
        return f"{size:.0f} B"
    return f"{size / 1000:.2f} KB" if per_second < 1000000 else f"{size / 1000 / 1000:.2f} MB"


def _bw(args) -> str | None:
    import collections
    import threading

    lock = threading.Lock()
    window = collections.deque(maxlen=args.window)  # (arrival, size)

    def arrived(data) -> None:
        with lock:
            window.append((time.monotonic(), len(data)))

    def report() -> None:
        with lock:
            if len(window) < 2:
                return
            sizes = [size for _, size in window]
            rate = sum(sizes) / (time.monotonic() - window[0][0])
        mean, low, high = (_bytes(value, rate) for value in (sum(sizes) / len(sizes), min(sizes), max(sizes)))
        print(f"{_bytes(rate, rate)}/s from {len(sizes)} messages\n\tMessage size mean: {mean} min: {low} max: {high}")

    return _subscribe_for_seconds(args, arrived, report, raw=True, announce=True)


def _delay(args) -> str | None:
    import math
    import threading

    from rclpy.time import Time

    from course_lib.ros import session

    clock = session.tool_node().get_clock()
    lock = threading.Lock()
    seen = {"delays": [], "first": False, "new": False, "no header": False}

    def arrived(msg) -> None:
        if not hasattr(msg, "header"):
            seen["no header"] = True
            return
        with lock:
            now = clock.now()
            if not seen["first"]:  # like ros2topic: the first message only starts the clock
                seen["first"] = True
                return
            seen["delays"] = (seen["delays"] + [(now - Time.from_msg(msg.header.stamp)).nanoseconds])[-args.window:]
            seen["new"] = True

    def report() -> str | None:
        if seen["no header"]:
            return "msg does not have header"
        with lock:
            delays, new, seen["new"] = list(seen["delays"]), seen["new"], False
        if not delays:
            return None
        if not new:
            print("no new messages")
            return None
        mean = sum(delays) / len(delays)
        deviation = math.sqrt(sum((delay - mean) ** 2 for delay in delays) / len(delays))
        print(f"average delay: {mean * 1e-9:.3f}\n\tmin: {min(delays) * 1e-9:.3f}s max: {max(delays) * 1e-9:.3f}s "
              f"std dev: {deviation * 1e-9:.5f}s window: {len(delays)}")
        return None

    return _subscribe_for_seconds(args, arrived, report, raw=False, announce=False)


# --- ros2 topic type / find --------------------------------------------------------------

def _type_arguments(parser) -> None:
    add_discovery_arguments(parser)
    parser.add_argument("topic_name", help="Name of the ROS topic to get type (e.g. '/chatter')")
    parser.set_defaults(include_hidden_topics=False)  # an option of `ros2 topic`, before the verb


def _type(args) -> int:
    from course_lib.ros import graph
    from course_lib.ros2cli import daemon

    pairs = daemon.graph_answer(args, "topics", include_hidden=args.include_hidden_topics)
    if pairs is not daemon.DIRECT:
        return print_types(dict(pairs).get(args.topic_name, []))
    return print_types_of(args.topic_name,
                          lambda: graph.topic_list(types=True, include_hidden=args.include_hidden_topics),
                          args.spin_time)


def _find_arguments(parser) -> None:
    add_discovery_arguments(parser)
    parser.add_argument("topic_type", help="Name of the ROS topic type to filter for (e.g. 'std_msg/msg/String')")
    parser.add_argument("-c", "--count-topics", action="store_true",
                        help="Only display the number of topics discovered")
    parser.add_argument("--include-hidden-topics", action="store_true", help="Consider hidden topics as well")


def _find(args) -> None:
    print_names_of_type(_topic_pairs(args, args.include_hidden_topics), args.topic_type, args.count_topics)


# --- ros2 topic info ---------------------------------------------------------------------

def _info_arguments(parser) -> None:
    add_discovery_arguments(parser)
    parser.add_argument("topic_name", help="Name of the ROS topic to get info (e.g. '/chatter')")
    parser.add_argument("--verbose", "-v", action="store_true",
                        help="Prints detailed information like the node name, node namespace, topic type, "
                             "topic type hash, GUID, and QoS Profile of the publishers and subscribers")


def _info(args) -> str | None:
    from course_lib.ros import graph_info

    info = _topic_info(args, args.topic_name, args.verbose)
    if info is None:
        return f"Unknown topic '{args.topic_name}'"
    # ros2cli ends every part (the last one too) with a blank line in verbose mode.
    print(graph_info.format_topic_info(info, verbose=args.verbose), end="\n" if args.verbose else "")
    return None


# --- ros2 topic pub ----------------------------------------------------------------------

def _pub_arguments(parser) -> None:
    parser.add_argument("topic_name", help="Name of the ROS topic to publish to (e.g. '/chatter')")
    parser.add_argument("message_type", help="Type of the ROS message (e.g. 'std_msgs/String')")
    parser.add_argument("values", nargs="?", default="{}",
                        help="Values to fill the message with in YAML format (e.g. 'data: Hello World'), "
                             "otherwise the message will be published with default values")
    parser.add_argument("-r", "--rate", metavar="N", type=_positive_float, default=1.0,
                        help="Publishing rate in Hz (default: 1)")
    parser.add_argument("-p", "--print", metavar="N", type=int, default=1,
                        help="Only print every N-th published message (default: 1)")
    once_or_times = parser.add_mutually_exclusive_group()
    once_or_times.add_argument("-1", "--once", action="store_true", help="Publish one message and exit")
    once_or_times.add_argument("-t", "--times", type=_nonnegative_int, default=0,
                               help="Publish this number of times and then exit")
    parser.add_argument("-w", "--wait-matching-subscriptions", type=_nonnegative_int, default=None,
                        help="Wait until finding the specified number of matching subscriptions. "
                             'Defaults to 1 when using "-1"/"--once"/"--times", otherwise defaults to 0.')
    parser.add_argument("--max-wait-time-secs", type=_positive_float, default=None,
                        help="The maximum wait time in seconds for --wait-matching-subscriptions")
    parser.add_argument("--keep-alive", metavar="N", type=_positive_float, default=0.1,
                        help="Keep publishing node alive for N seconds after the last msg (default: 0.1)")
    add_qos_arguments(parser, "publish", "default")
    add_discovery_arguments(parser, daemon=False)


def _pub(args) -> str | None:
    import yaml
    from rclpy.duration import Duration

    from course_lib.ros import message_yaml, session

    times = 1 if args.once else args.times
    wanted = args.wait_matching_subscriptions
    wanted = int(times != 0) if wanted is None else wanted
    if wanted == 0 and args.max_wait_time_secs is not None:
        return "--max-wait-time-secs option is only effective with --wait-matching-subscriptions, --once or --times"
    message_class = message_yaml.message_class(args.message_type)  # ValueError names the fix
    try:
        values = yaml.safe_load(args.values)
    except yaml.YAMLError as error:
        return f"The passed value is not valid YAML ({str(error).splitlines()[0]}): write it like '{{data: 5}}'"
    if not isinstance(values, dict):
        return "The passed value needs to be a dictionary in YAML format"
    msg = message_class()
    try:  # before waiting for subscribers (ros2cli fills after): a mistake shows at once
        stamp_setters = message_yaml.fill_message(msg, values)
    except ValueError as error:
        return f"Failed to populate field: {error}"
    node = session.tool_node()
    publisher = node.create_publisher(message_class, args.topic_name, qos_from_arguments(args))
    limit = loop_limit(args.max_wait_time_secs)  # None: wait as long as it takes
    started = time.monotonic()
    while publisher.get_subscription_count() < wanted:
        left = None if limit is None else limit - (time.monotonic() - started)
        if left is not None and left <= 0:
            return (f"Timed out waiting for subscribers: Expected {wanted} subcribers but only got "
                    f"{publisher.get_subscription_count()} subscribers")
        print(f"Waiting for at least {wanted} matching subscription(s)...")
        session.wait_for(lambda: publisher.get_subscription_count() >= wanted,
                         timeout=1.0 if left is None else min(1.0, left), poll=0.02)
    print("publisher: beginning loop")
    count = [0]

    def publish():
        if times and count[0] >= times:
            return
        now = node.get_clock().now().to_msg()
        for setter in stamp_setters:
            setter(now)
        count[0] += 1
        if args.print and count[0] % args.print == 0:
            print(f"publishing #{count[0]}: {msg!r}\n")
        publisher.publish(msg)

    publish()
    if times != 1:
        timer = node.create_timer(1.0 / args.rate, publish)
        try:
            wait_until(lambda: times != 0 and count[0] >= times)
        finally:
            node.destroy_timer(timer)
    # Reliable subscriptions acknowledge what was sent before the node goes. A subscription that
    # had not yet found this publisher when the message went out (the two ends discover each
    # other apart, seconds apart on a busy machine) gets it again only from a publisher that
    # still exists; ros2cli's keep-alive alone let `pub --once` end before that.
    publisher.wait_for_all_acked(Duration(seconds=ACK_SECONDS))
    time.sleep(args.keep_alive)
    node.destroy_publisher(publisher)
    return None


VERBS = {
    "bw": Verb("Display bandwidth used by topic", lambda parser: _window_arguments(parser, BW_WINDOW), _bw),
    "delay": Verb("Display delay of topic from timestamp in header",
                  lambda parser: _window_arguments(parser, DELAY_WINDOW), _delay),
    "echo": Verb("Output messages from a topic", _echo_arguments, _echo),
    "hz": Verb("Print the average publishing rate to screen", _hz_arguments, _hz),
    "info": Verb("Print information about a topic", _info_arguments, _info),
    "list": Verb("Output a list of available topics", _list_arguments, _list),
    "find": Verb("Output a list of available topics of a given type", _find_arguments, _find),
    "pub": Verb("Publish a message to a topic", _pub_arguments, _pub),
    "type": Verb("Print a topic's type", _type_arguments, _type),
}


def main(argv: list[str]):
    return run_group("ros2 topic", "Various topic related sub-commands", VERBS, argv, missing=LEFT_OUT,
                     hidden_flag="--include-hidden-topics")
