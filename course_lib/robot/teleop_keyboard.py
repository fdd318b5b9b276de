"""``ros2 run teleop_twist_keyboard teleop_twist_keyboard``: drive with the keyboard from a terminal,
with teleop_twist_keyboard's keys, help text and speed steps (it is not on PyPI).

Each key press publishes one geometry_msgs/Twist on ``cmd_vel``; a held key repeats at the
keyboard's rate; any other key stops the robot, and Ctrl-C publishes a stop and quits. The mapping
of a key to a velocity is the plain function :func:`apply_key`, which the notebook's keyboard
widget (:mod:`course_lib.robot.teleop_widget`) shares.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass

HELP = """
This node takes keypresses from the keyboard and publishes them
as Twist/TwistStamped messages. It works best with a US keyboard layout.
---------------------------
Moving around:
   u    i    o
   j    k    l
   m    ,    .

For Holonomic mode (strafing), hold down the shift key:
---------------------------
   U    I    O
   J    K    L
   M    <    >

t : up (+z)
b : down (-z)

anything else : stop

q/z : increase/decrease max speeds by 10%
w/x : increase/decrease only linear speed by 10%
e/c : increase/decrease only angular speed by 10%

CTRL-C to quit
"""

#: key -> (x, y, z, turn): the direction of the linear velocity and of the turn, each -1, 0 or 1.
MOVE_BINDINGS = {
    "i": (1, 0, 0, 0), "o": (1, 0, 0, -1), "j": (0, 0, 0, 1), "l": (0, 0, 0, -1), "u": (1, 0, 0, 1),
    ",": (-1, 0, 0, 0), ".": (-1, 0, 0, 1), "m": (-1, 0, 0, -1),
    "O": (1, -1, 0, 0), "I": (1, 0, 0, 0), "J": (0, 1, 0, 0), "L": (0, -1, 0, 0), "U": (1, 1, 0, 0),
    "<": (-1, 0, 0, 0), ">": (-1, -1, 0, 0), "M": (-1, 1, 0, 0),
    "t": (0, 0, 1, 0), "b": (0, 0, -1, 0),
}
#: key -> (factor of the linear speed, factor of the turn rate)
SPEED_BINDINGS = {"q": (1.1, 1.1), "z": (0.9, 0.9), "w": (1.1, 1.0), "x": (0.9, 1.0), "e": (1.0, 1.1), "c": (1.0, 0.9)}
CTRL_C = "\x03"


@dataclass
class Teleop:
    """What the keys have set: the speeds (m/s, rad/s) and the direction of travel."""

    speed: float = 0.5
    turn: float = 1.0
    direction: tuple[int, int, int, int] = (0, 0, 0, 0)
    speed_changes: int = 0  # upstream shows the help again after every 15th speed change

    def twist(self) -> tuple[float, float, float, float]:
        """(linear x, linear y, linear z, angular z) of the Twist to publish."""
        x, y, z, th = self.direction
        return x * self.speed, y * self.speed, z * self.speed, th * self.turn


def vels(speed: float, turn: float) -> str:
    return f"currently:\tspeed {speed}\tturn {turn} "  # upstream: %s of the floats


def apply_key(state: Teleop, key: str) -> str:
    """Update `state` for one key as teleop_twist_keyboard does; what it prints for that key ('' for none)."""
    if key in MOVE_BINDINGS:
        state.direction = MOVE_BINDINGS[key]
        return ""
    if key in SPEED_BINDINGS:
        factor_speed, factor_turn = SPEED_BINDINGS[key]
        state.speed, state.turn = state.speed * factor_speed, state.turn * factor_turn
        printed = vels(state.speed, state.turn)
        if state.speed_changes == 14:
            printed += "\n" + HELP
        state.speed_changes = (state.speed_changes + 1) % 15
        return printed
    state.direction = (0, 0, 0, 0)  # anything else: stop
    return ""


def twist_message(values: tuple[float, float, float, float]):
    from geometry_msgs.msg import Twist

    message = Twist()
    message.linear.x, message.linear.y, message.linear.z, message.angular.z = (float(v) for v in values)
    return message


def read_key(stream) -> str:
    """One key from a terminal, in raw mode only while it is read (as upstream's getKey). A key typed
    between two reads is kept: raw mode starts at once (TCSANOW), where tty.setraw's default flushes
    the input first (upstream loses such a key, a Ctrl-C too, and the tool then reads on)."""
    import termios
    import tty

    descriptor = stream.fileno()
    saved = termios.tcgetattr(descriptor)
    try:
        tty.setraw(descriptor, termios.TCSANOW)
        return stream.read(1)
    finally:
        termios.tcsetattr(descriptor, termios.TCSADRAIN, saved)


def main(args=None) -> int:
    import rclpy
    from rclpy.duration import Duration
    from rclpy.node import Node
    from rclpy.signals import SignalHandlerOptions

    # Ctrl-C between two keys (the terminal not in raw mode) is a SIGINT: a KeyboardInterrupt, with
    # the context still up to publish the stop (rclpy's own handler would shut it down first).
    rclpy.init(args=sys.argv if args is None else args, signal_handler_options=SignalHandlerOptions.NO)
    node = Node("teleop_twist_keyboard")
    publisher = node.create_publisher(type(twist_message((0, 0, 0, 0))), "cmd_vel", 10)
    state = Teleop(speed=node.declare_parameter("speed", 0.5).value, turn=node.declare_parameter("turn", 1.0).value)
    try:
        print(HELP)
        print(vels(state.speed, state.turn), flush=True)
        while True:
            key = read_key(sys.stdin)
            if key in ("", CTRL_C):  # end of input, or Ctrl-C (raw mode turns it into a key)
                break
            printed = apply_key(state, key)
            if printed:
                print(printed, flush=True)
            publisher.publish(twist_message(state.twist()))
    except KeyboardInterrupt:
        pass
    finally:
        publisher.publish(twist_message((0, 0, 0, 0)))
        # The stop must reach the robot: a node that ends right after publishing may take the
        # message with it (the subscribers acknowledge it; a second at most).
        publisher.wait_for_all_acked(Duration(seconds=1))
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
