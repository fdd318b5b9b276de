"""Tests for course_lib.graph: the ros2 CLI's node/topic introspection, from a notebook."""

import math
import select
import signal
import subprocess
import sys

import numpy as np
import pytest
from matplotlib.figure import Figure
from matplotlib.text import Annotation
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from sensor_msgs.msg import Image
from std_msgs.msg import String

from course_lib import graph, rosenv, session

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
                process.wait(timeout=10)
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
    monkeypatch.setattr(graph, "SETTLE_SECONDS", 0.0)
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
    names = graph.node_list(wait_for=["/far_talker"], timeout=15)
    assert "/far_talker" in names
    assert "/" + session.TOOL_NODE_NAME not in names
    assert "/" + session.TOOL_NODE_NAME in graph.node_list(all=True)


def test_topic_echo_receives_the_asked_number_of_messages(far_talker):
    """topic_echo(count=3) gives three consecutive messages of the type read from the graph."""
    session.start(domain_id=far_talker)
    messages = graph.topic_echo("far_chatter", count=3, timeout=15)
    assert len(messages) == 3
    assert all(isinstance(msg, String) for msg in messages)
    numbers = [int(msg.data.split()[1]) for msg in messages]
    assert numbers == list(range(numbers[0], numbers[0] + 3))
    assert graph.format_messages(messages) == "".join(f"data: hello {n}\n---\n" for n in numbers)


def test_topic_hz_measures_a_10hz_timer_publisher(far_talker):
    """topic_hz() reports close to 10 Hz for a 0.1 s timer (a loose bound: it is a measurement)."""
    session.start(domain_id=far_talker)
    stats = graph.topic_hz("/far_chatter", duration=2.0, timeout=15)
    assert 7.0 < stats.rate < 13.0, stats
    assert stats.samples >= 5
    assert stats.min_period <= 1 / stats.rate <= stats.max_period
    assert str(stats).startswith(f"average rate: {stats.rate:.3f}\n\tmin: ")


def test_topic_info_of_a_remote_publisher_names_its_node(far_talker):
    """topic_info() lists the other process's publisher with its node, type and a GID."""
    session.start(domain_id=far_talker)
    graph.topic_list(wait_for=["/far_chatter"], timeout=15)
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
    text = graph.format_topic_info(info)
    assert text.startswith("Type: std_msgs/msg/String\n\nPublisher count: 1\n\nNode name: camera\n")
    assert "Endpoint type: PUBLISHER\n" in text and "Endpoint type: SUBSCRIPTION\n" in text
    assert "  Reliability: BEST_EFFORT\n" in text and "  Reliability: RELIABLE\n" in text
    assert "  Deadline: Infinite\n" in text
    brief = graph.format_topic_info(graph.topic_info("camera_data", verbose=False), verbose=False)
    assert brief == "Type: std_msgs/msg/String\nPublisher count: 1\nSubscription count: 1\n"


def test_topic_info_of_an_unknown_topic_lists_the_known_ones(local_session):
    """Asking about a topic nobody uses fails with the list of topics there are."""
    with pytest.raises(ValueError, match="/rosout"):
        graph.topic_info("/nobody_here", timeout=0.2)


def test_topic_echo_does_not_leave_its_subscription_behind(local_session):
    """After topic_echo() the tool node no longer subscribes (topic_info shows no extra reader)."""
    session.add_node(Talker())
    assert len(graph.topic_echo("/chatter", count=2, timeout=10)) == 2
    assert graph.topic_info("/chatter").subscription_count == 0


def test_topic_echo_without_messages_times_out_with_what_it_got(local_session):
    """No publisher: topic_echo() raises a TimeoutError holding the (no) messages received."""
    with pytest.raises(graph.EchoTimeout, match="0 of 1") as caught:
        graph.topic_echo("/silent", msg_type="std_msgs/msg/String", timeout=0.3)
    assert caught.value.messages == []
    with pytest.raises(TimeoutError, match="msg_type="):
        graph.topic_echo("/silent", timeout=0.3)


def test_draw_graph_shows_nodes_and_topics_left_to_right(local_session):
    """draw_graph() draws talker -> /chatter -> listener, and leaves out /rosout and tool node."""
    session.add_node(Talker())
    session.add_node(Listener())
    figure = graph.draw_graph()
    assert isinstance(figure, Figure)
    texts = {t.get_text(): t for t in figure.axes[0].texts if not isinstance(t, Annotation)}
    assert set(texts) == {"/talker", "/chatter", "/listener"}
    x = {name: text.get_position()[0] for name, text in texts.items()}
    assert x["/talker"] < x["/chatter"] < x["/listener"]
    arrows = [t for t in figure.axes[0].texts if isinstance(t, Annotation)]
    assert len(arrows) == 2
    everything = {t.get_text() for t in graph.draw_graph(all=True, hide_topics=()).axes[0].texts}
    assert {"/rosout", "/parameter_events", "/" + session.TOOL_NODE_NAME} <= everything


# --- plain functions --------------------------------------------------------------------

def test_rate_statistics_of_known_arrival_times():
    """Periods 0.1, 0.1, 0.2 s give 7.5 Hz, min 0.1, max 0.2, and a window of 3 periods."""
    stats = graph.rate_statistics([0.0, 0.1, 0.2, 0.4])
    assert stats.rate == pytest.approx(7.5)
    assert (stats.min_period, stats.max_period) == pytest.approx((0.1, 0.2))
    assert stats.std_dev == pytest.approx(np.std([0.1, 0.1, 0.2]))
    assert stats.samples == 3
    assert graph.rate_statistics([0.0, 0.1, 0.2, 0.4], window=1).rate == pytest.approx(5.0)
    with pytest.raises(ValueError, match="at least two"):
        graph.rate_statistics([1.0])


