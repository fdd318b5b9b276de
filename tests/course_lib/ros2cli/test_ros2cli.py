"""The course's ``ros2`` command (course_lib.ros2cli), run as the installed ``.venv/bin/ros2``
against live nodes in other processes: one test per verb, each reading what the verb prints."""

import os
import re
import signal
import subprocess
import sys
import types
from pathlib import Path

import pytest
import yaml
from support.process import in_background_of_a_script, wait_until
from support.ros2cli import ROS2, node_script, ros2, ros2_together

from course_lib.ros import colcon, processes, rosenv, workspace
from course_lib.ros2cli.common import FULL_INSTALL

# Two nodes, each in a process of its own: `python live_nodes.py talker|listener [ros args]`.
LIVE_NODES = node_script('''
import sys

import rclpy
from rcl_interfaces.msg import SetParametersResult
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Int32, String


class Talker(Node):
    """Publishes '<greeting> N' on cli_chatter at 10 Hz; refuses a rate that is not positive."""

    def __init__(self):
        super().__init__('cli_talker')
        self.declare_parameter('greeting', 'hello')
        self.declare_parameter('rate', 10.0)
        self.declare_parameter('limits.low', 1)
        self.add_on_set_parameters_callback(self.check)
        self.count = 0
        self.publisher = self.create_publisher(String, 'cli_chatter', 10)
        self.create_timer(0.1, self.tick)

    def check(self, changes):
        for change in changes:
            if change.name == 'rate' and change.value <= 0.0:
                return SetParametersResult(successful=False, reason='rate must be positive')
        return SetParametersResult(successful=True)

    def tick(self):
        self.count += 1
        self.publisher.publish(String(data=f"{self.get_parameter('greeting').value} {self.count}"))


class Listener(Node):
    """Listens to cli_chatter and logs every number heard on cli_numbers."""

    def __init__(self):
        super().__init__('cli_listener')
        self.create_subscription(String, 'cli_chatter', lambda msg: None, 10)
        self.create_subscription(Int32, 'cli_numbers', lambda msg: print(f'heard {msg.data}', flush=True), 10)

''', "Talker() if sys.argv[1] == 'talker' else Listener()")


@pytest.fixture(scope="module")
def live(tmp_path_factory):
    """A talker and a listener in processes of their own, on a reserved domain; yields ros2's env."""
    script = tmp_path_factory.mktemp("live") / "live_nodes.py"
    script.write_text(LIVE_NODES)
    with rosenv.reserve_domain_id() as reservation:
        started = []
        try:
            for role in ("talker", "listener"):
                started.append(processes.NodeProcess([sys.executable, str(script), role], name=f"cli_{role}",
                                                     domain_id=reservation.domain_id).start())
            for process in started:
                process.wait_for_node(process.name, timeout=30)
            yield types.SimpleNamespace(env=rosenv.ros_environment(domain_id=reservation.domain_id),
                                        script=script, domain_id=reservation.domain_id, listener=started[1])
        finally:
            for process in started:
                process.stop()


def test_the_command_is_installed_in_the_venv():
    """make setup put ros2 next to the interpreter, and it is the course's."""
    from course_lib.ros2cli import install

    assert ROS2.is_file() and install.is_ours(ROS2)


# --- what is and is not supported ---------------------------------------------------------

def test_help_lists_the_supported_commands_and_verbs():
    env = {**rosenv.ros_environment(), "COLUMNS": "80"}  # argparse wraps help to the terminal's width
    top = ros2("--help", env=env).stdout
    assert re.findall(r"^  ([a-z]+) ", top, re.MULTILINE) == ["action", "bag", "daemon", "doctor", "interface",
                                                             "launch", "node", "param", "pkg", "run", "service",
                                                             "topic", "wtf"]
    # ros2cli's layout (Jazzy): usage, description, options, then the commands; what the course's
    # ros2 leaves out comes after them, so `ros2 --help` reads as the real one does.
    assert top.startswith("usage: ros2 [-h] [--use-python-default-buffering]\n"
                          "            Call `ros2 <command> -h` for more detailed usage. ...\n\n"
                          "ros2 is an extensible command-line tool for ROS 2.\n\noptions:\n"), top
    sections = [top.index(s) for s in ("\noptions:\n", "\nCommands:\n", "\n  Call `ros2 <command> -h`", FULL_INSTALL)]
    assert sections == sorted(sections), top
    assert ros2("--use-python-default-buffering", "--help", env=env).stdout == top
    topic = ros2("topic", "--help", env=env).stdout
    assert re.findall(r"^  ([a-z]+) ", topic, re.MULTILINE) == ["bw", "delay", "echo", "find", "hz", "info", "list",
                                                               "pub", "type"]
    assert "--once" in ros2("topic", "echo", "--help", env=env).stdout


