"""course_lib.notebook.rviz.view on real topics: what the view sends the browser, through TF.

Publishers in the notebook session (real rclpy nodes over DDS, a domain of the module's own) send a
scan of a wall, a marker and transforms as geometry_msgs/TransformStamped on a topic of the test's
own (tf2_msgs, and so /tf, is not on PyPI yet). The browser's side is a recorder that answers every
drawing at once, as rviz.js does once it has drawn it; tests/browser/test_rviz_browser.py draws them for real.
"""

import array
import math
from pathlib import Path

import numpy as np
import pytest
from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import Image, LaserScan
from support.process import wait_until
from visualization_msgs.msg import Marker

from course_lib.notebook.rviz import clouds
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

    def scan(self, beams=720, wall=WALL):
        msg = LaserScan(angle_min=-math.pi, angle_increment=2 * math.pi / beams, range_min=0.1, range_max=10.0)
        msg.header.frame_id = "laser"
        angles = msg.angle_min + msg.angle_increment * np.arange(beams)
        msg.ranges = np.where(np.abs(angles) < math.radians(45), wall / np.cos(angles), np.inf).tolist()
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
    """Stands in for rviz.js: takes each drawing the view sends, keeps each layer's newest items
    with their arrays decoded (a ``same`` array is the one before at its place), and answers that
    it was drawn."""

    def __init__(self, view):
        self.view, self.messages, self.layers = view, [], {}
        view.widget.send = self.receive
        view._on_browser(view.widget, {"kind": "ready"}, [])

    def receive(self, content, buffers):
        self.messages.append((content, buffers))
        for name, items in content["layers"].items():
            before = self.layers.get(name, []) + [{}] * len(items)
            self.layers[name] = [{key: self._array(value, buffers, before[index].get(key))
                                  if isinstance(value, dict) else value for key, value in item.items()}
                                 for index, item in enumerate(items)]
        self.view._on_browser(self.view.widget, {"kind": "drawn", "seq": content["seq"], "frames": 1}, [])

    @staticmethod
    def _array(value, buffers, before):
        if value.get("same"):
            assert before is not None, "a `same` array with none before it at its place"
            return before
        return np.frombuffer(buffers[value["buffer"]], value["dtype"]).reshape(value["shape"])

    def layer(self, name):
        """The newest drawing of a layer: its items with their arrays decoded."""
        return self.layers.get(name)


def drawn_positions(item):
    """An item's positions in the fixed frame (moved by its pose, when it has one)."""
    pose = np.asarray(item.get("pose", np.eye(4)))
    return item["positions"] @ pose[:3, :3].T + pose[:3, 3]


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


def test_drawings_in_flight_are_bounded_and_the_browsers_answer_sends_the_newest_at_once(robot, view):
    """Scans that arrive while MAX_IN_FLIGHT drawings are unanswered wait (newest wins); the answer
    sends the newest from its own handler, not a timer."""
    sent = []
    view.widget.send = lambda content, buffers: sent.append(content)
    view._on_browser(view.widget, {"kind": "ready"}, [])
    scan = view.add("LaserScan", topic="/scan")
    view.set_transform("odom", "laser")
    assert wait_until(lambda: robot.count_subscribers("scan") >= 1)
    full = rviz_view.MAX_IN_FLIGHT
    walls = iter(np.arange(1.0, 5.0, 0.001))  # each scan another: a drawing unchanged is not sent
    assert wait_until(lambda: robot.scan(wall=next(walls)) or len(sent) == full)
    received = scan.received
    assert wait_until(lambda: robot.scan(wall=next(walls)) or scan.received > received + 2)
    assert len(sent) == full and scan.changed  # no answer: nothing more
    view._on_browser(view.widget, {"kind": "drawn", "seq": 1}, [])
    assert len(sent) == full + 1 and "LaserScan" in sent[-1]["layers"]  # sent from the answer itself
    view._sent_at = 0.0  # a browser silent for STALL_SECONDS gets the next one anyway
    assert wait_until(lambda: robot.scan(wall=next(walls)) or len(sent) == full + 2)


def test_a_point_cloud_is_drawn_in_the_fixed_frame_with_its_colours(robot, view):
    from sensor_msgs.msg import PointCloud2, PointField

    browser = Browser(view)
    view.set_transform("odom", "camera", (0.0, 0.0, 1.0))
    display = view.add("PointCloud2", topic="/rviz_test_points")
    publisher = robot.create_publisher(PointCloud2, "rviz_test_points", qos_profile_sensor_data)
    xyz = np.random.default_rng(5).uniform(-1, 1, (50_000, 3))
    rgb = np.tile([[0, 128, 255]], (50_000, 1))
    fields, data, step = clouds.xyz_rgb_cloud_bytes(xyz, rgb)
    msg = PointCloud2(height=1, width=50_000, point_step=step, row_step=step * 50_000, is_dense=True,
                      fields=[PointField(name=n, offset=o, datatype=t, count=1) for n, o, t in fields])
    msg.header.frame_id = "camera"
    msg.data = array.array("B", data)
    assert wait_until(lambda: publisher.get_subscription_count() >= 1)
    assert wait_until(lambda: publisher.publish(msg) or browser.layer("PointCloud2"))
    (points,) = browser.layer("PointCloud2")
    assert np.allclose(drawn_positions(points), xyz + [0, 0, 1], atol=1e-6)
    assert points["colors"][0].tolist() == [0, 128, 255, 255] and display.status == ("ok", "50000 points")
    robot.destroy_publisher(publisher)


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
    with pytest.raises(ValueError, match="LaserScan, PointCloud2, Marker"):
        view.add("PointCloud3")


