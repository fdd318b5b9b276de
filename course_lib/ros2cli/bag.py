"""``ros2 bag record|info|play``: rosbag2's verbs (Jazzy) over course_lib.ros.bag_files' MCAP bags.

record subscribes like rosbag2's Recorder: to the topics asked for (or all, ``-a``) as discovery
finds their publishers, polling the graph every ``--polling-interval`` ms, with a QoS every
publisher can serve (reliable only if all publishers are, transient local only if all are),
and writes the serialized messages with their reception times. play publishes a bag's messages
with the QoS their publishers offered, at the recorded times scaled by ``--rate``. Both stop on
Ctrl-C or SIGTERM, whatever disposition they inherited, close what they hold and end with exit
code 0, as ros2bag does.
"""

from __future__ import annotations

import argparse
import datetime
import os
import time

from course_lib.ros import bag_files, bag_metadata
from course_lib.ros2cli.common import Verb, loop_limit, run_group, signals_received, unsupported

#: Verbs of ros2bag (Jazzy) that the course leaves out.
LEFT_OUT = ("burst", "convert", "list", "reindex")
#: The storages a full install's ros2bag offers; the course writes and plays the first.
STORAGES = (bag_files.STORAGE_ID, "sqlite3")
#: rosbag2's history depth for the recorder's subscriptions and the player's publishers.
DEPTH = 10
#: Seconds play waits at most for reliable subscribers to acknowledge its last messages.
ACK_SECONDS = 10.0


def _error(text: str) -> str:
    """ros2bag's print_error: the line a verb returns, printed on stderr (exit code 1)."""
    return f"[ERROR] [ros2bag]: {text}"


def _existing_path(value: str) -> str:
    if os.path.exists(value):
        return value
    raise argparse.ArgumentTypeError(f"Bag path '{value}' does not exist!")


def _positive_float(value: str) -> float:
    try:
        number = float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{value} is not the valid type (float)") from None
    if number <= 0.0:
        raise argparse.ArgumentTypeError(f"{value} is not in the valid range (> 0.0)")
    return number


def _reader_arguments(parser) -> None:
    parser.add_argument("bag_path", type=_existing_path, help="Bag to open")
    parser.add_argument("-s", "--storage", default="", choices=STORAGES,
                        help="Storage implementation of bag. By default attempts to detect automatically - "
                             "use this argument to override.")


def _node(name: str):
    """A node of the command's own, in the session's ROS context, and an executor that spins it
    in this thread (the verb's loop), so that nothing runs beside the verb's own steps. Like the
    session's tool node it has no parameter and type description services (nobody asks a bag
    command for them, and they would double the time it takes to make the node)."""
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from rclpy.parameter import Parameter

    from course_lib.ros import session

    session.start()
    node = Node(name, start_parameter_services=False,
                parameter_overrides=[Parameter("start_type_description_service", value=False)])
    executor = SingleThreadedExecutor(context=node.context)
    executor.add_node(node)
    return node, executor


# --- ros2 bag info -----------------------------------------------------------------------------

def _info_arguments(parser) -> None:
    _reader_arguments(parser)
    parser.add_argument("-t", "--topic-name", action="store_true", help="Only display topic names.")


def _info(args) -> None:
    try:
        metadata = bag_files.read_metadata(args.bag_path)
    except bag_files.BagError as error:
        raise RuntimeError(str(error)) from None
    if args.topic_name:
        for topic in metadata.topics:
            if not bag_metadata.is_service_event(topic):
                print(topic.name)
    else:
        print(bag_metadata.format_info(metadata))


# --- ros2 bag record ---------------------------------------------------------------------------

