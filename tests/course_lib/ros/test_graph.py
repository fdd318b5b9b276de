"""Tests for course_lib.ros.graph: the ros2 CLI's node/topic introspection, from a notebook."""

import math
import os
import select
import signal
import subprocess
import sys
import time

import pytest
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from std_msgs.msg import String

from course_lib.ros import announcements, discovery, graph, graph_info, message_yaml, rosenv, session

# A talker in another process: a 10 Hz timer publishing "hello N" on /far_chatter.
FAR_TALKER = """
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import String


class FarTalker(Node):
    def __init__(self):
        super().__init__("far_talker")
        self.count = 0
        self.publisher = self.create_publisher(String, "far_chatter", 10)
        self.create_timer(0.1, self.tick)

    def tick(self):
        self.count += 1
        self.publisher.publish(String(data=f"hello {self.count}"))


rclpy.init()
node = FarTalker()
print("ready", flush=True)
try:
    rclpy.spin(node)
except (KeyboardInterrupt, ExternalShutdownException):
    pass
finally:
    node.destroy_node()
    rclpy.try_shutdown()
"""


@pytest.fixture(scope="module")
def far_talker():
    """The domain id on which another process runs /far_talker; stopped after the module."""
    with rosenv.reserve_domain_id() as reservation:
        process = subprocess.Popen([sys.executable, "-c", FAR_TALKER], stdout=subprocess.PIPE,
                                   text=True,
                                   env=rosenv.ros_environment(domain_id=reservation.domain_id))
        try:
            ready, _, _ = select.select([process.stdout], [], [], 60)
            assert ready and process.stdout.readline().strip() == "ready", \
                "the talker process did not start"
            yield reservation.domain_id
        finally:
            process.send_signal(signal.SIGINT)
            try:
                process.wait(timeout=60)  # a backstop: the talker ends on the signal
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait(timeout=10)
            process.stdout.close()


@pytest.fixture(autouse=True)
def no_session_left():
    """Every test starts without a session and leaves none behind."""
    session.stop()
    yield
    session.stop()


@pytest.fixture
def local_session(domain_id, monkeypatch):
    """A session on a domain of its own; no discovery wait, as all nodes are in this process."""
    monkeypatch.setattr(discovery, "SETTLE_SECONDS", 0.0)
    session.start(domain_id=domain_id)
    return domain_id


class Talker(Node):
    def __init__(self, name="talker", topic="chatter", qos=10):
        super().__init__(name)
        self.publisher = self.create_publisher(String, topic, qos)
        self.create_timer(0.05, lambda: self.publisher.publish(String(data="hi")))


class Listener(Node):
    def __init__(self, name="listener", topic="chatter", qos=10):
        super().__init__(name)
        self.received = []
        self.create_subscription(String, topic, self.received.append, qos)


# --- against another process ------------------------------------------------------------

def test_node_list_sees_a_node_in_another_process(far_talker):
    """node_list() finds /far_talker, started by another process, and hides the tool node."""
    session.start(domain_id=far_talker)
    names = graph.node_list(wait_for=["/far_talker"], timeout=60)
    assert "/far_talker" in names
    assert "/" + session.tool_node_name() not in names
    assert "/" + session.tool_node_name() in graph.node_list(all=True)


def test_discovery_counts_a_process_holding_three_nodes_as_one_participant(domain_id):
    """`ros2 node list` waits until every process on the machine has shown its nodes; a process
    is one DDS participant however many nodes it holds (counting nodes would let a listing answer
    before a process holding one node showed, while another holding three nodes already had)."""
    process = subprocess.Popen(
        [sys.executable, "-c", "import rclpy, rclpy.node, time; rclpy.init(); "
         "nodes = [rclpy.node.Node(n) for n in ('one', 'two', 'three')]; print('ready', flush=True); time.sleep(60)"],
        stdout=subprocess.PIPE, text=True, env=rosenv.ros_environment(domain_id=domain_id))
    try:
        ready, _, _ = select.select([process.stdout], [], [], 60)
        assert ready and process.stdout.readline().strip() == "ready", "the three-node process did not start"
        session.start(domain_id=domain_id)
        tool = session.tool_node()
        assert session.wait_for(lambda: {"one", "two", "three"} <= set(tool.get_node_names()), timeout=15)
        here = discovery._participants_here(domain_id)
        assert sorted(here) == sorted([os.getpid(), process.pid])  # this process and the other one
        with announcements.Announcements(tool) as heard:
            assert session.wait_for(lambda: discovery._every_process_shown(tool, heard, here), timeout=30)
            assert process.pid & 0xFFFF in discovery._processes_shown(tool, heard.latest())
            session.add_node(Node("four"))
            assert session.wait_for(lambda: "four" in tool.get_node_names(), timeout=30)
            assert session.wait_for(lambda: discovery._processes_shown(tool, heard.latest()) ==
                                    {os.getpid() & 0xFFFF, process.pid & 0xFFFF}, timeout=30)
    finally:
        process.kill()
        process.wait(timeout=10)
        process.stdout.close()