def test_encode_sends_arrays_as_buffers_and_the_rest_as_json():
    content, buffers = rviz_view.encode({"a": [{"type": "points", "positions": np.zeros((2, 3), np.float32),
                                                "size": 0.1, "heights": np.ones(2)}]}, seq=4)
    item = content["layers"]["a"][0]
    assert item["positions"] == {"buffer": 0, "dtype": "float32", "shape": [2, 3]} and len(buffers[0]) == 24
    assert item["heights"] == [1.0, 1.0] and content["seq"] == 4


def test_encode_leaves_out_a_layer_drawn_exactly_as_it_was_last_sent():
    last = {}
    grid = [{"type": "lines", "positions": np.zeros((2, 3), np.float32)}]
    scan = [{"type": "points", "positions": np.ones((1, 3), np.float32)}]
    content, buffers = rviz_view.encode({"Grid": grid, "Scan": scan}, 1, last)
    assert content["layers"]["Scan"][0]["positions"]["buffer"] == 1 and len(buffers) == 2
    scan[0]["positions"] = np.full((1, 3), 2, np.float32)
    content, buffers = rviz_view.encode({"Grid": grid, "Scan": scan}, 2, last)
    assert list(content["layers"]) == ["Scan"] and content["layers"]["Scan"][0]["positions"]["buffer"] == 0


def test_encode_sends_an_array_as_it_was_at_its_place_as_same_and_a_new_pose_alone():
    """A cloud that moved sends its positions and not its unchanged colours; a new transform, its pose."""
    last, colors = {}, np.full((3, 4), 255, np.uint8)
    cloud = {"type": "points", "positions": np.zeros((3, 3), np.float32), "colors": colors, "pose": np.eye(4)}
    rviz_view.encode({"Cloud": [cloud]}, 1, last)
    moved = dict(cloud, positions=np.ones((3, 3), np.float32), colors=colors.copy())
    content, buffers = rviz_view.encode({"Cloud": [moved]}, 2, last)
    (item,) = content["layers"]["Cloud"]
    assert item["colors"] == {"same": True} and item["positions"]["buffer"] == 0 and len(buffers) == 1
    turned = dict(moved, pose=np.diag([-1.0, -1.0, 1.0, 1.0]))
    content, buffers = rviz_view.encode({"Cloud": [turned]}, 3, last)
    (item,) = content["layers"]["Cloud"]
    assert item["positions"] == item["colors"] == {"same": True} and buffers == []
    assert item["pose"][0] == [-1.0, 0.0, 0.0, 0.0]


def test_frames_from_tf_and_tf_static_place_the_robot_and_its_laser(robot, view):
    """TFMessage on /tf_static (latched, sent before the view listens) and /tf, as the simulator
    sends them: odom -> base_link -> laser at husky.LASER_OFFSET; the robot's box stands on base_link."""
    from rclpy.qos import DurabilityPolicy, QoSProfile
    from tf2_msgs.msg import TFMessage

    from course_lib.robot import husky

    def stamped(parent, child, x, y, z):
        msg = TransformStamped(child_frame_id=child)
        msg.header.frame_id = parent
        msg.transform.translation.x, msg.transform.translation.y, msg.transform.translation.z = x, y, z
        msg.transform.rotation.w = 1.0
        return msg

    latched_qos = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    latched = robot.create_publisher(TFMessage, "/tf_static", latched_qos)
    moving = robot.create_publisher(TFMessage, "/tf", 100)
    latched.publish(TFMessage(transforms=[stamped(husky.BASE_FRAME, husky.LASER_FRAME, *husky.LASER_OFFSET)]))
    tf_view = rviz_view.RViz(husky.ODOM_FRAME, name="tf_test", seconds=300)
    try:
        browser = Browser(tf_view)
        tf_view.add("TF")
        tf_view.add("RobotModel")
        assert wait_until(lambda: husky.LASER_FRAME in tf_view.tree.frames())  # latched: no second send
        assert wait_until(lambda: moving.publish(TFMessage(transforms=[stamped("odom", "base_link", 2.0, 1.0, 0.0)]))
                          or tf_view.displays["TF"].status == ("ok", "3 frames"))
        assert np.allclose(tf_view.tree.lookup("odom", "laser")[:3, 3], [2.35, 1.0, 0.4])
        assert wait_until(lambda: browser.layer("RobotModel") and
                          np.allclose(browser.layer("RobotModel")[0]["matrices"][0][:3, 3], [2.0, 1.0, 0.195]))
        (box,) = browser.layer("RobotModel")
        assert np.allclose(np.diag(box["matrices"][0])[:3], [0.99, 0.67, 0.39])
    finally:
        tf_view.stop()
        robot.destroy_publisher(latched)
        robot.destroy_publisher(moving)


