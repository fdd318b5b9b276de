"""``ros2 bag record|info|play`` (course_lib/ros2cli/bag.py, course_lib.ros.bag_files), run as the
installed ``.venv/bin/ros2`` against a node in a process of its own, with bags going both ways
between the course and rosbags (PyPI), whose rosbag2 and MCAP code is its own: rosbags reads
what the course recorded, and the course shows and plays what rosbags wrote. Held to rosbag2's
Jazzy sources (ros2bag/verb/*.py, rosbag2_py's format_bag_metadata, rosbag2_storage's yaml.hpp
and qos.cpp, rosbag2_storage_mcap's mcap_storage.cpp)."""

import os
import signal
import sys
import types

import pytest
import yaml
from rosbags.highlevel import AnyReader
from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore
from support.process import in_background_of_a_script
from support.ros2cli import ROS2, node_script, ros2_together

from course_lib.ros import bag_metadata, processes, rosenv
from course_lib.ros2cli.bag import play_messages

BAG_NODE = node_script('''
import sys

import rclpy
from rclpy.duration import Duration
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile
from std_msgs.msg import Int32, String


class BagNode(Node):
    """Latches 42 on /latched; once a recorder subscribes to /chatter and /latched, sends 'hello 1'
    to 'hello 5' on /chatter and says 'acked' when the recorder has acknowledged all of it; prints
    what it hears on /played."""

    def __init__(self):
        super().__init__('bag_node')
        self.latched = self.create_publisher(Int32, 'latched',
                                             QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL))
        self.latched.publish(Int32(data=42))
        self.chatter = self.create_publisher(String, 'chatter', 10)
        self.create_subscription(String, 'played', lambda msg: print(f'heard {msg.data}', flush=True), 10)
        self.timer = self.create_timer(0.05, self.send_when_recorded)

    def send_when_recorded(self):
        if self.chatter.get_subscription_count() and self.latched.get_subscription_count():
            self.timer.cancel()
            for number in range(1, 6):
                self.chatter.publish(String(data=f'hello {number}'))
            for publisher in (self.chatter, self.latched):
                publisher.wait_for_all_acked(Duration(seconds=60))
            print('acked', flush=True)

''', 'BagNode()')

#: rmw's infinite duration, as Jazzy's endpoints offer it.
INFINITE = QosTime(sec=9223372036, nsec=854775807)


@pytest.fixture(scope="module")
def bag_node(tmp_path_factory):
    """The node in a process of its own on a reserved domain; ros2's env without the test-suite's
    time limit (a recording ends with the test's signal, not after 2 s)."""
    script = tmp_path_factory.mktemp("bag_node") / "bag_node.py"
    script.write_text(BAG_NODE)
    with rosenv.reserve_domain_id() as reservation:
        with processes.NodeProcess([sys.executable, str(script)], name="bag_node",
                                   domain_id=reservation.domain_id) as process:
            env = rosenv.ros_environment(domain_id=reservation.domain_id)
            env.pop("COURSE_LIB_UNDER_TEST", None)
            env["TZ"] = "UTC"  # as ros2bag's test_info.py runs ros2 bag info
            yield types.SimpleNamespace(process=process, env=env)


def offered(reliability: str, durability: str) -> dict:
    """An offered profile as Jazzy's discovery reports a publisher's (history unknown, depth 0)."""
    return {"history": "unknown", "depth": 0, "reliability": reliability, "durability": durability,
            "deadline": INFINITE._asdict(), "lifespan": INFINITE._asdict(), "liveliness": "automatic",
            "liveliness_lease_duration": INFINITE._asdict(), "avoid_ros_namespace_conventions": False}