@pytest.mark.parametrize("args, names", [
    (["bag", "record", "-s", "sqlite3", "-a"], "ros2 bag record -s sqlite3 is not supported"),
    (["service", "echo", "/x"], "ros2 service echo is not supported"),
    (["topic", "echo", "/x", "--csv"], "ros2 topic echo: --csv is not supported"),
    (["topic", "echo", "/x", "--times", "3"], "ros2 topic echo: --times is not supported"),
    (["param", "dump", "/x", "--output-dir", "/tmp"], "ros2 param dump: --output-dir is not supported"),
    (["run", "--prefix", "gdb", "pkg", "exe"], "ros2 run: --prefix is not supported"),
    (["pkg", "create", "demo"], "ros2 pkg create: --build-type ament_cmake (the default) is not supported"),
])
def test_what_is_not_supported_is_one_line_naming_what_is(args, names, tmp_path):
    done = ros2(*args, env=rosenv.ros_environment(), check=False)
    assert done.returncode == 2 and done.stdout == ""
    assert len(done.stderr.splitlines()) == 1, done.stderr
    assert done.stderr.startswith(names) and "(it supports: " in done.stderr
    assert done.stderr.rstrip().endswith("a full ROS 2 install (ros2cli) has more")


# --- ros2 node --------------------------------------------------------------------------------

def test_node_list(live):
    assert ros2("node", "list", env=live.env).stdout == "/cli_listener\n/cli_talker\n"


def test_node_info(live):
    text = ros2("node", "info", "/cli_talker", env=live.env).stdout
    assert text.startswith("/cli_talker\n  Subscribers:\n\n  Publishers:\n    /cli_chatter: std_msgs/msg/String\n")
    assert "    /cli_talker/set_parameters: rcl_interfaces/srv/SetParameters\n" in text
    assert text.endswith("  Action Servers:\n\n  Action Clients:\n\n")


def test_node_info_finds_a_hidden_node_only_with_include_hidden(live):
    """ros2node's test_cli.py: test_info_hidden_node_no_hidden_flag ("Unable to find node
    '/_hidden_complex_node'") and test_info_hidden_node_hidden_flag; info/verb.py takes the name
    as given, so a name without its namespace is not found either."""
    args = [sys.executable, str(live.script), "talker", "--ros-args", "-r", "__node:=_hidden_talker"]
    with processes.NodeProcess(args, domain_id=live.domain_id) as hidden:
        hidden.wait_for_node("_hidden_talker", timeout=30)
        plain, shown, relative, listed = ros2_together(
            ["node", "info", "/_hidden_talker"], ["node", "info", "/_hidden_talker", "--include-hidden"],
            ["node", "info", "cli_talker"], ["node", "list", "-a"], env=live.env)
    assert (plain.returncode, plain.stdout, plain.stderr) == (1, "", "Unable to find node '/_hidden_talker'\n")
    assert shown.stdout.startswith("/_hidden_talker\n  Subscribers:\n") and shown.returncode == 0
    assert (relative.returncode, relative.stderr) == (1, "Unable to find node 'cli_talker'\n")
    assert "/_hidden_talker\n" in listed.stdout


def test_unknown_names_fail_in_ros2clis_words(live):
    """ros2topic's test_cli.py: test_topic_echo_no_publisher (its "WARNING: topic ... does not
    appear to be published yet" is on stdout), test_info_on_unknown_topic; ros2param's verbs
    return "Node not found"; echo/pub: "The passed message type is invalid". How soon they fail
    is benchmarks/bench_ros2cli.py's to measure (tests/course_lib/ros/test_discovery.py holds the rule)."""
    echo, info, param_list, param_get, bad_type = ros2_together(
        ["topic", "echo", "/no_such_topic"], ["topic", "info", "/no_such_topic"], ["param", "list", "/no_such_node"],
        ["param", "get", "/no_such_node", "rate"], ["topic", "echo", "/cli_chatter", "std_msgs/msg/NotAType"],
        env=live.env)
    assert (echo.returncode, echo.stdout, echo.stderr) == (
        1, "WARNING: topic [/no_such_topic] does not appear to be published yet\n",
        "Could not determine the type for the passed topic\n")
    assert (info.returncode, info.stderr) == (1, "Unknown topic '/no_such_topic'\n")
    for done in (param_list, param_get):
        assert (done.returncode, done.stderr) == (1, "Node not found\n")
    assert (bad_type.returncode, bad_type.stderr) == (1, "The passed message type is invalid\n")


