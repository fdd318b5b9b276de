"""course_lib.notebook.rviz.view on real topics: what the view sends the browser, through TF.

Publishers in the notebook session (real rclpy nodes over DDS, a domain of the module's own) send a
scan of a wall, a marker and transforms as geometry_msgs/TransformStamped on a topic of the test's
own (tf2_msgs, and so /tf, is not on PyPI yet). The browser's side is a recorder that answers every
drawing at once, as rviz.js does once it has drawn it; tests/test_rviz_browser.py draws them for real.
"""

import math

import numpy as np
import pytest
from geometry_msgs.msg import TransformStamped
from process_support import wait_until
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import LaserScan
from visualization_msgs.msg import Marker

from course_lib.notebook.rviz import view as rviz_view
from course_lib.ros import session

WALL = 2.0  # metres ahead of the laser

pytestmark = pytest.mark.skipif(not rviz_view.BUNDLE.exists(), reason=f"no {rviz_view.BUNDLE}: {rviz_view.BUNDLE_FIX}")


class Robot(Node):
    """Publishes what the test tells it to: scans on /scan, markers, transforms on /test_tf."""

    def __init__(self):
        super().__init__("rviz_test_robot")
        self.scans = self.create_publisher(LaserScan, "scan", qos_profile_sensor_data)
        self.markers = self.create_publisher(Marker, "visualization_marker", 10)
        self.transforms = self.create_publisher(TransformStamped, "test_tf", 10)

    def scan(self, beams=720):
        msg = LaserScan(angle_min=-math.pi, angle_increment=2 * math.pi / beams, range_min=0.1, range_max=10.0)
        msg.header.frame_id = "laser"
        angles = msg.angle_min + msg.angle_increment * np.arange(beams)
        msg.ranges = np.where(np.abs(angles) < math.radians(45), WALL / np.cos(angles), np.inf).tolist()
        self.scans.publish(msg)

    def transform(self, parent, child, x=0.0, y=0.0):
        msg = TransformStamped(child_frame_id=child)
        msg.header.frame_id = parent
        msg.transform.translation.x, msg.transform.translation.y = x, y
        msg.transform.rotation.w = 1.0
        self.transforms.publish(msg)

    def marker(self, action=Marker.ADD, x=1.0, y=-1.0):
        msg = Marker(type=Marker.CUBE, ns="boxes", id=7, action=action)
        msg.header.frame_id = "odom"
        msg.pose.position.x, msg.pose.position.y = x, y
        msg.pose.orientation.w = 1.0
        msg.scale.x = msg.scale.y = msg.scale.z = 0.5
        msg.color.r, msg.color.a = 1.0, 1.0
        self.markers.publish(msg)


class Browser:
    """Stands in for rviz.js: takes each drawing the view sends and answers that it was drawn."""

    def __init__(self, view):
        self.view, self.messages = view, []
        view.widget.send = self.receive
        view._on_browser(view.widget, {"kind": "ready"}, [])

    def receive(self, content, buffers):
        self.messages.append((content, buffers))
        self.view._on_browser(self.view.widget, {"kind": "drawn", "seq": content["seq"], "frames": 1}, [])

    def layer(self, name):
        """The newest drawing of a layer: its items with their arrays decoded."""
        for content, buffers in reversed(self.messages):
            if name in content["layers"]:
                return [{key: np.frombuffer(buffers[value["buffer"]], value["dtype"]).reshape(value["shape"])
                         if isinstance(value, dict) else value for key, value in item.items()}
                        for item in content["layers"][name]]
        return None


@pytest.fixture(scope="module")
def robot(session_domain):
    node = session.add_node(Robot())
    yield node
    rviz_view.stop_all()


@pytest.fixture
def view(robot):
    view = rviz_view.RViz("odom", name="test", transform_topics=["/test_tf"], seconds=300)
    wait_until(lambda: robot.count_subscribers("test_tf") >= 1)
    yield view
    view.stop()