def test_a_recorded_bag_is_what_rosbags_reads(bag_node, tmp_path):
    """record.py/recorder.cpp: `ros2 bag record -a -o DIR` subscribes to every published topic with
    a QoS all its publishers serve (qos.cpp adapt_request_to_offers: transient local when all are,
    so /latched's message is recorded), logs 'Listening for topics...', "Subscribed to topic
    '/chatter'", 'Recording...', and on SIGINT (inherited ignored: `&` in a script) 'Recording
    stopped', exit code 0. The bag is DIR/DIR_0.mcap and metadata.yaml version 9 (yaml.hpp's fields,
    offered_qos_profiles as a list with policies by name, type_description_hash); rosbags reads it
    with no types of its own, from the bag's ros2msg schemas alone."""
    bag = tmp_path / "recorded"
    log = tmp_path / "record.log"
    shell, pid = in_background_of_a_script([str(ROS2), "bag", "record", "-a", "-o", str(bag)], log, bag_node.env)
    bag_node.process.wait_for_output("acked", timeout=120)
    os.kill(pid, signal.SIGINT)
    assert shell.wait(timeout=120) == 0, log.read_text()
    lines = [line.split("]: ", 1)[-1] for line in log.read_text().splitlines()]
    assert lines[:1] == ["Listening for topics..."] and lines[-1:] == ["Recording stopped"], lines
    assert {"Recording...", "Subscribed to topic '/chatter'", "Subscribed to topic '/latched'"} <= set(lines)

    fields = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert list(fields) == ["version", "storage_identifier", "duration", "starting_time", "message_count",
                            "topics_with_message_count", "compression_format", "compression_mode",
                            "relative_file_paths", "files", "custom_data", "ros_distro"]
    assert (fields["version"], fields["storage_identifier"], fields["ros_distro"]) == (9, "mcap", "jazzy")
    assert fields["relative_file_paths"] == ["recorded_0.mcap"] == [file["path"] for file in fields["files"]]
    topics = {entry["topic_metadata"]["name"]: entry for entry in fields["topics_with_message_count"]}
    assert topics["/chatter"]["topic_metadata"]["offered_qos_profiles"] == [offered("reliable", "volatile")]
    assert topics["/latched"]["topic_metadata"]["offered_qos_profiles"] == [offered("reliable", "transient_local")]
    assert fields["message_count"] == sum(entry["message_count"] for entry in topics.values())

    jazzy = get_typestore(Stores.ROS2_JAZZY)
    with AnyReader([bag], default_typestore=get_typestore(Stores.EMPTY)) as reader:
        heard = {}
        times = []
        for connection, timestamp, data in reader.messages():
            heard.setdefault(connection.topic, []).append(reader.deserialize(data, connection.msgtype).data
                                                          if connection.topic in ("/chatter", "/latched") else None)
            times.append(timestamp)
        connections = {connection.topic: connection for connection in reader.connections}
    assert heard["/chatter"] == [f"hello {number}" for number in range(1, 6)]
    assert heard["/latched"] == [42]
    assert connections["/chatter"].digest == jazzy.hash_rihs01("std_msgs/msg/String")
    assert connections["/chatter"].ext.serialization_format == "cdr"
    assert connections["/latched"].ext.offered_qos_profiles[0].durability == QosDurability.TRANSIENT_LOCAL
    assert (fields["starting_time"]["nanoseconds_since_epoch"], fields["duration"]["nanoseconds"]) == (
        min(times), max(times) - min(times))


def write_their_bag(path) -> tuple[int, int]:
    """A bag rosbags writes (version 9, MCAP): 'one', 'two', 'three' on /played 0.1 s apart and
    7 on /other; (its start, its end) in nanoseconds since the epoch."""
    typestore = get_typestore(Stores.ROS2_JAZZY)
    string, int32 = typestore.types["std_msgs/msg/String"], typestore.types["std_msgs/msg/Int32"]
    qos = Qos(history=QosHistory.UNKNOWN, depth=0, reliability=QosReliability.RELIABLE,
              durability=QosDurability.VOLATILE, deadline=INFINITE, lifespan=INFINITE,
              liveliness=QosLiveliness.AUTOMATIC, liveliness_lease_duration=INFINITE,
              avoid_ros_namespace_conventions=False)
    start = 1_700_000_000_250_000_000
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        played = writer.add_connection("/played", string.__msgtype__, typestore=typestore, offered_qos_profiles=[qos])
        other = writer.add_connection("/other", int32.__msgtype__, typestore=typestore, offered_qos_profiles=[qos])
        for index, word in enumerate(("one", "two", "three")):
            writer.write(played, start + index * 100_000_000,
                         typestore.serialize_cdr(string(data=word), string.__msgtype__))
        writer.write(other, start + 50_000_000, typestore.serialize_cdr(int32(data=7), int32.__msgtype__))
    return start, start + 200_000_000