# --- ros2 topic -------------------------------------------------------------------------------

def test_topic_list(live):
    assert ros2("topic", "list", "-t", env=live.env).stdout.splitlines() == [
        "/cli_chatter [std_msgs/msg/String]", "/cli_numbers [std_msgs/msg/Int32]",
        "/parameter_events [rcl_interfaces/msg/ParameterEvent]", "/rosout [rcl_interfaces/msg/Log]"]


def test_topic_echo(live):
    once, field = ros2_together(["topic", "echo", "/cli_chatter", "--once"],
                                ["topic", "echo", "cli_chatter", "std_msgs/msg/String", "--field", "data", "--once"],
                                env=live.env)
    assert re.fullmatch(r"data: hello \d+\n---\n", once.stdout), once
    assert re.fullmatch(r"hello \d+\n---\n", field.stdout), field


def test_topic_hz_prints_rates_until_ctrl_c(live):
    """Average rate lines like ros2cli's every second; SIGINT ends it without a traceback.

    How regular the talker's messages come is the machine's doing, so the rates are not judged
    against its 10 Hz; what follows from any arrivals is: each report's mean period lies between
    its shortest and longest, and the periods of a report (window / rate) span at least a second
    more than those of the report before (the first: at least a second)."""
    env = dict(live.env)
    env.pop("COURSE_LIB_UNDER_TEST")  # the live behaviour: run until Ctrl-C
    hz = subprocess.Popen([str(ROS2), "topic", "hz", "/cli_chatter"], env=env, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True, stdin=subprocess.DEVNULL)
    try:
        lines = [hz.stdout.readline()]
        if lines[0] == "WARNING: topic [/cli_chatter] does not appear to be published yet\n":
            lines = []  # ros2cli's line when discovery takes longer than its wait; it waits on
        lines += [hz.stdout.readline() for _ in range(4 - len(lines))]
        hz.send_signal(signal.SIGINT)
        code = hz.wait(timeout=60)
    finally:
        hz.kill()
        hz.wait()
    reports = []
    for average, spread in zip(lines[::2], lines[1::2], strict=True):
        assert re.fullmatch(r"average rate: \d+\.\d{3}\n", average), lines
        found = re.fullmatch(r"\tmin: (\d+\.\d{3})s max: (\d+\.\d{3})s std dev: \d+\.\d{5}s window: (\d+)\n", spread)
        assert found, lines
        reports.append((float(average.split()[-1]), float(found[1]), float(found[2]), int(found[3])))
    rounding = 0.001  # min and max are printed in milliseconds
    for rate, shortest, longest, _ in reports:
        assert shortest - rounding <= 1 / rate <= longest + rounding, lines
    spans = [window / rate for rate, _, _, window in reports]
    assert spans[0] >= 1.0 - rounding and spans[1] >= spans[0] + 1.0 - rounding, (spans, lines)
    assert code == 2 and "Traceback" not in hz.stderr.read()


@pytest.mark.parametrize("args, ready, number, code", [
    (["topic", "echo", "/cli_chatter"], "---", signal.SIGINT, 2),
    (["topic", "hz", "/cli_chatter"], "average rate:", signal.SIGTERM, 15),
    (["topic", "pub", "/cli_numbers", "std_msgs/msg/Int32", "{data: 1}"], "publishing #1", signal.SIGINT, 2),
])
def test_a_verb_started_with_ampersand_by_a_script_ends_on_a_signal(live, tmp_path, args, ready, number, code):
    """A script's `ros2 topic ... &` inherits SIGINT ignored; like ros2cli (whose rclpy installs
    its handlers), it still ends on SIGINT (exit code 2) and SIGTERM (15, ros2cli/cli.py's
    ExternalShutdownException), without a traceback."""
    env = dict(live.env)
    env.pop("COURSE_LIB_UNDER_TEST")  # the live behaviour: run until a signal
    output = tmp_path / "out"
    shell, pid = in_background_of_a_script([str(ROS2), *args], output, env)
    try:
        assert wait_until(lambda: ready in output.read_text()), output.read_text()
        os.kill(pid, number)
        assert shell.wait(timeout=60) == code, output.read_text()
    finally:
        shell.kill()
        shell.wait()
    assert "Traceback" not in output.read_text()


