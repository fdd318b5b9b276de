"""``ros2 action`` (course_lib/ros2cli/action.py), run as the installed ``.venv/bin/ros2`` against a
Fibonacci action server in a process of its own, held to ros2action's own test_cli.py (Jazzy):
the same fixture (test_msgs/action/Fibonacci on /fibonacci) and expected lines."""

import re
import signal
import subprocess
import sys
import types

import pytest
import yaml
from support.ros2cli import ROS2, node_script, ros2, ros2_together

from course_lib.ros import processes, rosenv

# ros2action's test/fixtures/fibonacci_action_server.py, written anew: feedback after each new
# number, then the sequence as the result.
FIBONACCI_SERVER = node_script('''
import sys

import rclpy
from rclpy.action import ActionServer
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from test_msgs.action import Fibonacci


class FibonacciActionServer(Node):

    def __init__(self):
        super().__init__('fibonacci_action_server')
        self.server = ActionServer(self, Fibonacci, 'fibonacci', self.execute)

    def execute(self, goal_handle):
        feedback = Fibonacci.Feedback(sequence=[0, 1])
        for _ in range(1, goal_handle.request.order):
            feedback.sequence.append(feedback.sequence[-1] + feedback.sequence[-2])
            goal_handle.publish_feedback(feedback)
        goal_handle.succeed()
        return Fibonacci.Result(sequence=feedback.sequence)

''', 'FibonacciActionServer()')


def send_goal_output(order: int, with_feedback: int = 0) -> list:
    """ros2action's get_fibonacci_send_goal_output: its expected lines (a regex for the goal ID)."""
    lines = ["Waiting for an action server to become available...", "Sending goal:", f"     order: {order}", "",
             re.compile("Goal accepted with ID: [a-f0-9]+"), ""]
    sequence = [0, 1]
    for _ in range(order - 1):
        sequence.append(sequence[-1] + sequence[-2])
        if with_feedback > 0:
            lines += ["Feedback:", *("    " + yaml.dump({"sequence": sequence})).splitlines(), ""]
            with_feedback -= 1
    return lines + ["Result:", *("    " + yaml.dump({"sequence": sequence})).splitlines(), "",
                    "Goal finished with status: SUCCEEDED"]


def matches(expected: list, text: str, strict: bool = True) -> bool:
    """launch_testing's expect_output: the lines in order; strict: nothing else (else: in between)."""
    lines = text.splitlines()
    if strict and len(lines) != len(expected):
        return False
    index = 0
    for want in expected:
        while index < len(lines) and not (want.fullmatch(lines[index]) if isinstance(want, re.Pattern)
                                          else want == lines[index]):
            if strict:
                return False
            index += 1
        if index == len(lines):
            return False
        index += 1
    return True


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    script = tmp_path_factory.mktemp("action") / "fibonacci_action_server.py"
    script.write_text(FIBONACCI_SERVER)
    with rosenv.reserve_domain_id() as reservation:
        with processes.NodeProcess([sys.executable, str(script)], name="fibonacci_action_server",
                                   domain_id=reservation.domain_id) as process:
            process.wait_for_node("/fibonacci_action_server", timeout=30)
            yield types.SimpleNamespace(env=rosenv.ros_environment(domain_id=reservation.domain_id))


def test_list_type_and_info(server):
    """test_list, test_list_with_types, test_list_count, test_type, test_fibonacci_info (its server
    line indented by four spaces, as info.py prints it), _with_types, _count,
    test_info_on_nonexistent_action; an unknown action's type: no output, exit code 1 (type.py)."""
    listed, typed, count, kind, no_kind, info, info_typed, info_count, no_info = ros2_together(
        ["action", "list"], ["action", "list", "-t"], ["action", "list", "-c"], ["action", "type", "/fibonacci"],
        ["action", "type", "/not_an_action"], ["action", "info", "/fibonacci"], ["action", "info", "-t", "/fibonacci"],
        ["action", "info", "-c", "/fibonacci"], ["action", "info", "/not_an_action"], env=server.env)
    assert listed.stdout == "/fibonacci\n"
    assert typed.stdout == "/fibonacci [test_msgs/action/Fibonacci]\n"
    assert count.stdout == "1\n"
    assert kind.stdout == "test_msgs/action/Fibonacci\n"
    assert (no_kind.returncode, no_kind.stdout, no_kind.stderr) == (1, "", "")
    head = "Action: /fibonacci\nAction clients: 0\nAction servers: 1\n"
    assert info.stdout == head + "    /fibonacci_action_server\n"
    assert info_typed.stdout == head + "    /fibonacci_action_server [test_msgs/action/Fibonacci]\n"
    assert info_count.stdout == head
    assert no_info.stdout == "Action: /not_an_action\nAction clients: 0\nAction servers: 0\n"
    assert all(done.returncode == 0 for done in (listed, typed, count, kind, info, info_typed, info_count, no_info))


