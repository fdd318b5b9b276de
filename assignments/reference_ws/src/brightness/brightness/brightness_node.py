"""Brightness of camera images: a plain numpy function and the node around it.

``ros2 run brightness brightness_node`` subscribes ``/image`` (sensor_msgs/Image) and publishes
the average brightness of every frame on ``/brightness`` (std_msgs/UInt8), both with the
sensor-data QoS.
"""

import numpy as np
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import Image
from std_msgs.msg import UInt8

from course_lib import images
from course_lib.ros import sigterm


def average_brightness(image: np.ndarray) -> int:
    """The mean of all bytes of an image (every channel of every pixel), rounded down, as an int."""
    ### BEGIN SOLUTION
    # One numpy sum instead of a Python loop over millions of bytes; uint64 cannot overflow here.
    return int(image.sum(dtype=np.uint64) // image.size)
    ### END SOLUTION


class BrightnessNode(Node):
    """Subscribes /image and publishes the average brightness of every frame on /brightness."""

    def __init__(self):
        super().__init__("brightness_node")
        ### BEGIN SOLUTION
        self.publisher = self.create_publisher(UInt8, "/brightness", qos_profile_sensor_data)
        self.subscription = self.create_subscription(Image, "/image", self.on_image, qos_profile_sensor_data)
        ### END SOLUTION

    def on_image(self, msg: Image) -> None:
        """Publish the average brightness of one frame."""
        ### BEGIN SOLUTION
        frame = images.msg_to_image(msg)  # mono8: (H, W); bgr8: (H, W, 3); no copy
        self.publisher.publish(UInt8(data=average_brightness(frame)))
        ### END SOLUTION


def main(args=None):
    sigterm.end_spin_as_ctrl_c()  # `kill` ends the node as Ctrl-C does (see course_lib.ros.sigterm)
    rclpy.init(args=args)
    node = None
    try:
        node = BrightnessNode()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