def test_a_lone_socket_on_a_participants_port_is_no_participant(domain_id):
    """A participant binds two ports, for discovery and for data. Domain 101's ports reach the
    kernel's ephemeral ones, which any program's socket may get: counting single ports, a
    listing in domain 101 waited for a process that was not there, and this module's test of a
    three-node process counted 3 participants in a suite run."""
    import socket

    before = len(discovery._participants_here(domain_id))
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as lone, \
            socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as data:
        for participant in range(119, 60, -1):  # ids no process of this domain takes; skip ports in use
            port = 7410 + 250 * domain_id + 2 * participant
            try:
                lone.bind(("127.0.0.1", port))
            except OSError:
                continue
            break
        assert len(discovery._participants_here(domain_id)) == before
        data.bind(("127.0.0.1", port + 1))
        assert len(discovery._participants_here(domain_id)) == before + 1


def test_the_settling_wait_sees_a_subscription_arrive_on_a_topic_it_already_knows(local_session):
    """A process announces its publishers and its subscriptions apart: a listing that settled on
    the topic alone answered "Subscription count: 0" when the subscription came a moment later."""
    session.add_node(Talker(name="snap_talker", topic="snap_chatter"))
    tool = session.tool_node()
    assert session.wait_for(lambda: tool.count_publishers("/snap_chatter") == 1, timeout=5)
    before = discovery._snapshot(tool)
    session.add_node(Listener(name="snap_listener", topic="snap_chatter"))
    assert session.wait_for(lambda: tool.count_subscribers("/snap_chatter") == 1, timeout=5)
    assert discovery._snapshot(tool)[1] != before[1]  # the topics part changed, not only the node names


def test_topic_echo_receives_the_asked_number_of_messages(far_talker):
    """topic_echo(count=3) gives three consecutive messages of the type read from the graph."""
    session.start(domain_id=far_talker)
    messages = graph.topic_echo("far_chatter", count=3, timeout=60)
    assert len(messages) == 3
    assert all(isinstance(msg, String) for msg in messages)
    numbers = [int(msg.data.split()[1]) for msg in messages]
    assert numbers == list(range(numbers[0], numbers[0] + 3))
    assert message_yaml.format_messages(messages) == "".join(f"data: hello {n}\n---\n" for n in numbers)


def test_topic_hz_reports_the_statistics_of_the_arrivals_it_measured(far_talker):
    """topic_hz() measures the other process's messages from the first one on and reports ros2's
    statistics of their arrivals. How regular they come is the machine's doing (a starved
    talker's 10 Hz timer lags and skips ticks), so it is not judged; what follows from any
    arrivals is: the mean period lies between the shortest and the longest, and the periods
    measured, in seconds, fit in the time the call took."""
    session.start(domain_id=far_talker)
    began = time.monotonic()
    stats = graph.topic_hz("/far_chatter", duration=2.0, timeout=60)
    took = time.monotonic() - began
    assert stats.samples >= 1 and 0 < stats.min_period <= 1 / stats.rate <= stats.max_period, stats
    assert stats.samples / stats.rate <= took, (stats, took)
    assert str(stats).startswith(f"average rate: {stats.rate:.3f}\n\tmin: ")


def test_topic_info_of_a_remote_publisher_names_its_node(far_talker):
    """topic_info() lists the other process's publisher with its node, type and a GID."""
    session.start(domain_id=far_talker)
    graph.topic_list(wait_for=["/far_chatter"], timeout=60)
    info = graph.topic_info("/far_chatter")
    assert info.types == ["std_msgs/msg/String"]
    assert [(p.node, p.endpoint_type) for p in info.publishers] == [("/far_talker", "PUBLISHER")]
    assert info.publishers[0].qos.reliability == "RELIABLE"
    assert len(info.publishers[0].gid.split(".")) == 16


# --- in this process --------------------------------------------------------------------

def test_topic_list_gives_names_or_types(local_session):
    """topic_list() gives sorted names; types=True pairs each with its types."""
    session.add_node(Talker())
    names = graph.topic_list()
    assert names == sorted(names)
    assert {"/chatter", "/rosout", "/parameter_events"} <= set(names)
    assert ("/chatter", ["std_msgs/msg/String"]) in graph.topic_list(types=True)