def test_send_goal(server):
    """test_send_fibonacci_goal (strict) and test_send_fibonacci_goal_with_feedback (the first
    feedback among the lines)."""
    plain, with_feedback = ros2_together(
        ["action", "send_goal", "/fibonacci", "test_msgs/action/Fibonacci", "{order: 5}"],
        ["action", "send_goal", "-f", "/fibonacci", "test_msgs/action/Fibonacci", "{order: 5}"], env=server.env)
    assert plain.returncode == 0 and matches(send_goal_output(5), plain.stdout), plain.stdout
    assert with_feedback.returncode == 0, with_feedback.stderr
    assert matches(send_goal_output(5, with_feedback=1), with_feedback.stdout, strict=False), with_feedback.stdout
    # All four feedback messages, each after "Goal accepted" and before "Result:".
    text = with_feedback.stdout
    assert text.count("Feedback:\n") == 4
    assert text.index("Goal accepted") < text.index("Feedback:") < text.rindex("Feedback:") < text.index("Result:")


# A server that accepts a cancel and still publishes feedback for a while before it ends the goal:
# feedback then arrives after the cancel's answer, as it may from any server under load.
LATE_FEEDBACK_SERVER = node_script('''
import sys
import time

import rclpy
from rclpy.action import ActionServer, CancelResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.node import Node
from test_msgs.action import Fibonacci


class LateFeedbackServer(Node):

    def __init__(self):
        super().__init__('late_feedback_server')
        self.server = ActionServer(self, Fibonacci, 'fibonacci', self.execute, callback_group=ReentrantCallbackGroup(),
                                   cancel_callback=lambda goal_handle: CancelResponse.ACCEPT)

    def execute(self, goal_handle):
        feedback = Fibonacci.Feedback(sequence=[0, 1])
        after_cancel = 0
        while after_cancel < 100:  # feedback every 20 ms, for 2 s after the cancel request
            goal_handle.publish_feedback(feedback)
            after_cancel += goal_handle.is_cancel_requested
            time.sleep(0.02)
        goal_handle.canceled()
        return Fibonacci.Result(sequence=feedback.sequence)

''', 'LateFeedbackServer()').replace("rclpy.spin(node)", "rclpy.spin(node, MultiThreadedExecutor())")


def test_no_feedback_follows_goal_canceled(tmp_path):
    """Ctrl-C during `send_goal --feedback` cancels the goal, and feedback that the server still
    sends after accepting the cancel is not printed after "Goal canceled." (ros2action stops
    spinning there): the output ends with that line."""
    script = tmp_path / "late_feedback_server.py"
    script.write_text(LATE_FEEDBACK_SERVER)
    with rosenv.reserve_domain_id() as reservation:
        env = rosenv.ros_environment(domain_id=reservation.domain_id)
        with processes.NodeProcess([sys.executable, str(script)], name="late_feedback_server",
                                   domain_id=reservation.domain_id) as server:
            server.wait_for_node("/late_feedback_server", timeout=30)
            sending = subprocess.Popen([str(ROS2), "action", "send_goal", "-f", "/fibonacci",
                                        "test_msgs/action/Fibonacci", "{order: 5}"], env=env,
                                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                       stdin=subprocess.DEVNULL)
            try:
                while sending.stdout.readline() not in ("Feedback:\n", ""):
                    pass
                sending.send_signal(signal.SIGINT)
                out, err = sending.communicate(timeout=60)
            finally:
                sending.kill()
                sending.wait()
    lines = out.splitlines()
    assert "Canceling goal..." in lines and lines[-1] == "Goal canceled.", (out, err)
    assert "Traceback" not in err


def test_bad_goals_fail_in_ros2actions_words(server):
    """send_goal.py: 'The passed action type is invalid', 'Failed to populate message fields: ...'."""
    no_type, a_service, bad_field = ros2_together(
        ["action", "send_goal", "/fibonacci", "test_msgs/action/NotAType", "{order: 5}"],
        ["action", "send_goal", "/fibonacci", "test_msgs/srv/BasicTypes", "{}"],
        ["action", "send_goal", "/fibonacci", "test_msgs/action/Fibonacci", "{ordr: 5}"], env=server.env)
    assert (no_type.returncode, no_type.stdout, no_type.stderr) == (1, "", "The passed action type is invalid\n")
    assert (a_service.returncode, a_service.stderr) == (1, "The passed action type is invalid\n")
    assert bad_field.returncode == 1 and bad_field.stderr.startswith("Failed to populate message fields: ")
    assert "ordr" in bad_field.stderr and bad_field.stdout == ""


def test_help_lists_the_action_verbs():
    text = ros2("action", "--help", env=rosenv.ros_environment()).stdout
    assert all(f"  {verb} " in text for verb in ("info", "list", "send_goal", "type"))