def test_an_image_is_sent_as_a_jpeg_of_its_picture_for_the_2d_panel(robot, view):
    import cv2

    from course_lib.imaging.images import image_to_msg

    browser = Browser(view)
    display = view.add("Image", topic="/rviz_test_image", width=200)
    publisher = robot.create_publisher(Image, "rviz_test_image", qos_profile_sensor_data)
    picture = np.zeros((60, 80, 3), np.uint8)
    picture[:, 40:] = (0, 0, 255)  # right half red (BGR)
    assert wait_until(lambda: publisher.get_subscription_count() >= 1)
    assert wait_until(lambda: publisher.publish(image_to_msg(picture, "bgr8")) or browser.layer("Image"))
    (item,) = browser.layer("Image")
    shown = cv2.imdecode(item["jpeg"], cv2.IMREAD_COLOR)
    assert shown.shape == (60, 80, 3) and item["width"] == 200 and item["aspect"] == 0.75
    assert shown[30, 10].max() < 20 and shown[30, 70, 2] > 230 and display.status == ("ok", "80×60 bgr8")
    robot.destroy_publisher(publisher)


def test_the_tools_publish_a_goal_pose_and_a_clicked_point_in_the_fixed_frame(robot, view):
    """What rviz.js sends after a drag (2D Goal Pose) or a click (Publish Point) reaches real subscribers."""
    from geometry_msgs.msg import PointStamped, PoseStamped

    got = {}
    goals = robot.create_subscription(PoseStamped, "/goal_pose", lambda msg: got.setdefault("goal", msg), 10)
    points = robot.create_subscription(PointStamped, "/clicked_point", lambda msg: got.setdefault("point", msg), 10)
    view.set_fixed_frame("map")

    def use_tools():  # the first messages may go before the new publishers have met the subscribers
        view._on_browser(view.widget, {"kind": "tool", "tool": "2D Goal Pose", "point": [1.0, 2.0, 0.0],
                                       "yaw": math.pi / 2}, [])
        view._on_browser(view.widget, {"kind": "tool", "tool": "Publish Point", "point": [3.0, -1.0, 0.0]}, [])
        return len(got) == 2
    assert wait_until(use_tools)
    goal, point = got["goal"], got["point"]
    assert goal.header.frame_id == "map" and (goal.pose.position.x, goal.pose.position.y) == (1.0, 2.0)
    assert np.allclose([goal.pose.orientation.z, goal.pose.orientation.w], math.sqrt(0.5))
    assert point.header.frame_id == "map" and (point.point.x, point.point.y, point.point.z) == (3.0, -1.0, 0.0)
    assert view.widget.fixed_frame == "map"
    with pytest.raises(ValueError, match="Move Camera, 2D Goal Pose, Publish Point"):
        view.set_tool("Measure")
    robot.destroy_subscription(goals)
    robot.destroy_subscription(points)


def test_choosing_a_frame_in_the_views_list_redraws_in_that_frame(robot, view):
    browser = Browser(view)
    view.set_transform("map", "odom", (5.0, 0.0, 0.0))
    view.add("Grid", cells=2, frame="odom")  # RViz's Grid "Reference Frame"
    assert wait_until(lambda: browser.layer("Grid"))
    assert wait_until(lambda: view.widget.frames == ["map", "odom"])
    view.widget.fixed_frame = "map"  # as the browser's list sets it
    assert view.fixed_frame == "map"
    assert wait_until(lambda: np.isclose(browser.layer("Grid")[0]["positions"][:, 0].mean(), 5.0))


def test_a_saved_configuration_and_an_rviz_file_load_into_a_view_with_their_subscriptions(robot, view, tmp_path,
                                                                                          capsys):
    view.add("LaserScan", topic="/scan", size=0.1)
    view.set_fixed_frame("base_link")
    view.set_camera("top", scale=30)
    path = view.save_config(tmp_path / "view.yaml")
    view.load_config(Path(__file__).with_name("rviz_files") / "mobile_robot.rviz")
    assert view.fixed_frame == "odom" and view.widget.camera["scale"] == 40.0
    assert "PointCloud2" in [d.kind for d in view.displays.values()]
    assert wait_until(lambda: robot.count_publishers("camera/depth/points") + robot.count_subscribers(
        "camera/depth/points") >= 1)
    assert "Map (rviz_default_plugins/Map: no such display in this view)" in capsys.readouterr().out
    assert view.load_config(path) == []
    assert [(d.kind, d.topic, d.options) for d in view.displays.values()] == [("LaserScan", "/scan", {"size": 0.1})]
    assert view.fixed_frame == "base_link" and view.widget.camera == {"mode": "top", "scale": 30}
    assert wait_until(lambda: robot.count_subscribers("camera/depth/points") == 0)