def test_a_bag_rosbags_wrote_is_shown_and_played(bag_node, tmp_path):
    """format_bag_metadata.cpp: `ros2 bag info` prints a blank line, then Files, Bag size, Storage id,
    ROS Distro, Duration, Start, End, Messages, 'Topic information: Topic: ... | Type: ... | Count: ...
    | Serialization Format: cdr', Service, 'Service information: ' aligned at column 19 (TZ=UTC as
    ros2bag's test_info.py); `info -t` only the names. Errors in ros2bag's and rosbag2's words:
    api/__init__.py check_path_exists ("Bag path '...' does not exist!", a usage error),
    sequential_reader.cpp ('No storage could be initialized from the inputs.'), record.py ('Need
    to specify at least one option ...', "Output folder '...' already exists."). play.py: `--loop`
    plays on until Ctrl-C or SIGTERM (exit code 0: _transport.cpp defers both), with the recorded QoS,
    into a subscriber of another process."""
    theirs = tmp_path / "theirs"
    start, end = write_their_bag(theirs)
    not_a_bag = tmp_path / "notes.txt"
    not_a_bag.write_text("not a bag\n")
    size = sum(item.stat().st_size for item in theirs.iterdir())
    info, topic_names, missing, bad_play, no_topics, exists = ros2_together(
        ["bag", "info", str(theirs)], ["bag", "info", "-t", str(theirs)], ["bag", "info", "no_such_bag"],
        ["bag", "play", str(not_a_bag)], ["bag", "record"], ["bag", "record", "-a", "-o", str(theirs)],
        env=bag_node.env)
    assert (info.returncode, info.stdout) == (0, f"""
Files:             theirs.mcap
Bag size:          {bag_metadata._size(size)}
Storage id:        mcap
ROS Distro:        rosbags
Duration:          0.200000000s
Start:             Nov 14 2023 22:13:20.250000000 ({start // 10**9}.250000000)
End:               Nov 14 2023 22:13:20.450000000 ({end // 10**9}.450000000)
Messages:          4
Topic information: Topic: /played | Type: std_msgs/msg/String | Count: 3 | Serialization Format: cdr
                   Topic: /other | Type: std_msgs/msg/Int32 | Count: 1 | Serialization Format: cdr
Service:           0
Service information:""" + " \n"), info.stderr  # rosbag2 ends the last line with a space
    assert (topic_names.returncode, topic_names.stdout) == (0, "/played\n/other\n")
    assert missing.returncode == 2 and missing.stderr.endswith(
        "ros2 bag info: error: argument bag_path: Bag path 'no_such_bag' does not exist!\n")
    assert bad_play.returncode == 1 and bad_play.stderr.endswith("No storage could be initialized from the inputs.\n")
    assert "[rosbag2_storage]: No storage id specified, and no plugin found that could open URI" in bad_play.stderr
    assert (no_topics.returncode, no_topics.stderr) == (1, "[ERROR] [ros2bag]: Need to specify at least one option "
                                                           "out of --all, --all-topics, --all-services, --services, "
                                                           "--topics, --topic-types or --regex\n")
    assert (exists.returncode, exists.stderr) == (1, f"[ERROR] [ros2bag]: Output folder '{theirs}' already exists.\n")

    play = processes.NodeProcess([str(ROS2), "bag", "play", str(theirs), "--loop", "--rate", "4"],
                                 domain_id=bag_node.process.domain_id, env={"COURSE_LIB_UNDER_TEST": None}).start()
    try:
        for word in ("one", "two", "three"):
            bag_node.process.wait_for_output(f"heard {word}", timeout=120)
        play.send_signal(signal.SIGTERM)  # rosbag2_py's handler defers it, and play ends as after Ctrl-C
        assert play.wait(timeout=60) == 0, play.log
    finally:
        play.stop()
    assert "[rosbag2_player]: Set rate to 4" in play.log and "Playback until timestamp: -1" in play.log