def _record_arguments(parser) -> None:
    parser.add_argument("-o", "--output", help="Destination of the bagfile to create, defaults to a timestamped "
                                               "folder in the current directory.")
    parser.add_argument("-s", "--storage", default=bag_files.STORAGE_ID, choices=STORAGES,
                        help="Storage identifier to be used, defaults to '%(default)s'.")
    topics = parser.add_mutually_exclusive_group()
    topics.add_argument("topics_positional", type=str, default=[], metavar="[Topic ...]", nargs="*",
                        help="Space-delimited list of topics to record. (deprecated)")
    topics.add_argument("--topics", type=str, default=[], metavar="Topic", nargs="+",
                        help="Space-delimited list of topics to record.")
    parser.add_argument("-a", "--all", action="store_true",
                        help="Record all topics and services (Exclude hidden topic).")
    parser.add_argument("--all-topics", action="store_true", help="Record all topics (Exclude hidden topic).")
    parser.add_argument("--include-hidden-topics", action="store_true",
                        help="Discover and record hidden topics as well. These are topics used internally by "
                             "ROS 2 implementation.")
    parser.add_argument("--no-discovery", action="store_true",
                        help="Disables topic auto discovery during recording: only topics present at startup will "
                             "be recorded.")
    parser.add_argument("-p", "--polling-interval", type=int, default=100,
                        help="Time in ms to wait between querying available topics for recording. It has no effect "
                             "if --no-discovery is enabled.")
    parser.add_argument("--node-name", type=str, default="rosbag2_recorder",
                        help="Specify the recorder node name. Default is %(default)s.")


class Recorder:
    """rosbag2's Recorder on one node: subscribes to the topics it is to record as they appear,
    writes each message as it arrives, and at stop() takes what its subscriptions still hold
    before it closes the bag."""

    def __init__(self, bag: bag_files.BagWriter, node, requested: list[str], include_hidden: bool):
        self.bag = bag
        self.node = node
        self.requested = [node.resolve_topic_name(topic) for topic in requested]  # [] records all
        self.include_hidden = include_hidden
        self.subscriptions = {}
        self.refused: set[str] = set()

    def _wanted(self, name: str, kinds: list[str]) -> bool:
        from rclpy.logging import get_logger
        from rclpy.topic_or_service_is_hidden import topic_or_service_is_hidden

        from course_lib.ros import message_yaml

        if name in self.subscriptions or name in self.refused or (self.requested and name not in self.requested):
            return False
        if len(kinds) != 1:
            get_logger("rosbag2_transport").error(
                f"Topic '{name}' has more than one type associated. Only topics with one type are supported")
        elif not self.include_hidden and topic_or_service_is_hidden(name):
            get_logger("rosbag2_transport").warning(
                "Hidden topics are not recorded. Enable them with --include-hidden-topics", once=True)
        else:
            try:
                message_yaml.message_class(kinds[0])
            except ValueError as error:
                get_logger("rosbag2_transport").warning(
                    f"Topic '{name}' has unknown type '{kinds[0]}' . Only topics with known type are supported. "
                    f"Reason: '{error}")
            else:
                return self.node.count_publishers(name) > 0  # rosbag2 leaves unpublished topics out
        self.refused.add(name)
        return False

    def discover(self) -> None:
        """Subscribe to each wanted topic that has publishers and no subscription yet."""
        for name, kinds in self.node.get_topic_names_and_types():
            if self._wanted(name, kinds):
                self._subscribe(name, kinds[0])

    def all_subscribed(self) -> bool:
        return bool(self.requested) and len(self.subscriptions) == len(self.requested)

    def _subscribe(self, name: str, type_name: str) -> None:
        from course_lib.ros import graph, message_yaml

        publishers = self.node.get_publishers_info_by_topic(name)
        # rosbag2 keeps the type hash the publishers agree on ("" when they differ or have none).
        hashes = {str(info.topic_type_hash) for info in publishers if info.topic_type_hash.version > 0}
        try:
            definition = bag_files.message_definition(type_name)
        except LookupError:
            definition = ""  # rosbag2 stores no schema for a type whose .msg it cannot find
        self.bag.add_topic(name, type_name, [bag_metadata.qos_to_dict(info.qos_profile) for info in publishers],
                           hashes.pop() if len(hashes) == 1 else "", definition)
        _warn_mixed_offers(name, publishers)
        qos = graph.matching_qos(self.node, name, DEPTH)
        self.subscriptions[name] = self.node.create_subscription(
            message_yaml.message_class(type_name), name,
            lambda data, info: self._write(name, data, info), qos, raw=True)
        self.node.get_logger().info(f"Subscribed to topic '{name}'")

    def _write(self, name: str, data: bytes, info: dict) -> None:
        received = info.get("received_timestamp") or time.time_ns()
        self.bag.write(name, data, log_time=received, publish_time=info.get("source_timestamp") or received)

    def stop(self) -> bag_metadata.BagMetadata:
        """Write what the subscriptions still hold, then close the bag (metadata.yaml)."""
        for name, subscription in self.subscriptions.items():
            with subscription.handle:
                while (taken := subscription.handle.take_message(subscription.msg_type, True)) is not None:
                    self._write(name, *taken)
            self.node.destroy_subscription(subscription)
        self.subscriptions.clear()
        return self.bag.close()