def test_a_scan_without_a_transform_is_not_drawn_and_the_status_says_why_in_rvizs_words(robot, view):
    browser = Browser(view)
    scan = view.add("LaserScan", topic="/scan")
    assert wait_until(lambda: robot.count_subscribers("scan") >= 1)
    assert wait_until(lambda: robot.scan() or scan.status[1] == "No transform from [laser] to [odom]")
    assert scan.status[0] == "error" and browser.layer("LaserScan") == []
    shown = [d for d in view.widget.displays if d["name"] == "LaserScan"]
    assert shown == [{"name": "LaserScan", "kind": "LaserScan", "topic": "/scan", "level": "error",
                      "status": "No transform from [laser] to [odom]"}]

    # The laser 0.5 m ahead of base_link, base_link at x = 1 in odom: the wall stands at x = 3.5.
    def wall_drawn():
        robot.transform("odom", "base_link", x=1.0)
        robot.transform("base_link", "laser", x=0.5)
        robot.scan()
        layer = browser.layer("LaserScan")
        return bool(layer) and len(layer[0]["positions"]) > 0
    assert wait_until(wall_drawn)
    (points,) = browser.layer("LaserScan")
    assert np.allclose(points["positions"][:, 0], 3.5, atol=1e-4)
    assert scan.status == ("ok", f"{len(points['positions'])} points of 720 beams")


def test_a_marker_appears_at_its_pose_and_delete_removes_it(robot, view):
    browser = Browser(view)
    view.add("Marker")
    assert wait_until(lambda: robot.count_subscribers("visualization_marker") >= 1)
    assert wait_until(lambda: robot.marker() or browser.layer("Marker"))
    (cube,) = browser.layer("Marker")
    assert cube["shape"] == "cube" and np.allclose((cube["matrices"][0] @ [0.5, 0, 0, 1])[:3], [1.25, -1, 0])
    assert view.displays["Marker"].status == ("ok", "1 markers (boxes: 1)")
    assert wait_until(lambda: robot.marker(Marker.DELETE) or browser.layer("Marker") == [])


def test_removing_a_display_clears_its_drawing_and_ends_its_subscription(robot, view):
    browser = Browser(view)
    view.add("Grid")
    view.add("PoseStamped", topic="/rviz_test_pose")
    assert wait_until(lambda: browser.layer("Grid"))
    assert wait_until(lambda: robot.count_publishers("rviz_test_pose") or robot.count_subscribers("rviz_test_pose"))
    view.remove("Grid")
    view.remove(view.displays["PoseStamped"])
    assert wait_until(lambda: browser.layer("Grid") == [])
    assert wait_until(lambda: robot.count_subscribers("rviz_test_pose") == 0)
    assert view.widget.displays == []
    with pytest.raises(KeyError, match="No display named 'Grid'"):
        view.remove("Grid")


def test_a_browser_that_does_not_answer_gets_at_most_two_drawings_then_one_a_second(view):
    view._on_browser(view.widget, {"kind": "ready"}, [])
    view.sent, view._sent_at = 2, 100.0
    assert not view._may_send(100.5)
    assert view._may_send(100.0 + rviz_view.STALL_SECONDS)
    view._on_browser(view.widget, {"kind": "drawn", "seq": 1}, [])
    assert view._may_send(100.1)


def test_rerunning_the_cell_replaces_the_view_and_its_node(robot):
    first = rviz_view.RViz("odom", name="rerun", seconds=300)
    second = rviz_view.RViz("odom", name="rerun", seconds=300)
    try:
        assert first.stopped and not second.stopped
        names = [node.get_name() for node in session.nodes()]
        assert names.count("_rviz_rerun") == 1
    finally:
        second.stop()


def test_an_unknown_display_kind_lists_the_kinds_there_are(view):
    with pytest.raises(ValueError, match="LaserScan, Marker"):
        view.add("PointCloud3")


def test_encode_sends_arrays_as_buffers_and_the_rest_as_json():
    content, buffers = rviz_view.encode({"a": [{"type": "points", "positions": np.zeros((2, 3), np.float32),
                                                "size": 0.1, "heights": np.ones(2)}]}, seq=4)
    item = content["layers"]["a"][0]
    assert item["positions"] == {"buffer": 0, "dtype": "float32", "shape": [2, 3]} and len(buffers[0]) == 24
    assert item["heights"] == [1.0, 1.0] and content["seq"] == 4
