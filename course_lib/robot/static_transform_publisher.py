"""``ros2 run tf2_ros static_transform_publisher``: publish one fixed transform on /tf_static, with
tf2_ros's arguments, words and exit codes (its C++ program is not on PyPI).

    ros2 run tf2_ros static_transform_publisher --x 0.35 --z 0.4 --yaw 1.57 --frame-id base_link --child-frame-id laser
    ros2 run tf2_ros static_transform_publisher 0.35 0 0.4 1.57 0 0 base_link laser  # old: x y z yaw pitch roll
    ros2 run tf2_ros static_transform_publisher 0 0 0 0 0 0 1 base_link laser        # old: x y z qx qy qz qw

As upstream: the rotation as roll/pitch/yaw in radians or as a quaternion (not both), the identity
when neither is given, and the old positional form (8 or 9 values) with a deprecation warning.
The node (named ``static_transform_publisher_`` and 16 random letters, so that several can run)
publishes once, latched (transient local), and spins until Ctrl-C.
"""

from __future__ import annotations

import math
import random
import re
import string
import sys

USAGE = """usage: static_transform_publisher [--x X] [--y Y] [--z Z] [--qx QX] [--qy QY] [--qz QZ] [--qw QW] \
[--roll ROLL] [--pitch PITCH] [--yaw YAW] --frame-id FRAME_ID --child-frame-id CHILD_FRAME_ID

A command line utility for manually sending a static transform.

If no translation or orientation is provided, the identity transform will be published.

The translation offsets are in meters.

The rotation may be provided with roll, pitch, yaw euler angles in radians, or as a quaternion.

required arguments:
  --frame-id FRAME_ID parent frame
  --child-frame-id CHILD_FRAME_ID child frame id

optional arguments:
  --x X                 x component of translation
  --y Y                 y component of translation
  --z Z                 z component of translation
  --qx QX               x component of quaternion rotation
  --qy QY               y component of quaternion rotation
  --qz QZ               z component of quaternion rotation
  --qw QW               w component of quaternion rotation
  --roll ROLL           roll component Euler rotation
  --pitch PITCH         pitch component Euler rotation
  --yaw YAW             yaw component Euler rotation"""

_TRANSLATION = {"--x": 0, "--y": 1, "--z": 2}
_QUATERNION = {"--qx": 0, "--qy": 1, "--qz": 2, "--qw": 3}
_EULER = {"--roll": 0, "--pitch": 1, "--yaw": 2}
_FRAMES = {"--frame-id": 0, "--child-frame-id": 1}
# C's strtod, as std::stod reads it: the longest number at the start ("1.5m" is 1.5)
_NUMBER = re.compile(r"\s*[+-]?(inf(inity)?|nan|(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?)", re.IGNORECASE)


class ArgumentError(ValueError):
    """What upstream prints after "error parsing command line arguments: "."""