@pytest.mark.parametrize("interruption, code", [(KeyboardInterrupt, 2), ("Terminated", 15)])
def test_an_error_while_cleaning_up_after_a_signal_still_ends_with_the_signals_code(monkeypatch, capsys,
                                                                                   interruption, code):
    """Ctrl-C raises KeyboardInterrupt wherever a verb is, and the verb's clean-up (unsubscribing)
    may then fail in rclpy ('cannot use Destroyable ...'): the command was ended by the signal
    all the same, exit code 2 (15 for SIGTERM), not 1 with the clean-up's error."""
    from course_lib.ros2cli import cli, topic

    signal_error = cli.Terminated if interruption == "Terminated" else interruption

    def verb(argv):
        try:
            raise signal_error()
        finally:
            raise RuntimeError("cannot use Destroyable because destruction was requested")

    monkeypatch.setattr(topic, "main", verb)
    assert cli.main(["topic", "bw", "/words"]) == code
    assert "Destroyable" not in capsys.readouterr().err
    monkeypatch.setattr(topic, "main", lambda argv: (_ for _ in ()).throw(RuntimeError("no such topic")))
    assert cli.main(["topic", "bw", "/words"]) == 1, "an error of its own is still the verb's failure"


def test_topic_info(live):
    short, verbose = (done.stdout for done in ros2_together(["topic", "info", "/cli_chatter"],
                                                            ["topic", "info", "-v", "/cli_chatter"], env=live.env))
    assert short == "Type: std_msgs/msg/String\nPublisher count: 1\nSubscription count: 1\n"
    assert "\n\nNode name: cli_talker\nNode namespace: /\nTopic type: std_msgs/msg/String\n" in verbose
    assert "Endpoint type: SUBSCRIPTION\n" in verbose and verbose.endswith("\n\n")


def test_topic_pub_reaches_the_listener(live):
    """pub --once waits for the listener, publishes the YAML values, and the listener hears them."""
    out = ros2("topic", "pub", "--once", "/cli_numbers", "std_msgs/msg/Int32", "{data: 5}", env=live.env).stdout
    assert "publisher: beginning loop\npublishing #1: std_msgs.msg.Int32(data=5)\n\n" in out
    live.listener.wait_for_output("heard 5", timeout=60)
    bad = ros2("topic", "pub", "--once", "/cli_numbers", "std_msgs/msg/Int32", "{dat: 5}", env=live.env,
               check=False)
    assert bad.returncode == 1 and bad.stderr.startswith("Failed to populate field: std_msgs/msg/Int32 has no "
                                                         "field 'dat'")


# --- ros2 param -------------------------------------------------------------------------------

def test_param_list(live):
    text = ros2("param", "list", "--param-type", env=live.env).stdout
    assert text.startswith("/cli_listener:\n  start_type_description_service (type: boolean)\n")
    assert ("/cli_talker:\n  greeting (type: string)\n  limits.low (type: integer)\n  rate (type: double)\n"
            in text)


def test_param_get(live):
    found, unset, missing = ros2_together(["param", "get", "/cli_talker", "greeting"],
                                          ["param", "get", "/cli_talker", "nope"],
                                          ["param", "get", "/ghost", "rate", "--timeout", "0", "--spin-time", "0.1"],
                                          env=live.env)
    assert found.stdout == "String value is: hello\n"
    assert (unset.returncode, unset.stderr) == (1, "Parameter not set\n")
    assert (missing.returncode, missing.stderr) == (1, "Node not found\n")


def test_param_set_goes_through_the_nodes_callback(live):
    """Accepted: the node has the value. Rejected: ros2cli's message with the node's reason."""
    accepted, refused = ros2_together(["param", "set", "/cli_talker", "rate", "5.0"],
                                      ["param", "set", "/cli_talker", "rate", "-1.0"], env=live.env)
    assert accepted.stdout == "Set parameter successful\n" and accepted.returncode == 0
    assert refused.returncode == 0  # ros2cli too: a refusal is printed, not an error exit
    assert refused.stderr == "Setting parameter failed: rate must be positive\n" and refused.stdout == ""
    assert ros2("param", "get", "/cli_talker", "rate", env=live.env).stdout == "Double value is: 5.0\n"


