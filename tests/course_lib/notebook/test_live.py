"""Tests for course_lib.notebook.live: live image views (rqt_image_view) and plots (rqt_plot) on real topics.

One camera process (course_lib.imaging.camera) and one in-session publisher of numbers and known frames
serve the whole module, in a ROS domain of its own.
"""

import threading
import time

import cv2
import numpy as np
import pytest
from geometry_msgs.msg import PoseStamped
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import Image
from std_msgs.msg import Float64, UInt8

from course_lib.imaging import images
from course_lib.notebook import live
from course_lib.ros import graph, processes, rosenv, session

CAMERA_SIZE = (320, 240)


class Numbers(Node):
    """Publishes a counter as Float64 on /level, in a PoseStamped on /pose and as grey frames on /grey."""

    def __init__(self):
        super().__init__("numbers")
        self.count = 0
        self.level = self.create_publisher(Float64, "level", 10)
        self.pose = self.create_publisher(PoseStamped, "pose", 10)
        self.grey = self.create_publisher(Image, "grey", qos_profile_sensor_data)
        self.create_timer(0.05, self.tick)

    def tick(self):
        self.count += 1
        self.level.publish(Float64(data=float(self.count)))
        msg = PoseStamped()
        msg.pose.position.x = -float(self.count)
        self.pose.publish(msg)
        # Grey levels 40, 80, ..., 200 in turn: a frame's brightness says which one it was.
        self.grey.publish(images.image_to_msg(np.full((60, 80), 40 * (1 + self.count % 5), np.uint8), "mono8"))


@pytest.fixture(scope="module")
def ros(session_domain):
    """The session on a reserved domain, the Numbers node in it and a camera process; yields the camera."""
    try:
        session.add_node(Numbers())
        width, height = CAMERA_SIZE
        with processes.python_node("course_lib.imaging.camera:main", "--ros-args", "-p", f"width:={width}", "-p",
                                   f"height:={height}", "-p", "rate:=15.0", name="live-test-camera",
                                   domain_id=session_domain) as camera:
            camera.wait_for_node("image_publisher", timeout=60)
            graph.topic_list(wait_for=["/image", "/level", "/pose", "/grey"], timeout=20)
            yield camera
    finally:
        live.stop_all()


def watch(widget) -> list:
    """Every value the widget takes from now on (set from the session's thread)."""
    values = []
    lock = threading.Lock()

    def changed(change):
        with lock:
            values.append(change["new"])
    widget.observe(changed, names="value")
    return values


def decode(data: bytes) -> np.ndarray:
    picture = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED)
    assert picture is not None, f"the widget holds {len(data)} bytes that are no picture"
    return picture


# --- image views ---------------------------------------------------------------------------

def test_image_view_picture_follows_the_camera_frames(ros):
    view = live.image_view("/image", updates=4)
    shown = watch(view.image)
    assert session.wait_for(lambda: view.stopped, timeout=20), (view.status.value, ros.log_tail())
    assert view.stop_reason == "stopped after 4 updates"
    assert len(shown) == 4 and len(set(shown)) == 4, "each redraw shows a new frame"
    first, last = decode(shown[0]), decode(shown[-1])
    assert first.shape == (CAMERA_SIZE[1], CAMERA_SIZE[0], 3) and view.image.format == "jpeg"
    assert np.abs(first.astype(int) - last).mean() > 1, "the simulated camera moves between redraws"
    assert "/image · 320x240 bgr8" in view.status.value


def test_the_picture_shows_the_frame_that_arrived(ros):
    view = live.image_view("/grey", updates=3)
    shown = watch(view.image)
    assert session.wait_for(lambda: view.stopped, timeout=20), view.status.value
    levels = {round(float(decode(data).mean())) for data in shown}
    assert levels <= {40, 80, 120, 160, 200}, f"grey levels shown: {levels}"


def test_redraws_are_throttled_to_max_rate_and_skip_frames_in_between(ros):
    began = time.monotonic()
    view = live.image_view("/image", max_rate=2.0, updates=1000, seconds=300)
    try:
        # The 15 Hz camera's frames come faster than two redraws a second: a frame between two
        # redraws is skipped, not queued (a view that redrew every frame never gets here).
        assert session.wait_for(lambda: view.updates >= 3 and view.frames > view.updates, timeout=60), \
            (view.updates, view.frames, view.status.value)
    finally:
        view.stop()
    elapsed = time.monotonic() - began
    assert view.updates <= 2.0 * elapsed + 1, "never more redraws than max_rate allows"


