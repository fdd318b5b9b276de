"""``ros2 run pubsub topic_publisher``: a counter in tutorial_interfaces/MsgTutorial at 10 Hz.

Each message carries the time of publishing (``stamp``) and the counter (``data``: 0, 1, 2, ...)
on topic ``ros_tutorial_msg``, with a queue depth of 100.
"""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tutorial_interfaces.msg import MsgTutorial

TOPIC = 'ros_tutorial_msg'
QUEUE_DEPTH = 100


class TopicPublisher(Node):
    """Publishes MsgTutorial at 10 Hz: stamp = now, data = the counter."""

    def __init__(self):
        super().__init__('topic_publisher')
        ### BEGIN SOLUTION
        self.count = 0
        self.publisher = self.create_publisher(MsgTutorial, TOPIC, QUEUE_DEPTH)
        self.timer = self.create_timer(0.1, self.publish_count)
        ### END SOLUTION

    def publish_count(self) -> None:
        """Publish the counter with the time of publishing, then add one."""
        ### BEGIN SOLUTION
        msg = MsgTutorial()
        msg.stamp = self.get_clock().now().to_msg()
        msg.data = self.count
        self.publisher.publish(msg)
        self.get_logger().info(f'Published message: {msg.data}')
        self.count += 1
        ### END SOLUTION


def main(args=None):
    rclpy.init(args=args)
    node = None
    try:
        node = TopicPublisher()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
