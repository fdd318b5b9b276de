"""A webcam node: publishes camera frames as sensor_msgs/Image (bgr8) on the topic ``image``.

Where the frames come from is the ``source`` parameter:

- ``sim`` (default): the scene simulator (course_lib.imaging.scenes.CameraPath), a camera drifting over
  the cat-and-dog marker board while the light changes slowly; works on every machine.
- a video file path: its frames, looped.
- a device index such as ``0``: a real camera through cv2.VideoCapture.

Run it as a process (``python -m course_lib.imaging.camera --ros-args -p rate:=15.0``) or create a
``WebcamNode`` in a notebook session.

It offers one service, ``~/snapshot`` (``std_srvs/srv/Trigger``, so ``/image_publisher/snapshot``):
the last frame it published is written as a PNG into the ``snapshot_dir`` folder, and the
response's message is the file's path.
"""

from __future__ import annotations

import os

import cv2
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from sensor_msgs.msg import Image
from std_srvs.srv import Trigger

from course_lib.imaging import frame_memory, images, scenes

FRAME_ID = "camera"


class WebcamNode(Node):
    """Publishes frames on ``image`` at ``rate`` Hz from a timer.

    Parameters:
        rate (double, 30.0): frames per second.
        width, height (int, 640, 480): frame size; frames from files or devices are resized to it.
        source (string, "sim"): "sim", a video file path, or a camera index such as "0".
        seed (int, 0): chooses the simulated camera path.
        snapshot_dir (string, "snapshots"): where ``~/snapshot`` writes its PNG files.

    Raises:
        ValueError: a non-positive rate or size, or a source that cannot be opened (the message
            says what to use instead).
    """

    def __init__(self, **kwargs):
        super().__init__("image_publisher", **kwargs)
        rate = float(self.declare_parameter("rate", 30.0).value)
        width = int(self.declare_parameter("width", 640).value)
        height = int(self.declare_parameter("height", 480).value)
        source = str(self.declare_parameter("source", "sim").value)
        seed = int(self.declare_parameter("seed", 0).value)
        self.snapshot_dir = str(self.declare_parameter("snapshot_dir", "snapshots").value)
        if rate <= 0:
            raise ValueError(f"rate must be above 0 frames per second, not {rate}; for example rate:=30.0")
        if width < 1 or height < 1:
            raise ValueError(f"width and height must be at least 1, not {width}x{height}; for example 640x480")
        self.size = (width, height)
        self.source = source
        self._capture = None
        self._path = None
        if source == "sim":
            self._path = scenes.CameraPath(seed, size=self.size)
        else:
            self._capture = _open_capture(source, self.size)
        self._start = self.get_clock().now()
        self.frames_published = 0
        self._last_frame = None
        self.snapshots = 0
        self._snapshot_service = self.create_service(Trigger, "~/snapshot", self._snapshot)
        self._publisher = self.create_publisher(Image, "image", 10)
        self._timer = self.create_timer(1.0 / rate, self._publish_frame)
        self.get_logger().info(f"Publishing {width}x{height} frames from {source!r} at {rate:g} Hz on "
                               f"{self._publisher.topic_name}")

    def next_frame(self):
        """The next BGR frame of the source (simulated frames follow the node's clock)."""
        if self._path is not None:
            elapsed = (self.get_clock().now() - self._start).nanoseconds / 1e9
            return self._path.scene_at(elapsed).frame
        ok, frame = self._capture.read()
        if not ok and self._capture.get(cv2.CAP_PROP_FRAME_COUNT) > 0:
            self._capture.set(cv2.CAP_PROP_POS_FRAMES, 0)  # a file ended: start again
            ok, frame = self._capture.read()
        if not ok:
            return None
        if (frame.shape[1], frame.shape[0]) != self.size:
            frame = cv2.resize(frame, self.size, interpolation=cv2.INTER_AREA)
        return frame

    def _publish_frame(self):
        frame = self.next_frame()
        if frame is None:
            self.get_logger().warning(f"No frame from {self.source!r}", throttle_duration_sec=5.0)
            return
        msg = images.image_to_msg(frame, "bgr8", stamp=self.get_clock().now(), frame_id=FRAME_ID)
        try:
            self._publisher.publish(msg)
        except Exception:
            # Ctrl-C shuts the context down while a frame is being made: not an error then.
            if self.context.ok():
                raise
            return
        self.frames_published += 1
        self._last_frame = frame

    def _snapshot(self, request, response):
        """Trigger: write the last published frame to snapshot_dir/snapshot_NNNN.png."""
        if self._last_frame is None:
            response.success, response.message = False, "no frame published yet: call again in a moment"
            return response
        os.makedirs(self.snapshot_dir, exist_ok=True)
        self.snapshots += 1
        path = os.path.abspath(os.path.join(self.snapshot_dir, f"snapshot_{self.snapshots:04d}.png"))
        response.success = bool(cv2.imwrite(path, self._last_frame))
        response.message = path if response.success else f"could not write {path}: is snapshot_dir writable?"
        return response

    def destroy_node(self):
        if self._capture is not None:
            self._capture.release()
            self._capture = None
        return super().destroy_node()


def _open_capture(source: str, size) -> cv2.VideoCapture:
    if source.isdigit():
        capture = cv2.VideoCapture(int(source))
        if not capture.isOpened():
            raise ValueError(f"Could not open camera {source}: no such device here; "
                             "use source:=sim for the simulated camera or a video file path")
        capture.set(cv2.CAP_PROP_FRAME_WIDTH, size[0])
        capture.set(cv2.CAP_PROP_FRAME_HEIGHT, size[1])
        return capture
    if not os.path.isfile(source):
        raise ValueError(f"Video file {source!r} does not exist; give a path to a video, a camera "
                         "index such as 0, or sim for the simulated camera")
    capture = cv2.VideoCapture(source)
    if not capture.isOpened():
        raise ValueError(f"OpenCV cannot read the video {source!r}; convert it to MJPG .avi or use source:=sim")
    return capture


def main(args=None):
    # A camera process does one thing: OpenCV's worker threads would make each frame sooner but
    # cost about a fifth more processor (14 instead of 17 ms per 640x480 frame on one thread).
    cv2.setNumThreads(1)
    frame_memory.keep_freed_frames()  # each frame's arrays reuse the last one's memory
    rclpy.init(args=args)
    node = None
    try:
        node = WebcamNode()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