def test_stop_ends_the_updates_and_removes_the_views_node(ros):
    view = live.image_view("/image", updates=1000)
    assert session.wait_for(lambda: view.updates >= 1, timeout=20), view.status.value
    view.stop()
    assert view.stopped and all(node.get_name() != view.node_name for node in session.nodes())
    frozen, frames = view.image.value, view.frames
    session.spin_for(0.5)
    assert view.image.value == frozen and view.frames == frames
    assert view.status.value.endswith("stopped")


def test_a_new_view_of_the_same_topic_replaces_the_old_one(ros):
    """Re-running a cell leaves one view: the old one says it was replaced and stops."""
    old = live.image_view("/image", updates=1000)
    new = live.image_view("/image", updates=1000)
    try:
        assert old.stopped and old.stop_reason == "replaced by a new view"
        assert [n.get_name() for n in session.nodes()].count(new.node_name) == 1
        assert session.wait_for(lambda: new.updates >= 1, timeout=20), new.status.value
    finally:
        new.stop()


def test_views_stop_by_themselves_under_test(ros):
    assert rosenv.under_test()
    view = live.image_view("/image")
    assert session.wait_for(lambda: view.stopped, timeout=live.LIMITED_SECONDS + 60)
    assert view.updates <= live.LIMITED_UPDATES


def test_a_topic_that_is_no_image_is_refused_with_what_to_use(ros):
    with pytest.raises(ValueError, match=r"carries std_msgs/msg/Float64, not an image.*live.plot"):
        live.image_view("/level")


def test_frames_for_the_browser_convert_shrink_and_pass_jpeg_through():
    red = np.zeros((20, 40, 3), np.uint8)
    red[..., 0] = 255  # red in RGB order
    data, kind = live.frame_for_browser(images.image_to_msg(red, "rgb8"))
    assert kind == "jpeg" and decode(data)[10, 20].tolist() == pytest.approx([0, 0, 255], abs=8)
    depth = np.arange(1000, 1000 + 20 * 40, dtype=np.uint16).reshape(20, 40)
    shown = decode(live.frame_for_browser(images.image_to_msg(depth, "mono16"))[0])
    assert shown.dtype == np.uint8 and shown.min() < 10 and shown.max() > 245, "16 bits scaled to 0-255"
    wide = images.image_to_msg(np.zeros((1080, 1920, 3), np.uint8))
    assert decode(live.frame_for_browser(wide, max_width=640)[0]).shape == (360, 640, 3)
    compressed = images.image_to_compressed(red, "jpeg", encoding="rgb8")
    assert live.frame_for_browser(compressed) == (bytes(compressed.data), "jpeg")


# --- plots ---------------------------------------------------------------------------------

def test_plot_data_grow_with_the_messages_and_the_picture_is_redrawn(ros):
    view = live.plot("/level", "/pose/pose/position/x", updates=4)
    shown = watch(view.image)
    assert session.wait_for(lambda: view.updates >= 2, timeout=20), view.status.value
    early = {series: len(times) for series, (times, _) in view.data.items()}
    assert session.wait_for(lambda: view.stopped, timeout=20), view.status.value
    data = view.data
    assert view.series == ["/level", "/pose/pose/position/x"]
    for series, (times, values) in data.items():
        assert len(times) == len(values) > early[series] > 0, f"{series} grows while messages arrive"
        assert times == sorted(times)
    levels, xs = data["/level"][1], data["/pose/pose/position/x"][1]
    assert np.all(np.diff(levels) > 0) and np.all(np.diff(xs) < 0), "the counter, and the pose's x = -counter"
    assert len(set(shown)) == len(shown) >= 2 and decode(shown[-1]).ndim == 3, "a new PNG per redraw"


def test_a_plot_of_one_number_message_takes_its_only_field(ros):
    view = live.plot("/brightness", msg_type=UInt8, updates=1)
    assert view.series == ["/brightness"]
    view.stop()


def test_a_topic_missing_from_the_graph_times_out_naming_the_fix(ros):
    with pytest.raises(TimeoutError, match="msg_type="):
        live.plot("/no_such_topic/data", timeout=0.5)