def test_play_keeps_the_recorded_times_over_the_rate():
    """player.cpp: a message is published when its time since the bag's start, divided by --rate,
    has passed since playback began (on a clock that here moves only when play waits)."""
    now = [100.0]
    published = []

    def wait(seconds):
        now[0] += seconds
        return False

    messages = [("/a", b"1", 5_000_000_000), ("/b", b"2", 5_400_000_000), ("/a", b"3", 6_000_000_000)]
    assert play_messages(messages, 5_000_000_000, 2.0, lambda topic, data: published.append((topic, data, now[0])),
                         lambda: now[0], wait) is False
    assert [(topic, data) for topic, data, _ in published] == [("/a", b"1"), ("/b", b"2"), ("/a", b"3")]
    assert [round(at - 100.0, 6) for _, _, at in published] == [0.0, 0.2, 0.5]
    assert play_messages(messages, 5_000_000_000, 1.0, lambda *_: None, lambda: now[0], lambda _: True) is True


def test_older_metadata_versions_are_read():
    """qos.cpp: metadata before version 9 held offered_qos_profiles as a YAML text with rmw's enum
    numbers (the talker bag of rosbag2_py's tests, version 4); version 9 a list with names."""
    old = ("- history: 3\n  depth: 0\n  reliability: 1\n  durability: 2\n  deadline:\n    sec: 0\n    nsec: 0\n"
           "  lifespan:\n    sec: 0\n    nsec: 0\n  liveliness: 1\n  liveliness_lease_duration:\n    sec: 0\n"
           "    nsec: 0\n  avoid_ros_namespace_conventions: false")
    profile = bag_metadata.offered_profiles(old)[0]
    assert (profile["history"], profile["reliability"], profile["durability"], profile["liveliness"]) == (
        "unknown", "reliable", "volatile", "automatic")
    assert bag_metadata.offered_profiles([offered("best_effort", "volatile")]) == [offered("best_effort", "volatile")]


def test_service_event_topics_are_counted_apart():
    """format_bag_metadata.cpp, as rosbag2's test_rosbag2_info_end_to_end.cpp reads it for its bag
    bag_with_topics_and_service_events (metadata version 8): 'Messages:          2' (service events
    left out), 'Service:           2', each service once as 'Service: ... | Type: ... | Event Count:
    ... | Serialization Format: cdr' aligned at column 21, 'ROS Distro:        unknown' when empty."""
    def topic(name, kind, count):
        return {"topic_metadata": {"name": name, "type": kind, "serialization_format": "cdr",
                                   "offered_qos_profiles": "", "type_description_hash": ""}, "message_count": count}

    metadata = bag_metadata.from_dict({
        "version": 8, "storage_identifier": "mcap", "duration": {"nanoseconds": 70653944},
        "starting_time": {"nanoseconds_since_epoch": 1699345836270074454}, "message_count": 10,
        "relative_file_paths": ["bag_with_topics_and_service_events.mcap"], "ros_distro": "",
        "topics_with_message_count": [
            topic("/test_service1/_service_event", "test_msgs/srv/BasicTypes_Event", 4),
            topic("/test_topic1", "test_msgs/msg/Strings", 1),
            topic("/test_service2/_service_event", "test_msgs/srv/BasicTypes_Event", 4),
            topic("/test_topic2", "test_msgs/msg/Strings", 1)]})
    lines = bag_metadata.format_info(metadata).splitlines()
    assert lines[4:5] == ["ROS Distro:        unknown"] and lines[8:9] == ["Messages:          2"]
    assert lines[9:] == [
        "Topic information: Topic: /test_topic1 | Type: test_msgs/msg/Strings | Count: 1 | Serialization Format: cdr",
        "                   Topic: /test_topic2 | Type: test_msgs/msg/Strings | Count: 1 | Serialization Format: cdr",
        "Service:           2",
        "Service information: Service: /test_service1 | Type: test_msgs/srv/BasicTypes | Event Count: 4 | "
        "Serialization Format: cdr",
        "                     Service: /test_service2 | Type: test_msgs/srv/BasicTypes | Event Count: 4 | "
        "Serialization Format: cdr"]