def test_param_load(live, tmp_path):
    path = tmp_path / "talker.yaml"
    path.write_text("/cli_talker:\n  ros__parameters:\n    limits:\n      low: 3\n    rate: -2.0\n")
    done = ros2("param", "load", "/cli_talker", str(path), env=live.env)
    assert done.stdout == "Set parameter limits.low successful\n"
    assert done.stderr == "Set parameter rate failed: rate must be positive\n"
    assert ros2("param", "get", "/cli_talker", "limits.low", "--hide-type", env=live.env).stdout == "3\n"


def test_param_dump_is_a_params_file(live, tmp_path):
    """Dump a node's parameters, start it again with --params-file the dump: it has the value."""
    name = "cli_dumped"
    args = [sys.executable, str(live.script), "talker", "--ros-args", "-r", f"__node:={name}"]
    with processes.NodeProcess(args + ["-p", "greeting:=dumped"], domain_id=live.domain_id) as first:
        first.wait_for_node(name, timeout=30)
        dump = ros2("param", "dump", f"/{name}", env=live.env).stdout
    assert dump.startswith(f"/{name}:\n  ros__parameters:\n    greeting: dumped\n    limits:\n      low: 1\n")
    path = tmp_path / "dumped.yaml"
    path.write_text(dump)
    assert yaml.safe_load(dump)[f"/{name}"]["ros__parameters"]["rate"] == 10.0
    with processes.NodeProcess(args + ["--params-file", str(path)], domain_id=live.domain_id) as second:
        second.wait_for_node(name, timeout=30)
        assert ros2("param", "get", f"/{name}", "greeting", env=live.env).stdout == "String value is: dumped\n"


# --- ros2 interface / pkg / launch --------------------------------------------------------------

def test_interface_verbs():
    env = rosenv.ros_environment()
    show = ros2("interface", "show", "geometry_msgs/msg/Twist", "--no-comments", env=env).stdout
    assert show.startswith("Vector3  linear\n\tfloat64 x\n")
    assert "std_msgs/msg/Int32\n" in ros2("interface", "package", "std_msgs", env=env).stdout
    listing = ros2("interface", "list", "-m", env=env).stdout
    assert listing.startswith("Messages:\n") and "    sensor_msgs/msg/Image\n" in listing
    assert "Services:" not in listing
    assert "rcl_interfaces\n" in ros2("interface", "packages", env=env).stdout


@pytest.mark.parametrize("name, words", [
    # ros2interface's test_cli.py: test_show_not_a_package, test_show_not_an_interface (rosidl_runtime_py)
    ("not_a_package/msg/String", "Unknown package 'not_a_package'\n"),
    ("std_msgs/msg/NotAMessageTypeName",
     r"Could not find the interface '/.+/share/std_msgs/msg/NotAMessageTypeName\.idl'\n"),
    ("std_msgs/String", "Invalid name 'std_msgs/String'. Expected three parts separated by '/'\n"),  # show.py
])
def test_interface_show_of_what_is_not_there_says_it_in_ros2clis_words(name, words):
    """Exactly the real line: no notebook helper is named in a terminal."""
    done = ros2("interface", "show", name, env=rosenv.ros_environment(), check=False)
    assert done.returncode == 1 and done.stdout == ""
    assert re.fullmatch(words, done.stderr), done.stderr


def test_pkg_verbs():
    env = rosenv.ros_environment()
    assert "std_msgs\n" in ros2("pkg", "list", env=env).stdout
    prefix = ros2("pkg", "prefix", "std_msgs", env=env).stdout.strip()
    assert (Path(prefix) / "share" / "std_msgs" / "package.xml").is_file()
    assert ros2("pkg", "prefix", "--share", "std_msgs", env=env).stdout.strip() == f"{prefix}/share/std_msgs"
    # ros2pkg's test_cli.py: test_not_a_package_prefix
    missing = ros2("pkg", "prefix", "no_such_pkg", env=env, check=False)
    assert (missing.returncode, missing.stdout, missing.stderr) == (1, "", "Package not found\n")
    # ros2pkg's verb/executables.py; ros2run's command/run.py
    for args in (["pkg", "executables", "no_such_pkg"], ["run", "no_such_pkg", "talker"]):
        done = ros2(*args, env=env, check=False)
        assert (done.returncode, done.stderr) == (1, "Package 'no_such_pkg' not found\n")


