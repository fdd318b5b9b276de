"""``ros2 run tf2_ros tf2_echo SOURCE TARGET [RATE]``: print, RATE times a second (1 by default),
the newest transform between two frames in tf2_ros's layout (its C++ program is not on PyPI).

As upstream, the transform printed is ``lookup_transform(SOURCE, TARGET)``: the pose of TARGET in
SOURCE's frame, the one that maps TARGET's coordinates into SOURCE's. Until it is known the node
logs ``Waiting for transform SOURCE ->  TARGET: <tf2's reason>`` once a second.
"""

from __future__ import annotations

import math
import sys

USAGE = ("Usage: tf2_echo source_frame target_frame [echo_rate]\n\n"
         "This will echo the transform from the coordinate frame of the source_frame\n"
         "to the coordinate frame of the target_frame. \n"
         "Note: This is the transform to get data from target_frame into the source_frame.\n"
         "Default echo rate is 1 if echo_rate is not given.")


def rotation_matrix(x: float, y: float, z: float, w: float) -> list[list[float]]:
    """The 3×3 rotation matrix of a unit quaternion."""
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def roll_pitch_yaw(matrix: list[list[float]]) -> tuple[float, float, float]:
    """(roll, pitch, yaw) of a rotation matrix, as tf2's Matrix3x3::getEulerYPR."""
    pitch = -math.asin(max(-1.0, min(1.0, matrix[2][0])))
    if abs(matrix[2][0]) >= 1:  # gimbal lock: yaw 0, all the turn in roll
        return (math.atan2(-matrix[0][1], -matrix[0][2]) if matrix[2][0] > 0
                else math.atan2(matrix[0][1], matrix[0][2])), pitch, 0.0
    cos_pitch = math.cos(pitch)
    return (math.atan2(matrix[2][1] / cos_pitch, matrix[2][2] / cos_pitch), pitch,
            math.atan2(matrix[1][0] / cos_pitch, matrix[0][0] / cos_pitch))


def format_transform(transform) -> str:
    """A geometry_msgs/TransformStamped as tf2_echo prints it (3 decimals, a 4×4 matrix)."""
    t, r = transform.transform.translation, transform.transform.rotation
    matrix = rotation_matrix(r.x, r.y, r.z, r.w)
    roll, pitch, yaw = roll_pitch_yaw(matrix)
    degrees = (math.degrees(roll), math.degrees(pitch), math.degrees(yaw))
    rows = [[*matrix[i], (t.x, t.y, t.z)[i]] for i in range(3)] + [[0.0, 0.0, 0.0, 1.0]]
    stamp = transform.header.stamp
    return "\n".join([
        f"At time {stamp.sec}.{stamp.nanosec}",  # upstream prints the nanoseconds unpadded
        f"- Translation: [{t.x:.3f}, {t.y:.3f}, {t.z:.3f}]",
        f"- Rotation: in Quaternion [{r.x:.3f}, {r.y:.3f}, {r.z:.3f}, {r.w:.3f}]",
        f"- Rotation: in RPY (radian) [{roll:.3f}, {pitch:.3f}, {yaw:.3f}]",
        "- Rotation: in RPY (degree) [{:.3f}, {:.3f}, {:.3f}]".format(*degrees),
        "- Matrix:",
        *("".join(f" {value:6.3f}" for value in row) for row in rows),
    ])


def parse_rate(args: list[str]) -> float | tuple[str, int]:
    """The echo rate of the arguments (source, target[, rate]), or (what to print, exit code)."""
    if len(args) == 2:
        return 1.0
    if len(args) == 3:
        try:
            return float(args[2])
        except ValueError:
            return f"Failed to convert rate argument '{args[2]}' to a floating-point number", 2
    return USAGE, 1


def main(args=None) -> int:
    import rclpy
    from rclpy.executors import ExternalShutdownException
    from rclpy.node import Node
    from rclpy.time import Time

    from course_lib.robot.tf_buffer import Buffer, TransformException, TransformListener

    argv = sys.argv if args is None else args
    rclpy.init(args=argv)
    plain = rclpy.utilities.remove_ros_args(argv)[1:]
    rate = parse_rate(plain)
    if isinstance(rate, tuple):
        print(rate[0], file=sys.stderr if rate[1] != 1 else sys.stdout, flush=True)
        rclpy.try_shutdown()
        return rate[1]
    source, target = plain[:2]
    node = None
    try:
        node = Node("tf2_echo")
        buffer = Buffer()
        node.listener = TransformListener(buffer, node)
        state = {"found": False, "last_wait_log": None}

        def echo():
            if not state["found"]:
                found, reason = buffer.can_transform(source, target, Time(), return_debug_tuple=True)
                if not found:
                    now = node.get_clock().now().nanoseconds
                    if state["last_wait_log"] is None or now - state["last_wait_log"] >= 10**9:
                        state["last_wait_log"] = now  # RCLCPP_INFO_THROTTLE: once a second
                        node.get_logger().info(f"Waiting for transform {source} ->  {target}: {reason}")
                    return
                state["found"] = True
            try:
                print(format_transform(buffer.lookup_transform(source, target, Time())), flush=True)
            except TransformException as error:
                print(f"Failure at {node.get_clock().now().nanoseconds / 1e9}\nException thrown:{error}\n"
                      f"The current list of frames is:\n{buffer.all_frames_as_string()}", flush=True)

        node.create_timer(1.0 / rate, echo)
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
