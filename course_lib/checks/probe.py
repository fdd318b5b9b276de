"""The checker's ROS node in a check's domain (:class:`RosProbe`)."""

from __future__ import annotations

import os

from course_lib import waiting


class RosProbe:
    """The checker's side of a ROS exchange: a node in its own context, spun in bounded steps."""

    def __init__(self, domain_id: int):
        import rclpy
        from rclpy.context import Context as RclContext
        from rclpy.executors import SingleThreadedExecutor

        self.context = RclContext()
        rclpy.init(context=self.context, domain_id=domain_id)
        self.node = rclpy.create_node(f"autograder_probe_{os.getpid()}", context=self.context,
                                      enable_rosout=False, start_parameter_services=False)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)

    def spin_until(self, condition, timeout: float) -> bool:
        """Process callbacks until condition() is true or `timeout` seconds pass; returns condition()."""
        return waiting.spin_until(condition, timeout, executor=self.executor)

    def resend_until(self, publisher, msg, condition, timeout: float, every: float = 0.3) -> bool:
        """Publish `msg` every `every` seconds (best effort may drop one) and process callbacks,
        until condition() is true or `timeout` seconds pass; returns condition()."""
        import time

        end = time.monotonic() + timeout
        while not condition():
            left = end - time.monotonic()
            if left <= 0:
                return bool(condition())
            publisher.publish(msg)
            self.spin_until(condition, min(every, left))
        return True

    def spin_for(self, seconds: float) -> None:
        self.spin_until(lambda: False, seconds)

    def wait_for_subscriber(self, publisher, timeout: float) -> bool:
        return self.spin_until(lambda: publisher.get_subscription_count() > 0, timeout)

    def wait_for_publisher(self, subscription, timeout: float) -> bool:
        return self.spin_until(lambda: subscription.get_publisher_count() > 0, timeout)

    def close(self) -> None:
        try:
            from course_lib.ros import teardown

            self.executor.shutdown(timeout_sec=1.0)
            teardown.destroy_node(self.node)  # with the action clients a check made on it
        finally:
            self.context.try_shutdown()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