def test_topic_info_reports_best_effort_publisher_and_reliable_subscriber(local_session):
    """A sensor-data publisher shows BEST_EFFORT, a default subscription RELIABLE, as ros2 -v."""
    session.add_node(Talker("camera", "camera_data", qos_profile_sensor_data))
    session.add_node(Listener("viewer", "camera_data",
                              QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)))
    info = graph.topic_info("camera_data")
    assert (info.name, info.types) == ("/camera_data", ["std_msgs/msg/String"])
    assert (info.publisher_count, info.subscription_count) == (1, 1)
    publisher, subscription = info.publishers[0], info.subscriptions[0]
    assert (publisher.node, publisher.endpoint_type) == ("/camera", "PUBLISHER")
    assert (subscription.node, subscription.endpoint_type) == ("/viewer", "SUBSCRIPTION")
    assert publisher.qos.reliability == "BEST_EFFORT"
    assert subscription.qos.reliability == "RELIABLE"
    assert publisher.qos.durability == subscription.qos.durability == "VOLATILE"
    assert publisher.qos.liveliness == "AUTOMATIC"
    assert math.isinf(publisher.qos.deadline)
    text = graph_info.format_topic_info(info)
    assert text.startswith("Type: std_msgs/msg/String\n\nPublisher count: 1\n\nNode name: camera\n")
    assert "Endpoint type: PUBLISHER\n" in text and "Endpoint type: SUBSCRIPTION\n" in text
    assert "  Reliability: BEST_EFFORT\n" in text and "  Reliability: RELIABLE\n" in text
    assert "  Deadline: Infinite\n" in text
    brief = graph_info.format_topic_info(graph.topic_info("camera_data", verbose=False), verbose=False)
    assert brief == "Type: std_msgs/msg/String\nPublisher count: 1\nSubscription count: 1\n"


def test_topic_info_of_an_unknown_topic_lists_the_known_ones(local_session):
    """Asking about a topic nobody uses fails with the list of topics there are."""
    with pytest.raises(ValueError, match="/rosout"):
        graph.topic_info("/nobody_here", timeout=0.2)


def test_topic_echo_does_not_leave_its_subscription_behind(local_session):
    """After topic_echo() the tool node no longer subscribes (topic_info shows no extra reader)."""
    session.add_node(Talker())
    assert len(graph.topic_echo("/chatter", count=2, timeout=60)) == 2
    assert graph.topic_info("/chatter").subscription_count == 0


def test_topic_echo_without_messages_times_out_with_what_it_got(local_session):
    """No publisher: topic_echo() raises a TimeoutError holding the (no) messages received."""
    with pytest.raises(graph.EchoTimeout, match="0 of 1") as caught:
        graph.topic_echo("/silent", msg_type="std_msgs/msg/String", timeout=0.3)
    assert caught.value.messages == []
    with pytest.raises(TimeoutError, match="msg_type="):
        graph.topic_echo("/silent", timeout=0.3)


def test_node_info_lists_topics_and_services_like_ros2_node_info(local_session):
    """A talker's info shows its publisher, its parameter services and empty sections."""
    session.add_node(Talker(name="info_talker", topic="info_chatter"))
    info = graph.node_info("info_talker")
    assert ("/info_chatter", ["std_msgs/msg/String"]) in info.publishers
    assert ("/info_talker/get_parameters", ["rcl_interfaces/srv/GetParameters"]) in info.service_servers
    text = graph_info.format_node_info(info)
    assert text.startswith("/info_talker\n  Subscribers:\n\n  Publishers:\n")
    assert "    /info_chatter: std_msgs/msg/String\n" in text
    assert text.endswith("  Action Servers:\n\n  Action Clients:\n\n")
    with pytest.raises(ValueError, match="Unable to find node '/nobody'"):
        graph.node_info("/nobody", timeout=0.2)


def test_wait_for_publisher_says_plainly_that_nothing_publishes(local_session):
    """Before waiting for frames: no publisher is an error that names the topic and the fix
    (after a kernel restart the camera is gone), not '0 frames received' later."""
    from std_msgs.msg import String

    with pytest.raises(graph.NoPublisher, match=r"No node publishes on /camera/image_raw .* run the camera cell"):
        graph.wait_for_publisher("/camera/image_raw", timeout=0.2, hint="run the camera cell")
    node = session.add_node(Node("camera_stand_in"))
    node.create_publisher(String, "/camera/image_raw", 10)
    assert graph.wait_for_publisher("/camera/image_raw", timeout=5) == 1