def _warn_mixed_offers(topic: str, publishers) -> None:
    """rosbag2_storage's warnings when only some publishers are reliable or transient local (the
    recorder then asks for best effort or volatile, graph.matching_qos, and hears them all)."""
    from rclpy.logging import get_logger
    from rclpy.qos import DurabilityPolicy, ReliabilityPolicy

    reliable = [info.qos_profile.reliability == ReliabilityPolicy.RELIABLE for info in publishers]
    if any(reliable) and not all(reliable):
        get_logger("rosbag2_storage").warning(
            f'Some, but not all, publishers on topic "{topic}" are offering RMW_QOS_POLICY_RELIABILITY_RELIABLE. '
            "Falling back to RMW_QOS_POLICY_RELIABILITY_BEST_EFFORT as it will connect to all publishers. "
            "Some messages from Reliable publishers could be dropped.")
    latched = [info.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL for info in publishers]
    if any(latched) and not all(latched):
        get_logger("rosbag2_storage").warning(
            f'Some, but not all, publishers on topic "{topic}" are offering RMW_QOS_POLICY_DURABILITY_TRANSIENT_LOCAL. '
            "Falling back to RMW_QOS_POLICY_DURABILITY_VOLATILE as it will connect to all publishers. "
            "Previously-published latched messages will not be retrieved.")


def _record(args) -> str | None:
    if args.storage != bag_files.STORAGE_ID:
        raise unsupported(f"ros2 bag record -s {args.storage}", [f"-s {bag_files.STORAGE_ID}"])
    topics = args.topics or args.topics_positional
    if not (args.all or args.all_topics or topics):
        return _error("Need to specify at least one option out of --all, --all-topics, --all-services, "
                      "--services, --topics, --topic-types or --regex")
    if (args.all or args.all_topics) and topics:
        print("[WARN] [ros2bag]: --all or --all-topics will override --topics")
        topics = []
    uri = args.output or datetime.datetime.now().strftime("rosbag2_%Y_%m_%d-%H_%M_%S")
    if os.path.isdir(uri):
        return _error(f"Output folder '{uri}' already exists.")
    with signals_received() as received:  # from here on, Ctrl-C closes the bag, even while starting
        try:
            bag = bag_files.BagWriter(uri)
        except bag_files.BagError as error:
            return _error(str(error))
        try:
            node, executor = _node(args.node_name)
        except BaseException:
            bag.close()
            raise
        recorder = Recorder(bag, node, topics, args.include_hidden_topics)
        try:
            _record_until_stopped(recorder, executor, args, received)
        finally:
            recorder.stop()  # a valid bag also after an error
            node.get_logger().info("Recording stopped")
            executor.shutdown(timeout_sec=0)
            node.destroy_node()
    return None


