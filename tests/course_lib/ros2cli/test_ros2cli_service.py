"""``ros2 service`` (course_lib/ros2cli/service.py), run as the installed ``.venv/bin/ros2`` against
echo servers in processes of their own, held to ros2service's own test_cli.py (Jazzy): the same
fixture (test_msgs/srv/BasicTypes echoed back, in /my_ns, one of them hidden) and expectations."""

import signal
import subprocess
import sys
import types

import pytest
from support.ros2cli import ROS2, node_script, ros2, ros2_together

from course_lib.ros import processes, rosenv

# ros2service's test/fixtures/echo_server.py, written anew: answers a BasicTypes request with
# the same values (after a sleep of float64_value seconds when string_value is 'slow').
ECHO_SERVER = node_script('''
import sys
import time

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from test_msgs.srv import BasicTypes


class EchoServer(Node):

    def __init__(self):
        super().__init__('echo_server')
        self.create_service(BasicTypes, 'echo', self.echo)

    def echo(self, request, response):
        if request.string_value == 'slow':
            time.sleep(request.float64_value)
        for field in request.get_fields_and_field_types():
            setattr(response, field, getattr(request, field))
        return response

''', 'EchoServer()')

# The services every rclpy node has (ros2service's test_cli.py: expected_builtin_services).
BUILTIN = {
    "describe_parameters": "rcl_interfaces/srv/DescribeParameters",
    "get_parameter_types": "rcl_interfaces/srv/GetParameterTypes",
    "get_parameters": "rcl_interfaces/srv/GetParameters",
    "get_type_description": "type_description_interfaces/srv/GetTypeDescription",
    "list_parameters": "rcl_interfaces/srv/ListParameters",
    "set_parameters": "rcl_interfaces/srv/SetParameters",
    "set_parameters_atomically": "rcl_interfaces/srv/SetParametersAtomically",
}


def builtin(node: str, with_types: bool = False) -> list[str]:
    return [f"{node}/{name}" + (f" [{kind}]" if with_types else "") for name, kind in BUILTIN.items()]


def echo_call_output(**values) -> str:
    """ros2service's get_echo_call_output: the request's repr, a blank line, then the response's."""
    from test_msgs.srv import BasicTypes

    request, response = BasicTypes.Request(**values), BasicTypes.Response(**values)
    return f"requester: making request: {request!r}\n\nresponse:\n{response!r}\n\n"


@pytest.fixture(scope="module")
def servers(tmp_path_factory):
    """/my_ns/echo_server (service /my_ns/echo) and /my_ns/_hidden_echo_server (/my_ns/_echo)."""
    script = tmp_path_factory.mktemp("service") / "echo_server.py"
    script.write_text(ECHO_SERVER)
    with rosenv.reserve_domain_id() as reservation:
        started = []
        try:
            for name, remap in (("echo_server", []), ("_hidden_echo_server", ["-r", "echo:=_echo"])):
                command = [sys.executable, str(script), "--ros-args", "-r", f"__node:={name}", "-r", "__ns:=/my_ns",
                           *remap]
                started.append(processes.NodeProcess(command, name=name, domain_id=reservation.domain_id).start())
            for process in started:
                process.wait_for_node(f"/my_ns/{process.name}", timeout=30)
            yield types.SimpleNamespace(env=rosenv.ros_environment(domain_id=reservation.domain_id))
        finally:
            for process in started:
                process.stop()


def test_list(servers):
    """test_list_services, test_list_hidden, test_list_with_types, test_list_count."""
    plain, hidden, typed, count = ros2_together(
        ["service", "list"], ["service", "list", "--include-hidden-services"], ["service", "list", "-t"],
        ["service", "list", "-c"], env=servers.env)
    assert plain.stdout.splitlines() == ["/my_ns/echo", *builtin("/my_ns/echo_server")]
    assert hidden.stdout.splitlines() == ["/my_ns/_echo", *builtin("/my_ns/_hidden_echo_server"),
                                          "/my_ns/echo", *builtin("/my_ns/echo_server")]
    assert typed.stdout.splitlines() == ["/my_ns/echo [test_msgs/srv/BasicTypes]",
                                         *builtin("/my_ns/echo_server", with_types=True)]
    assert count.stdout == f"{len(BUILTIN) + 1}\n"
    assert all(done.returncode == 0 for done in (plain, hidden, typed, count))


def test_find_and_type(servers):
    """test_find ('/my_ns/echo'), test_find_hidden, test_find_count (1), test_find_not_a_service_type
    (no output, exit code 0), test_type ('test_msgs/srv/BasicTypes'), test_type_on_not_a_service
    (no output, exit code 1); a hidden service's type with `ros2 service --include-hidden-services`."""
    find, find_hidden, find_count, find_none, kind, no_kind, hidden_kind = ros2_together(
        ["service", "find", "test_msgs/srv/BasicTypes"],
        ["service", "find", "--include-hidden-services", "test_msgs/srv/BasicTypes"],
        ["service", "find", "-c", "test_msgs/srv/BasicTypes"], ["service", "find", "not_a_service_type"],
        ["service", "type", "/my_ns/echo"], ["service", "type", "/not_a_service"],
        ["service", "--include-hidden-services", "type", "/my_ns/_echo"], env=servers.env)
    assert (find.returncode, find.stdout) == (0, "/my_ns/echo\n")
    assert (find_hidden.returncode, find_hidden.stdout) == (0, "/my_ns/_echo\n/my_ns/echo\n")
    assert (find_count.returncode, find_count.stdout) == (0, "1\n")
    assert (find_none.returncode, find_none.stdout) == (0, "")
    assert (kind.returncode, kind.stdout) == (0, "test_msgs/srv/BasicTypes\n")
    assert (no_kind.returncode, no_kind.stdout, no_kind.stderr) == (1, "", "")
    assert (hidden_kind.returncode, hidden_kind.stdout) == (0, "test_msgs/srv/BasicTypes\n")


