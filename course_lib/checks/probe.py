"""The checker's ROS node in a check's domain (:class:`RosProbe`)."""

from __future__ import annotations

import os
import time
from pathlib import Path

from course_lib.checks.student_processes import _student_uid


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
        if _student_uid() is not None:
            _share_shared_memory()

    def spin_until(self, condition, timeout: float) -> bool:
        """Process callbacks until condition() is true or `timeout` seconds pass; returns condition()."""
        deadline = time.monotonic() + timeout
        while not condition():
            left = deadline - time.monotonic()
            if left <= 0:
                return bool(condition())
            self.executor.spin_once(timeout_sec=min(0.05, left))
        return True

    def spin_for(self, seconds: float) -> None:
        self.spin_until(lambda: False, seconds)

    def wait_for_subscriber(self, publisher, timeout: float) -> bool:
        return self.spin_until(lambda: publisher.get_subscription_count() > 0, timeout)

    def wait_for_publisher(self, subscription, timeout: float) -> bool:
        return self.spin_until(lambda: subscription.get_publisher_count() > 0, timeout)

    def close(self) -> None:
        try:
            self.executor.shutdown(timeout_sec=1.0)
            self.node.destroy_node()
        finally:
            self.context.try_shutdown()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _share_shared_memory() -> None:
    """Let the student's uid use this (root) process's Fast DDS shared-memory files.

    Fast DDS creates its segments, ports and port mutexes 0644, so a node of another uid can
    neither deliver into a root participant's port nor release buffers in its segment: root and
    student nodes would not even discover each other. The grader's /dev/shm is a private tmpfs of
    the submission's sandbox, so opening this process's files to "others" opens them to that
    student's processes only.
    """
    me = os.geteuid()
    for path in Path("/dev/shm").glob("*fastrtps_*"):
        try:
            if path.stat().st_uid == me:
                os.chmod(path, 0o666)
        except OSError:  # another participant's file went away meanwhile
            pass
