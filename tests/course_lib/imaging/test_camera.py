"""Tests for course_lib.imaging.camera: the webcam node publishes real Images over Fast DDS."""

import time

import cv2
import numpy as np
import pytest
import rclpy
from builtin_interfaces.msg import Time
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Image

from course_lib.imaging import camera, marker_board
from course_lib.imaging.images import msg_to_image


def receive_frames(domain_id, count, **parameters):
    """Run a WebcamNode and a subscriber in one executor until `count` frames arrived.

    The node runs on simulated time (use_sim_time): the /clock here moves on by one period of the
    node's timer once the previous frame has arrived, so the frames and their stamps follow the
    timer and not how soon a busy machine runs it (60 s per frame only bound a run whose frames
    stop).
    """
    received = []
    context = rclpy.Context()  # own context: no interference with other tests in this process
    rclpy.init(context=context, domain_id=domain_id)
    try:
        overrides = [Parameter(name, value=value) for name, value in {**parameters, "use_sim_time": True}.items()]
        webcam = camera.WebcamNode(context=context, parameter_overrides=overrides)
        viewer = Node("viewer", context=context)
        viewer.create_subscription(Image, "image", received.append, 10)
        clock = viewer.create_publisher(Clock, "/clock", 10)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(webcam)
        executor.add_node(viewer)
        (timer,) = webcam.timers
        now_ns = 0
        while len(received) < count:
            now_ns += timer.timer_period_ns
            clock.publish(Clock(clock=Time(sec=now_ns // 10**9, nanosec=now_ns % 10**9)))
            waited_for, deadline = len(received) + 1, time.monotonic() + 60.0
            while len(received) < waited_for and time.monotonic() < deadline:
                executor.spin_once(timeout_sec=0.1)
            if len(received) < waited_for:
                break
        executor.shutdown()
        webcam.destroy_node()
        viewer.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)
    assert len(received) >= count, f"received {len(received)} of {count} frames; the last for 60 s"
    return received


def stamps(messages):
    return np.array([m.header.stamp.sec + m.header.stamp.nanosec * 1e-9 for m in messages])


def test_simulated_frames_arrive_with_size_encoding_frame_and_rate(domain_id):
    messages = receive_frames(domain_id, 12, rate=20.0, width=320, height=240)
    for msg in messages:
        assert (msg.width, msg.height, msg.encoding) == (320, 240, "bgr8")
        assert msg.header.frame_id == "camera"
    frames = [msg_to_image(m) for m in messages]
    assert frames[0].shape == (240, 320, 3)
    assert not np.array_equal(frames[0], frames[-1]), "the simulated camera moves"
    # Markers are in view: the frames are the marker scenes.
    _, ids, _ = marker_board.detector().detectMarkers(frames[-1])
    assert ids is not None and len(ids) >= 4
    # A frame per period of the node's clock (simulated here), stamped with that clock.
    assert np.allclose(np.diff(stamps(messages)), 1 / 20.0), stamps(messages)


def test_a_video_file_is_played_and_resized(domain_id, tmp_path):
    path = str(tmp_path / "clip.avi")
    writer = cv2.VideoWriter(path, cv2.VideoWriter_fourcc(*"MJPG"), 10, (160, 120))
    assert writer.isOpened(), "OpenCV can write MJPG .avi files"
    for level in (40, 120, 200):
        writer.write(np.full((120, 160, 3), level, np.uint8))
    writer.release()
    messages = receive_frames(domain_id, 5, rate=30.0, width=80, height=60, source=path)
    levels = [int(np.median(msg_to_image(m))) for m in messages]
    assert all((m.width, m.height) == (80, 60) for m in messages)
    assert {40, 120, 200} <= {round(level / 40) * 40 for level in levels}, levels  # the clip loops


@pytest.mark.parametrize("overrides, message", [
    ({"rate": 0.0}, "rate must be above 0"),
    ({"source": "/no/such/clip.avi"}, "sim for the simulated camera"),
    ({"source": "97"}, "source:=sim"),
])
def test_bad_parameters_are_refused_with_the_fix(domain_id, overrides, message):
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain_id)
    try:
        with pytest.raises(ValueError, match=message):
            camera.WebcamNode(context=context,
                              parameter_overrides=[Parameter(k, value=v) for k, v in overrides.items()])
    finally:
        rclpy.try_shutdown(context=context)


def test_snapshot_service_writes_the_last_frame_and_says_where(domain_id, tmp_path):
    """/image_publisher/snapshot (std_srvs/Trigger) over DDS: refused before the first frame, then
    the last published frame as a PNG, its path in the response's message."""
    from std_srvs.srv import Trigger

    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain_id)
    try:
        overrides = [Parameter("width", value=160), Parameter("height", value=120), Parameter("rate", value=0.01),
                     Parameter("snapshot_dir", value=str(tmp_path / "shots"))]
        webcam = camera.WebcamNode(context=context, parameter_overrides=overrides)
        caller = Node("caller", context=context)
        client = caller.create_client(Trigger, "/image_publisher/snapshot")
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(webcam)
        executor.add_node(caller)

        def call():
            future = client.call_async(Trigger.Request())
            executor.spin_until_future_complete(future, timeout_sec=30.0)
            assert future.done(), "the snapshot service did not answer within 30 s"
            return future.result()

        assert client.wait_for_service(timeout_sec=30.0)
        early = call()
        assert not early.success and "no frame published yet" in early.message
        webcam._publish_frame()
        answer = call()
        executor.shutdown()
        webcam.destroy_node()
        caller.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)
    assert answer.success, answer.message
    assert answer.message == str(tmp_path / "shots" / "snapshot_0001.png")
    assert np.array_equal(cv2.imread(answer.message), webcam._last_frame)
