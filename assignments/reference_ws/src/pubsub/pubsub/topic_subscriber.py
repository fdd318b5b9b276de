"""``ros2 run pubsub topic_subscriber``: logs each field of every MsgTutorial on ros_tutorial_msg.

For each message it logs ``I heard: stamp <sec>.<nanosec> data <data>`` (queue depth 100).
"""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from tutorial_interfaces.msg import MsgTutorial

TOPIC = 'ros_tutorial_msg'
QUEUE_DEPTH = 100


class TopicSubscriber(Node):
    """Subscribes ros_tutorial_msg and logs the stamp and the data of every message."""

    def __init__(self):
        super().__init__('topic_subscriber')
        ### BEGIN SOLUTION
        self.subscription = self.create_subscription(
            MsgTutorial, TOPIC, self.on_message, QUEUE_DEPTH)
        ### END SOLUTION

    def on_message(self, msg: MsgTutorial) -> None:
        """Log each field of one message."""
        ### BEGIN SOLUTION
        self.get_logger().info(
            f'I heard: stamp {msg.stamp.sec}.{msg.stamp.nanosec:09d} data {msg.data}')
        ### END SOLUTION


def main(args=None):
    rclpy.init(args=args)
    node = None
    try:
        node = TopicSubscriber()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
