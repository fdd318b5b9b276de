"""Teleoperation (course_lib.robot.teleop_keyboard and teleop_widget): teleop_twist_keyboard's keys,
speeds and help text, the terminal tool driven through a pty, and the notebook's pad publishing
while a key is held and stopping on release or silence."""

import os
import pty
import select
import signal
import subprocess
import threading
import time

import pytest
import rclpy
from geometry_msgs.msg import Twist
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from support.process import wait_until
from support.ros2cli import ROS2

from course_lib.robot import teleop_keyboard
from course_lib.robot.teleop_keyboard import HELP, Teleop, apply_key
from course_lib.ros import rosenv, session
from course_lib.supervision import process_tree

STOP_STEPS = ((signal.SIGINT, 60.0), (signal.SIGKILL, 5.0))


@pytest.mark.parametrize(("key", "twist"), [
    ("i", (0.5, 0.0, 0.0, 0.0)), ("u", (0.5, 0.0, 0.0, 1.0)), ("o", (0.5, 0.0, 0.0, -1.0)),
    ("j", (0.0, 0.0, 0.0, 1.0)), ("l", (0.0, 0.0, 0.0, -1.0)),
    (",", (-0.5, 0.0, 0.0, 0.0)), (".", (-0.5, 0.0, 0.0, 1.0)), ("m", (-0.5, 0.0, 0.0, -1.0)),
    ("J", (0.0, 0.5, 0.0, 0.0)), ("t", (0.0, 0.0, 0.5, 0.0)), ("k", (0.0, 0.0, 0.0, 0.0)),
])
def test_each_key_gives_upstreams_twist(key, twist):
    state = Teleop()
    apply_key(state, "i")
    apply_key(state, key)
    assert state.twist() == twist


def test_any_other_key_stops_and_speed_keys_scale_by_ten_percent():
    state = Teleop()
    apply_key(state, "i")
    assert apply_key(state, "q") == "currently:\tspeed 0.55\tturn 1.1 "
    assert state.twist() == pytest.approx((0.55, 0.0, 0.0, 0.0)), "a speed key keeps the direction"
    apply_key(state, "x")
    apply_key(state, "c")
    assert (state.speed, state.turn) == pytest.approx((0.495, 0.99))
    apply_key(state, "?")
    assert state.twist() == (0.0, 0.0, 0.0, 0.0)


def test_the_help_comes_again_after_fifteen_speed_changes():
    state = Teleop()
    printed = [apply_key(state, "e") for _ in range(15)]
    assert all(HELP not in p for p in printed[:14]) and printed[14].endswith(HELP)


def read_until(descriptor: int, words: str, seen: list[str]) -> bool:
    """Read the pty into `seen` until `words` shows (60 s backstop)."""
    def arrived():
        if select.select([descriptor], [], [], 0.1)[0]:
            try:
                seen.append(os.read(descriptor, 4096).decode(errors="replace"))
            except OSError:  # the process ended and closed its side
                return True
        return words in "".join(seen)
    return wait_until(arrived) and words in "".join(seen)


def _controlling_terminal() -> None:
    """In the tool's new session: the pty its controlling terminal, as a terminal window's is. Ctrl-C
    typed while the tool is between two reads (not in raw mode) is then a SIGINT, as for a user;
    without one the terminal dropped the key and the tool read on for ever."""
    import fcntl
    import termios

    fcntl.ioctl(0, termios.TIOCSCTTY, 0)


def test_a_key_typed_between_two_reads_is_read_not_flushed():
    """The tool reads in raw mode only while it waits for a key; a key typed before that (a Ctrl-C
    right after a key that moved the robot) must be the next key read. With tty.setraw's default
    (flush the input) it was lost, and the test that typed Ctrl-C waited for the tool's end."""
    main, child = pty.openpty()
    keys = []
    with open(child, closefd=True) as terminal:
        os.write(main, b"u")  # the terminal is not in raw mode yet
        time.sleep(0.1)  # the pty hands it to the line discipline
        reader = threading.Thread(target=lambda: keys.append(teleop_keyboard.read_key(terminal)), daemon=True)
        reader.start()
        reader.join(5.0)
        if reader.is_alive():  # the key is gone: a second one ends the read
            os.write(main, b"x")
            reader.join(5.0)
    os.close(main)
    assert keys == ["u"]