def quaternion_from_rpy(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of the rotation by yaw about z, then pitch about y, then roll about x (tf2's setRPY)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


def _number(option: str, text: str) -> float:
    match = _NUMBER.match(text)
    if match is None:
        raise ArgumentError(f"Failed to parse {option} argument as float")
    return float(match.group(0))


def parse_args(args: list[str]) -> dict | None:
    """The transform the arguments (without the program's name and ROS arguments) ask for: a dict
    of translation (x, y, z), rotation (x, y, z, w), frame_id and child_frame_id; None for --help.

    Raises:
        ArgumentError: with upstream's reason.
    """
    translation, quaternion, euler, frames = [0.0] * 3, [0.0, 0.0, 0.0, 1.0], [0.0] * 3, ["", ""]
    seen, positional, help_asked = set(), [], False
    index = 0
    while index < len(args):
        option = args[index]
        if option in ("--help", "-h"):
            help_asked = True
        elif option in {**_TRANSLATION, **_QUATERNION, **_EULER, **_FRAMES}:
            if index == len(args) - 1:
                raise ArgumentError(f"Not enough arguments for {option}")
            index += 1
            for table, values, kind in ((_TRANSLATION, translation, "trans"), (_QUATERNION, quaternion, "quat"),
                                        (_EULER, euler, "rpy")):
                if option in table:
                    values[table[option]] = _number(option, args[index])
                    seen.add(kind)
            if option in _FRAMES:
                frames[_FRAMES[option]] = args[index]
                seen.add("frame")
        else:
            positional.append(option)
        index += 1
    if help_asked:
        return None
    if {"rpy", "quat"} <= seen:
        raise ArgumentError("Cannot specify both quaternion and Euler rotations")
    rotation = quaternion_from_rpy(*euler) if "rpy" in seen else tuple(quaternion)
    if len(positional) in (8, 9):
        _log("WARN", "", "Old-style arguments are deprecated; see --help for new-style arguments")
        if seen & {"frame", "trans", "quat"}:
            raise ArgumentError("Cannot specify both new-style (flags) and old-style (arguments)")
        translation = [_number(name, value) for name, value in zip("xyz", positional, strict=False)]
        if len(positional) == 8:  # x y z yaw pitch roll: tf's old order, yaw first
            yaw, pitch, roll = (_number(name, value) for name, value in zip(("yaw", "pitch", "roll"), positional[3:6],
                                                                                strict=True))
            rotation = quaternion_from_rpy(roll, pitch, yaw)
        else:
            rotation = tuple(_number(name, value) for name, value in zip(("qx", "qy", "qz", "qw"), positional[3:7],
                                                                             strict=True))
        frames = positional[-2:]
    elif positional:
        raise ArgumentError("Extra unparsed arguments on command-line")
    if not frames[0]:
        raise ArgumentError("Frame id must not be empty")
    if not frames[1]:
        raise ArgumentError("Child frame id must not be empty")
    return {"translation": tuple(translation), "rotation": tuple(rotation),
            "frame_id": frames[0], "child_frame_id": frames[1]}


def _log(severity: str, name: str, message: str) -> None:
    """A line as rcutils logs it to the console (upstream logs these before any node exists)."""
    import time

    print(f"[{severity}] [{time.time():.9f}] [{name}]: {message}", file=sys.stderr, flush=True)


def unique_node_name() -> str:
    return "static_transform_publisher_" + "".join(random.choices(string.ascii_letters + string.digits, k=16))


def main(args=None) -> int:
    import rclpy
    from geometry_msgs.msg import TransformStamped
    from rclpy.executors import ExternalShutdownException
    from rclpy.node import Node
    from rclpy.qos import DurabilityPolicy, QoSProfile
    from tf2_msgs.msg import TFMessage

    argv = sys.argv if args is None else args
    rclpy.init(args=argv)
    try:
        transform = parse_args(rclpy.utilities.remove_ros_args(argv)[1:])
    except ArgumentError as error:
        _log("ERROR", "", f"error parsing command line arguments: {error}")
        print(USAGE, flush=True)
        rclpy.try_shutdown()
        return 1
    if transform is None:
        print(USAGE, flush=True)
        rclpy.try_shutdown()
        return 0
    node = None
    try:
        node = Node(unique_node_name())
        if transform["frame_id"] == transform["child_frame_id"]:
            node.get_logger().error(f"cannot publish static transform from '{transform['frame_id']}' to "
                                    f"'{transform['child_frame_id']}', exiting")
            return 1
        message = TransformStamped()
        message.header.stamp = node.get_clock().now().to_msg()
        message.header.frame_id, message.child_frame_id = transform["frame_id"], transform["child_frame_id"]
        t, r = message.transform.translation, message.transform.rotation
        t.x, t.y, t.z = transform["translation"]
        r.x, r.y, r.z, r.w = transform["rotation"]
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        node.create_publisher(TFMessage, "/tf_static", latched).publish(TFMessage(transforms=[message]))
        node.get_logger().info(
            "Spinning until stopped - publishing transform\ntranslation: ('{:f}', '{:f}', '{:f}')\n"
            "rotation: ('{:f}', '{:f}', '{:f}', '{:f}')\nfrom '{}' to '{}'".format(
                *transform["translation"], *transform["rotation"], transform["frame_id"], transform["child_frame_id"]))
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