def test_call(servers):
    """test_call_no_args and test_call: 'requester: making request: <repr>', '', 'response:', '<repr>', ''
    (the test filters out 'waiting for service to become available...')."""
    empty, filled = ros2_together(
        ["service", "call", "/my_ns/echo", "test_msgs/srv/BasicTypes"],
        ["service", "call", "/my_ns/echo", "test_msgs/srv/BasicTypes",
         "{bool_value: false, int32_value: -1, float64_value: 0.1, string_value: bazbar}"], env=servers.env)
    waiting = "waiting for service to become available...\n"
    assert empty.returncode == 0 and empty.stdout.removeprefix(waiting) == echo_call_output()
    assert filled.returncode == 0 and filled.stdout.removeprefix(waiting) == echo_call_output(
        bool_value=False, int32_value=-1, float64_value=0.1, string_value="bazbar")


def test_an_answer_slower_than_the_loop_limit_is_awaited_under_test(servers):
    """Under test a verb's loops end after the loop limit (a `!ros2 topic hz` cell cannot hang a
    lesson's run), but the answer of a server it has found is awaited: it comes unless the server is
    broken, and a busy machine must not turn a slow answer into a failed test."""
    from course_lib.ros2cli.common import loop_limit

    seconds = loop_limit(None) + 1.0
    assert seconds < 30, "the loop limit applies under test (COURSE_LIB_UNDER_TEST=1)"
    values = f"{{float64_value: {seconds}, string_value: slow}}"
    done = ros2("service", "call", "/my_ns/echo", "test_msgs/srv/BasicTypes", values, env=servers.env, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.endswith(echo_call_output(float64_value=seconds, string_value="slow")), done.stdout


def test_repeated_call_goes_on_until_ctrl_c(servers):
    """test_repeated_call: `-r 1` makes the same call again and again (two of them awaited there);
    ros2cli ends with exit code 2 on SIGINT."""
    values = "{bool_value: true, int32_value: 1, float64_value: 1.0, string_value: foobar}"
    command = [str(ROS2), "service", "call", "-r", "5", "/my_ns/echo", "test_msgs/srv/BasicTypes", values]
    with subprocess.Popen(command, env=servers.env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          stdin=subprocess.DEVNULL) as caller:
        lines = []
        while sum(line.startswith("test_msgs.srv.BasicTypes_Response(") for line in lines) < 2:  # or the end
            line = caller.stdout.readline()
            if not line:
                break
            lines.append(line.rstrip("\n"))
        caller.send_signal(signal.SIGINT)
        rest, errors = caller.communicate(timeout=60)
    once = echo_call_output(bool_value=True, int32_value=1, float64_value=1.0, string_value="foobar")
    text = "\n".join(lines).removeprefix("waiting for service to become available...\n") + "\n\n"
    assert text == 2 * once, errors
    assert caller.returncode == 2 and "Traceback" not in errors


def test_bad_calls_fail_in_ros2services_words(servers):
    """call.py: 'The passed service type is invalid', 'The passed type is not a service',
    'Failed to populate field: ...', 'rate must be greater than zero'; all before any waiting."""
    no_type, message, bad_field, bad_rate, bad_yaml = ros2_together(
        ["service", "call", "/my_ns/echo", "test_msgs/srv/NotAType"],
        ["service", "call", "/my_ns/echo", "std_msgs/msg/String"],
        ["service", "call", "/my_ns/echo", "test_msgs/srv/BasicTypes", "{no_such_field: 1}"],
        ["service", "call", "-r", "0", "/my_ns/echo", "test_msgs/srv/BasicTypes"],
        ["service", "call", "/my_ns/echo", "test_msgs/srv/BasicTypes", "{bool_value: [}"], env=servers.env)
    assert (no_type.returncode, no_type.stdout, no_type.stderr) == (1, "", "The passed service type is invalid\n")
    assert (message.returncode, message.stderr) == (1, "The passed type is not a service\n")
    assert bad_field.returncode == 1 and bad_field.stderr.startswith("Failed to populate field: ")
    assert "no_such_field" in bad_field.stderr
    assert (bad_rate.returncode, bad_rate.stderr) == (1, "rate must be greater than zero\n")
    assert bad_yaml.returncode == 1 and "not valid YAML" in bad_yaml.stderr and "Traceback" not in bad_yaml.stderr


def test_help_lists_the_service_verbs():
    text = ros2("service", "--help", env=rosenv.ros_environment()).stdout
    assert all(f"  {verb} " in text for verb in ("call", "find", "list", "type"))