class TerminalTool:
    """The terminal tool in a pty of its own (`terminal`: the pty's other side), and a node of the
    test's that hears /cmd_vel (`heard`); `seen`: what the tool printed so far."""

    def __init__(self, domain_id: int):
        self.terminal, child = pty.openpty()
        self.process = subprocess.Popen(
            [str(ROS2), "run", "teleop_twist_keyboard", "teleop_twist_keyboard"],
            env=rosenv.ros_environment(domain_id), stdin=child, stdout=child, stderr=child,
            start_new_session=True, preexec_fn=_controlling_terminal)
        os.close(child)
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=domain_id)
        self.heard, self.seen = [], []
        self.node = Node("cmd_vel_reader", context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.node.create_subscription(Twist, "/cmd_vel", self.heard.append, 10)
        self.executor.add_node(self.node)

    def read_until(self, words: str) -> bool:
        return read_until(self.terminal, words, self.seen)

    def press_until(self, key: str, condition) -> bool:
        """Press `key` again until the twist it publishes arrives (the first may go out before the
        publisher has matched this subscriber: a key press is not stored)."""
        def done():
            os.write(self.terminal, key.encode())
            self.executor.spin_once(timeout_sec=0.2)
            return bool(self.heard) and condition(self.heard[-1])
        return wait_until(done)

    def ended_with_a_stop(self) -> bool:
        """The tool ended with exit code 0, and the last twist heard is a stop."""
        return (wait_until(lambda: self.process.poll() is not None) and self.process.returncode == 0
                and wait_until(lambda: self.executor.spin_once(timeout_sec=0.1)
                               or (self.heard[-1].linear.x, self.heard[-1].angular.z) == (0.0, 0.0)))

    def close(self) -> None:
        # The node leaves the graph now, whatever failed: a later test in this domain must not see it.
        self.executor.shutdown()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)
        process_tree.stop_group(self.process, STOP_STEPS)
        os.close(self.terminal)


@pytest.fixture
def tool(domain_id):
    started = TerminalTool(domain_id)
    yield started
    started.close()


def test_the_terminal_tool_in_a_pty_publishes_the_keys_twists_and_stops_on_ctrl_c(tool):
    """About 1.5 CPU-s: one ROS process and a subscriber."""
    assert tool.read_until("currently:\tspeed 0.5\tturn 1.0 "), "".join(tool.seen)
    shown = "".join(tool.seen).replace("\r\n", "\n")
    assert "Moving around:\n   u    i    o\n   j    k    l\n   m    ,    .\n" in shown
    assert tool.press_until("i", lambda t: (t.linear.x, t.angular.z) == (0.5, 0.0))
    os.write(tool.terminal, b"q")
    assert tool.read_until("currently:\tspeed 0.55\tturn 1.1 ")
    assert tool.press_until("j", lambda t: (t.linear.x, t.angular.z) == (0.0, pytest.approx(1.1)))
    assert tool.press_until("k", lambda t: (t.linear.x, t.angular.z) == (0.0, 0.0))
    assert tool.press_until("u", lambda t: t.linear.x == pytest.approx(0.55))
    os.write(tool.terminal, b"\x03")  # raw mode: Ctrl-C is a key, and the tool stops the robot as it quits
    assert tool.ended_with_a_stop(), "".join(tool.seen)


def test_ctrl_c_between_two_keys_is_a_sigint_that_ends_the_tool_with_a_stop(tool):
    """The terminal is out of raw mode between two keys, so a Ctrl-C typed then is a SIGINT to the
    tool's process group, not a key (a test that types Ctrl-C right after a key meets this now and
    then). About 1.5 CPU-s."""
    assert tool.read_until("currently:\tspeed 0.5\tturn 1.0 "), "".join(tool.seen)
    assert tool.press_until("i", lambda t: t.linear.x == 0.5)  # matched both ways
    os.killpg(tool.process.pid, signal.SIGINT)
    assert tool.ended_with_a_stop(), "".join(tool.seen)


@pytest.fixture
def pad(session_domain):
    from course_lib.robot.teleop_widget import KeyboardTeleop

    heard = []
    listener = session.add_node(Node("pad_listener"))
    listener.create_subscription(Twist, "/cmd_vel", heard.append, 10)
    widget = KeyboardTeleop()
    wait_until(lambda: widget.publisher.get_subscription_count() >= 1)
    yield widget, heard
    session.remove_node(widget.node)
    session.remove_node(listener)


def test_the_pad_publishes_while_a_key_is_held_and_stops_on_release(pad):
    widget, heard = pad
    beats = iter(range(1, 10**6))

    def hold(keys):
        widget.held, widget.beat = keys, next(beats)

    def heard_values():
        return heard and (heard[-1].linear.x, heard[-1].angular.z)

    assert wait_until(lambda: hold(["i"]) or heard_values() == (0.5, 0.0))
    count = len(heard)
    assert wait_until(lambda: hold(["i"]) or len(heard) >= count + 3), "it keeps publishing while held"
    widget.on_message(widget, {"speed_key": "q"}, [])
    assert widget.status == "speed 0.55 m/s, turn 1.10 rad/s"
    assert wait_until(lambda: hold(["i", "j"]) or heard_values() == (0.0, pytest.approx(1.1))), "the newest key wins"
    hold([])
    assert wait_until(lambda: heard_values() == (0.0, 0.0)), "a zero twist on release"
    count = len(heard)
    session.wait_for(lambda: False, timeout=0.3)
    assert len(heard) == count, "nothing more while no key is held"


def test_the_pad_stops_when_the_browser_goes_silent(pad):
    widget, heard = pad
    widget.held, widget.beat = ["i"], widget.beat + 1
    assert wait_until(lambda: heard and heard[-1].linear.x == 0.5)
    # no further heartbeat: a closed tab or a lost connection; the deadman stops the robot
    assert wait_until(lambda: heard[-1].linear.x == 0.0 and not widget.moving)
    assert teleop_keyboard.MOVE_BINDINGS["i"] == (1, 0, 0, 0)
    assert time.monotonic() - widget.last_beat >= widget.deadman