def test_layered_layout_is_layered_and_survives_cycles():
    """Sources sit left of what they feed; a cycle does not stop the layout or make it random."""
    edges = [("cam", "/image"), ("/image", "detector"), ("detector", "/markers"),
             ("/markers", "viewer"), ("viewer", "/image")]
    layout = graph.layered_layout(edges)
    assert graph.layered_layout(list(reversed(edges))) == layout
    assert layout["cam"][0] < layout["/image"][0] < layout["detector"][0] < layout["/markers"][0]
    assert len({position for position in layout.values()}) == len(layout)


def test_format_message_prints_like_ros2_topic_echo():
    """YAML with quoting where needed, nested fields indented, long arrays cut with '...'."""
    assert graph.format_message(String(data="a: b")) == "data: 'a: b'\n"
    image = Image(height=1, width=200, encoding="mono8", step=200, data=bytes(range(200)))
    text = graph.format_message(image, truncate_length=3)
    assert "header:\n  stamp:\n    sec: 0\n" in text
    assert "data:\n- 0\n- 1\n- 2\n- '...'\n" in text
    assert graph.message_to_dict(image, truncate_length=None)["data"] == list(range(200))


def test_echo_options_shorten_strings_and_arrays_like_ros2_topic_echo():
    """Long strings are cut like arrays; --no-arr and --no-str leave only types and lengths."""
    image = Image(height=1, width=4, encoding="mono8", step=4, data=bytes(4))
    assert graph.message_to_dict(String(data="abcdef"), truncate_length=3) == {"data": "abc..."}
    assert graph.message_to_dict(String(data="abcdef"), no_str=True) == {"data": "<string length: <6>>"}
    assert graph.message_to_dict(image, no_arr=True)["data"] == "<sequence type: uint8, length: 4>"
    assert graph.message_to_dict(image, no_arr=True)["encoding"] == "mono8"


def test_fill_message_reads_values_the_way_ros2_topic_pub_does():
    """Nested dicts, lists of messages, ints for floats, and `header: auto` become a message."""
    from geometry_msgs.msg import PolygonStamped

    msg = PolygonStamped()
    setters = graph.fill_message(msg, {"header": "auto", "polygon": {"points": [{"x": 1, "y": 2.5}, {}]}})
    assert [(point.x, point.y) for point in msg.polygon.points] == [(1.0, 2.5), (0.0, 0.0)]
    assert len(setters) == 1
    setters[0](graph.message_class("builtin_interfaces/msg/Time")(sec=7))
    assert msg.header.stamp.sec == 7
    image = Image()
    graph.fill_message(image, {"data": [1, 2, 3], "encoding": "mono8"})
    assert list(image.data) == [1, 2, 3] and image.encoding == "mono8"


@pytest.mark.parametrize("values, message", [
    ({"dta": 5}, "has no field 'dta'; its fields are: data"),
    ({"data": "five"}, "data is a int32 and cannot take 'five'"),
    ([5], "The message is a std_msgs/msg/Int32 and needs a dictionary of its fields"),
])
def test_fill_message_names_the_field_that_does_not_fit(values, message):
    from std_msgs.msg import Int32

    with pytest.raises(ValueError, match=message):
        graph.fill_message(Int32(), values)


def test_node_info_lists_topics_and_services_like_ros2_node_info(local_session):
    """A talker's info shows its publisher, its parameter services and empty sections."""
    session.add_node(Talker(name="info_talker", topic="info_chatter"))
    info = graph.node_info("info_talker")
    assert ("/info_chatter", ["std_msgs/msg/String"]) in info.publishers
    assert ("/info_talker/get_parameters", ["rcl_interfaces/srv/GetParameters"]) in info.service_servers
    text = graph.format_node_info(info)
    assert text.startswith("/info_talker\n  Subscribers:\n\n  Publishers:\n")
    assert "    /info_chatter: std_msgs/msg/String\n" in text
    assert text.endswith("  Action Servers:\n\n  Action Clients:\n\n")
    with pytest.raises(ValueError, match="Unable to find node '/nobody'"):
        graph.node_info("/nobody", timeout=0.2)


def test_message_class_reads_both_name_forms_and_names_the_missing_package():
    """'std_msgs/msg/String' and 'std_msgs/String' both work; a missing package names its pip."""
    assert graph.message_class("std_msgs/msg/String") is String
    assert graph.message_class("std_msgs/String") is String
    with pytest.raises(ValueError, match="ros-jazzy-nope-msgs"):
        graph.message_class("nope_msgs/msg/Thing")
    with pytest.raises(ValueError, match="package/msg/Type"):
        graph.message_class("String")


def test_wait_for_publisher_says_plainly_that_nothing_publishes(local_session):
    """Before waiting for frames: no publisher is an error that names the topic and the fix
    (after a kernel restart the camera is gone), not '0 frames received' later."""
    from std_msgs.msg import String

    with pytest.raises(graph.NoPublisher, match=r"No node publishes on /camera/image_raw .* run the camera cell"):
        graph.wait_for_publisher("/camera/image_raw", timeout=0.2, hint="run the camera cell")
    node = session.add_node(Node("camera_stand_in"))
    node.create_publisher(String, "/camera/image_raw", 10)
    assert graph.wait_for_publisher("/camera/image_raw", timeout=5) == 1