def _record_until_stopped(recorder: Recorder, executor, args, received: list) -> None:
    """rosbag2's record loop: subscribe to what is there, then write what arrives and look for new
    topics every polling interval, until a signal (or the time limit under test or grading)."""
    logger = recorder.node.get_logger()
    limit = loop_limit(None)
    logger.info("Listening for topics...")
    recorder.discover()
    logger.info("Recording...")
    discovering = not args.no_discovery
    began = next_poll = time.monotonic()
    while not received and (limit is None or time.monotonic() - began < limit):
        if discovering and recorder.all_subscribed():
            logger.info("All requested topics are subscribed. Stopping discovery...")
            discovering = False
        executor.spin_once(timeout_sec=max(0.0, min(0.1, next_poll - time.monotonic())) if discovering else 0.1)
        if discovering and time.monotonic() >= next_poll:
            recorder.discover()
            next_poll = time.monotonic() + args.polling_interval / 1000


# --- ros2 bag play -----------------------------------------------------------------------------

def _play_arguments(parser) -> None:
    _reader_arguments(parser)
    parser.add_argument("-r", "--rate", type=_positive_float, default=1.0,
                        help="rate at which to play back messages. Valid range > 0.0.")
    parser.add_argument("--topics", type=str, default=[], metavar="topic", nargs="+",
                        help="Space-delimited list of topics to play.")
    parser.add_argument("-l", "--loop", action="store_true",
                        help="enables loop playback when playing a bagfile: it starts back at the beginning on "
                             "reaching the end and plays indefinitely.")


def playback_qos(topic: str, profiles: list[dict]):
    """The QoS to play a topic with, as rosbag2's adapt_offer_to_recorded_offers chooses it: the
    recorded publishers' profile (history: keep last 10) when they all offered the same policies
    that matter for matching, else rosbag2's default, with its warning."""
    from rclpy.duration import Duration
    from rclpy.logging import get_logger
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, LivelinessPolicy, QoSProfile, ReliabilityPolicy

    matching = ("reliability", "durability", "deadline", "liveliness", "liveliness_lease_duration")
    if not profiles:
        return QoSProfile(depth=DEPTH)
    if any({field: p.get(field) for field in matching} != {field: profiles[0].get(field) for field in matching}
           for p in profiles):
        get_logger("rosbag2_storage").warning(
            f"Not all original publishers on topic {topic} offered the same QoS profiles. Rosbag2 cannot yet choose "
            "an adapted profile to offer for this mixed case. Falling back to the rosbag2_storage default publisher "
            "offer.")
        return QoSProfile(depth=DEPTH)
    recorded = profiles[0]

    def policy(kind, field):  # "unknown" (what discovery reports) cannot make a publisher
        name = str(recorded.get(field, "system_default")).upper()
        return kind.SYSTEM_DEFAULT if name == "UNKNOWN" or name not in kind.__members__ else kind[name]

    def duration(field):
        value = recorded.get(field) or {"sec": 0, "nsec": 0}
        return Duration(seconds=int(value["sec"]), nanoseconds=int(value["nsec"]))

    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=DEPTH,
                      reliability=policy(ReliabilityPolicy, "reliability"),
                      durability=policy(DurabilityPolicy, "durability"), deadline=duration("deadline"),
                      lifespan=duration("lifespan"), liveliness=policy(LivelinessPolicy, "liveliness"),
                      liveliness_lease_duration=duration("liveliness_lease_duration"),
                      avoid_ros_namespace_conventions=bool(recorded.get("avoid_ros_namespace_conventions")))


def play_messages(messages, bag_start: int, rate: float, publish, clock, wait) -> bool:
    """Publish ``messages`` ((topic, data, log_time), in time order) each when its time has come:
    ``(log_time - bag_start) / rate`` after the call, on ``clock`` (seconds, monotonic).
    ``wait(seconds)`` waits and returns True when playback is to stop; so does play_messages."""
    began = clock()
    for topic, data, log_time in messages:
        due = began + (log_time - bag_start) / 1e9 / rate
        while (left := due - clock()) > 0:
            if wait(min(left, 0.05)):
                return True
        publish(topic, data)
    return False


