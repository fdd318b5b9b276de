"""A right answer to lesson 02's exercise (brightness/brightness_node.py), for the tests of its self-check
and of the lesson's commands. It is the lesson's stand-in, not the brightness assignment's solution."""
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import Image
from std_msgs.msg import UInt8

from course_lib.imaging import images


def centre_value(frame):
    """The first channel of a bgr8 frame's centre pixel (row height // 2, column width // 2), as an int."""
    height, width = frame.shape[:2]
    return int(frame[height // 2, width // 2, 0])


class BrightnessNode(Node):
    """Subscribes image; publishes centre_value of every frame on brightness."""

    def __init__(self):
        super().__init__('brightness_node')
        self.publisher = self.create_publisher(UInt8, 'brightness', qos_profile_sensor_data)
        self.subscription = self.create_subscription(Image, 'image', self.on_image, qos_profile_sensor_data)

    def on_image(self, msg):
        self.publisher.publish(UInt8(data=centre_value(images.msg_to_image(msg))))


def main(args=None):
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