def test_pkg_create_says_what_it_creates_in_ros2pkgs_order_and_form(tmp_path):
    """ros2pkg's test_cli.py (test_create_package) and api/create.py: relative to the destination
    ("./pkg/..."), the source folder announced, each folder once, in the order it is made."""
    done = subprocess.run([str(ROS2), "pkg", "create", "demo_pkg", "--build-type", "ament_python", "--node-name",
                           "my_node", "--dependencies", "rclpy"], cwd=tmp_path, env=rosenv.ros_environment(),
                          capture_output=True, text=True, timeout=60, stdin=subprocess.DEVNULL)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[lines.index("node_name: my_node") + 1:] == [
        "creating folder ./demo_pkg", "creating ./demo_pkg/package.xml", "creating source folder",
        "creating folder ./demo_pkg/demo_pkg", "creating ./demo_pkg/setup.py", "creating ./demo_pkg/setup.cfg",
        "creating folder ./demo_pkg/resource", "creating ./demo_pkg/resource/demo_pkg",
        "creating ./demo_pkg/demo_pkg/__init__.py", "creating folder ./demo_pkg/test",
        "creating ./demo_pkg/test/test_copyright.py", "creating ./demo_pkg/test/test_flake8.py",
        "creating ./demo_pkg/test/test_pep257.py", "creating ./demo_pkg/demo_pkg/my_node.py"]
    assert (tmp_path / "demo_pkg" / "demo_pkg" / "my_node.py").is_file()


def test_launch_runs_course_lib_launch(tmp_path):
    """ros2 launch hands everything after the word to course_lib.launch: a launch file's arguments."""
    path = tmp_path / "demo.launch.xml"
    path.write_text('<launch>\n  <arg name="rate" default="10" description="messages per second"/>\n</launch>\n')
    shown = ros2("launch", str(path), "--show-args", env=rosenv.ros_environment()).stdout
    assert shown.startswith("Arguments (pass arguments as '<name>:=<value>'):")
    assert "'rate':" in shown and "messages per second" in shown and "(default: '10')" in shown


@pytest.mark.slow
def test_pkg_create_build_and_run(tmp_path, domain_id):
    """ros2 pkg create writes an ament_python package that colcon builds; ros2 run finds its
    executables and becomes the node (exec), so SIGINT reaches the node itself."""
    src = tmp_path / "ws" / "src"
    src.mkdir(parents=True)
    env = rosenv.ros_environment(domain_id=domain_id)
    created = ros2("pkg", "create", "--build-type", "ament_python", "--dependencies", "rclpy", "--node-name",
                   "hello", "--destination-directory", str(src), "demo_pkg", env=env).stdout
    assert created.startswith("going to create a new package\npackage name: demo_pkg\n")
    assert f"creating {src}/demo_pkg/package.xml\n" in created
    package = src / "demo_pkg"
    (package / "demo_pkg" / "spinner.py").write_text(SPINNER)
    setup = package / "setup.py"
    setup.write_text(setup.read_text().replace("'hello = demo_pkg.hello:main',",
                                               "'hello = demo_pkg.hello:main',\n"
                                               "            'spinner = demo_pkg.spinner:main',"))
    colcon.build(tmp_path / "ws", timeout=300)
    env = workspace.workspace_environment(tmp_path / "ws", domain_id=domain_id)
    assert ros2("pkg", "executables", "demo_pkg", env=env).stdout == "demo_pkg hello\ndemo_pkg spinner\n"
    assert ros2("run", "demo_pkg", "hello", env=env).stdout == "Hi from demo_pkg.\n"
    spinner = subprocess.Popen([str(ROS2), "run", "demo_pkg", "spinner", "--ros-args", "-r", "__node:=turned"],
                               env=env, stdout=subprocess.PIPE, text=True, stdin=subprocess.DEVNULL)
    try:
        assert spinner.stdout.readline() == "spinning as /turned\n"
        command_line = Path(f"/proc/{spinner.pid}/cmdline").read_bytes().split(b"\0")
        assert command_line[1].endswith(b"lib/demo_pkg/spinner")  # the node itself, not ros2
        spinner.send_signal(signal.SIGINT)
        assert spinner.wait(timeout=60) == 0  # a backstop: the node ends on the signal
    finally:
        spinner.kill()
        spinner.wait()
    missing = ros2("run", "demo_pkg", "nope", env=env, check=False)
    assert (missing.returncode, missing.stderr) == (1, "No executable found\n")  # ros2run's words


SPINNER = '''import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node


def main(args=None):
    rclpy.init(args=args)
    node = Node('spinner')
    try:
        print(f'spinning as {node.get_fully_qualified_name()}', flush=True)
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
'''