def _await_subscribers(node, publishers: dict, received: list) -> None:
    """Before the first message: until discovery has settled and each publisher has matched the
    subscriptions the graph shows on its topic, so that a running echo hears the bag from its
    start (the real player starts at once; a new process may take a second to be discovered).
    A signal ends the wait."""
    from course_lib.ros import discovery, session
    from course_lib.ros2cli.common import COMPLETE_SECONDS, DISCOVERY_BACKSTOP, QUIET_SECONDS

    discovery.wait_for_discovery(minimum=0.0, quiet=QUIET_SECONDS, complete_within=COMPLETE_SECONDS,
                                 until=lambda: bool(received))
    session.wait_for(lambda: bool(received) or all(publisher.get_subscription_count() >= node.count_subscribers(name)
                                                   for name, publisher in publishers.items()),
                     timeout=DISCOVERY_BACKSTOP)


def _publishers(node, metadata: bag_metadata.BagMetadata, topics: list[str]) -> dict:
    """A publisher for each topic of the bag to play (of ``topics``, if given) whose type is
    installed, with the QoS its recorded publishers offered; player.cpp's warning for the others."""
    from course_lib.ros import message_yaml

    publishers = {}
    for topic in metadata.topics:
        if topics and topic.name not in topics:
            continue
        try:
            message_class = message_yaml.message_class(topic.type)
        except ValueError as error:
            node.get_logger().warning(f"Ignoring a topic '{topic.name}', reason: {error}.")
            continue
        publishers[topic.name] = node.create_publisher(
            message_class, topic.name, playback_qos(topic.name, topic.offered_qos_profiles))
    return publishers


def _play(args) -> None:
    from rclpy.duration import Duration

    try:
        files = bag_files.storage_files(args.bag_path)
        metadata = bag_files.read_metadata(args.bag_path)
    except bag_files.BagError as error:
        raise RuntimeError(str(error)) from None
    with signals_received() as received:  # from here on, Ctrl-C ends playback (exit code 0)
        node, executor = _node("rosbag2_player")
        try:
            node.get_logger().info(f"Set rate to {args.rate:g}")
            publishers = _publishers(node, metadata, args.topics)
            _await_subscribers(node, publishers, received)
            node.get_logger().info("Playback until timestamp: -1")
            limit = loop_limit(None)
            began = time.monotonic()
            published = [0]

            def publish(name: str, data: bytes) -> None:
                publishers[name].publish(data)
                published[0] += 1

            def wait(seconds: float) -> bool:
                executor.spin_once(timeout_sec=seconds)
                return bool(received) or (limit is not None and time.monotonic() - began > limit)

            while not received:
                stopped = play_messages(bag_files.read_messages(files, list(publishers)), metadata.starting_time,
                                        args.rate, publish, time.monotonic, wait)
                # --loop starts again at once (a bag with nothing to play: after a moment)
                if stopped or not args.loop or wait(0.0 if published[0] else 0.05):
                    break
            if not received:  # reliable subscribers get the last messages before the publishers go
                for publisher in publishers.values():
                    publisher.wait_for_all_acked(Duration(seconds=ACK_SECONDS))
        finally:
            executor.shutdown(timeout_sec=0)
            node.destroy_node()


VERBS = {
    "info": Verb("Print information about a bag to the screen", _info_arguments, _info),
    "play": Verb("Play back ROS data from a bag", _play_arguments, _play),
    "record": Verb("Record ROS data to a bag", _record_arguments, _record),
}


def main(argv: list[str]):
    return run_group("ros2 bag", "Various rosbag related sub-commands", VERBS, argv, missing=LEFT_OUT)
