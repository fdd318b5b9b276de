"""Tests for course_lib.ros.workspace: a built workspace sourced and its nodes run (and the real colcon build of it).

The slow tests share one workspace, built once per test run (tests/support/tutorial_workspace.py, shared
with tests/course_lib/ros2cli/test_ros2cli_interface_builds.py): the interface package tutorial_interfaces
(msg/MsgTutorial.msg among others) and the ament_python package tutorial_nodes that uses it.
"""

import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from support import tutorial_workspace
from support.ros2cli import ros2

from course_lib.ros import rosenv, workspace
from course_lib.supervision import process_tree


@pytest.fixture(scope="session")
def built_ws(tmp_path_factory):
    """The tutorial workspace (tutorial_interfaces and tutorial_nodes), built once per test run with
    the real colcon (tests/support/tutorial_workspace.py)."""
    return tutorial_workspace.built(tmp_path_factory)[0]


def wait_for_log(process, pattern: str, count: int, timeout: float) -> list[re.Match]:
    """Poll a NodeProcess log until `count` lines match (bounded by timeout); return the matches."""
    deadline = time.monotonic() + timeout
    while True:
        matches = list(re.finditer(pattern, process.log))
        if len(matches) >= count or time.monotonic() > deadline or not process.running():
            return matches
        time.sleep(0.1)


# --- running (fast) ----------------------------------------------------------------------------

def _fake_install(ws: Path) -> None:
    lib = ws / "install" / "demo" / "lib" / "demo"
    lib.mkdir(parents=True)
    (ws / "install" / "setup.bash").write_text("")
    (lib / "talker").write_text("#!/bin/sh\n")
    (lib / "talker").chmod(0o755)
    (lib / "listener").write_text("#!/bin/sh\n")
    (lib / "listener").chmod(0o755)


def test_executable_command_builds_ros_args_like_ros2_run(tmp_path):
    _fake_install(tmp_path)
    command = workspace.executable_command(
        tmp_path, "demo", "talker", remap={"chatter": "news", "__node": "loud"},
        params={"rate": 2.5, "verbose": True, "names": ["a", "b"]}, params_file=tmp_path / "p.yaml",
        ros_args=["--log-level", "debug"])
    assert command == [str(tmp_path / "install/demo/lib/demo/talker"), "--ros-args",
                       "-r", "chatter:=news", "-r", "__node:=loud",
                       "-p", "rate:=2.5", "-p", "verbose:=true", "-p", "names:=[a, b]",
                       "--params-file", str(tmp_path / "p.yaml"), "--log-level", "debug"]
    assert workspace.executable_command(tmp_path, "demo", "talker") == [command[0]]


def test_missing_executables_and_packages_are_listed(tmp_path):
    _fake_install(tmp_path)
    with pytest.raises(FileNotFoundError, match="available: listener, talker"):
        workspace.executable_command(tmp_path, "demo", "speaker")
    with pytest.raises(FileNotFoundError, match="built packages: demo"):
        workspace.executable_command(tmp_path, "other", "talker")
    with pytest.raises(FileNotFoundError, match="build the workspace first"):
        workspace.executable_command(tmp_path / "nowhere", "demo", "talker")


# --- real builds (slow) ------------------------------------------------------------------------

@pytest.mark.slow
def test_built_workspace_installs_both_packages_like_colcon_does(built_ws):
    install = built_ws / "install"
    assert (install / "setup.bash").is_file()
    assert workspace.executables(built_ws, "tutorial_nodes") == ["hello_node", "topic_publisher",
                                                                 "topic_subscriber"]
    assert list((install / "tutorial_interfaces/lib").glob("libtutorial_interfaces__rosidl_typesupport_c.so"))


@pytest.mark.slow
def test_generated_node_logs_and_takes_remaps(built_ws, domain_id):
    command = workspace.executable_command(built_ws, "tutorial_nodes", "hello_node",
                                           remap={"__node": "renamed_hello"}, params={"use_sim_time": False})
    env = workspace.workspace_environment(built_ws, domain_id=domain_id)
    # Clean-clone run #53: the node still ran 10 s after Ctrl-C (SIGKILL, -9) and its output said
    # nothing more; with the fault handler, the abort that ends a stuck node prints its stacks.
    process = subprocess.Popen(command, env=dict(env, PYTHONFAULTHANDLER="1"), stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True, start_new_session=True)
    lines, greeted = [], threading.Event()

    def read():
        for line in process.stdout:
            lines.append(line)
            if "Node started!" in line:
                greeted.set()

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    try:
        greeted.wait(timeout=30)
        # "Node started!" comes before rclpy.spin(): a SIGINT then ends the context before the
        # executor is made (rclpy raises RCLError). Its parameter service answers once it spins.
        answer = ros2("param", "get", "/renamed_hello", "use_sim_time", env=env).stdout
        assert answer.strip() == "Boolean value is: False", answer
    finally:
        # Ctrl-C; after the suite's 60 s backstop SIGABRT, which the fault handler turns into stacks
        process_tree.stop_group(process, steps=((signal.SIGINT, 60.0), (signal.SIGABRT, 10.0), (signal.SIGKILL, 10.0)))
        reader.join(timeout=10)
    output = "".join(lines)
    assert process.returncode == 0, output  # SIGINT ends the node cleanly (try/finally + try_shutdown)
    assert re.search(r"\[renamed_hello\]: Node started!", output), output


@pytest.mark.slow
def test_messages_import_in_a_subprocess_with_the_workspace_environment(built_ws):
    code = ("from tutorial_interfaces.msg import MsgTutorial\n"
            "from rclpy.serialization import serialize_message, deserialize_message\n"
            "m = deserialize_message(serialize_message(MsgTutorial(data=41)), MsgTutorial)\n"
            "print(type(m).__name__, m.data, m.stamp.sec)\n")
    env = workspace.workspace_environment(built_ws)
    assert str(built_ws / "install/tutorial_interfaces/lib") in env["LD_LIBRARY_PATH"].split(os.pathsep)
    assert "" not in env["LD_LIBRARY_PATH"].split(os.pathsep)
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)
    assert done.stdout.split() == ["MsgTutorial", "41", "0"], done.stderr


@pytest.mark.slow
def test_use_workspace_imports_messages_in_a_running_interpreter(built_ws):
    # A fresh interpreter whose LD_LIBRARY_PATH knows nothing of the workspace, like a kernel
    # started before the build.
    code = ("import sys\n"
            "from course_lib import colcon, pkg_create, workspace\n"
            f"print(workspace.use_workspace({str(built_ws)!r}))\n"
            "from tutorial_interfaces.msg import MsgTutorial\n"
            "from rclpy.serialization import serialize_message, deserialize_message\n"
            "m = MsgTutorial(data=7); m.stamp.sec = 3\n"
            "back = deserialize_message(serialize_message(m), MsgTutorial)\n"
            "print(back.data, back.stamp.sec)\n")
    env = rosenv.ros_environment()
    assert str(built_ws) not in env.get("LD_LIBRARY_PATH", "")
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)
    assert done.stdout.splitlines() == ["['tutorial_interfaces', 'tutorial_nodes']", "7 3"], done.stderr


@pytest.mark.slow
def test_publisher_reaches_subscriber_across_two_processes(built_ws, domain_id):
    subscriber = workspace.run(built_ws, "tutorial_nodes", "topic_subscriber", remap={"topic": "tutorial_topic"},
                               domain_id=domain_id, name="test_topic_subscriber")
    publisher = None
    try:
        subscriber.wait_for_node("topic_subscriber", timeout=60)
        publisher = workspace.run(built_ws, "tutorial_nodes", "topic_publisher", domain_id=domain_id,
                                  remap={"topic": "tutorial_topic"}, params={"start": 100},
                                  name="test_topic_publisher")
        received = wait_for_log(subscriber, r"Received: stamp=(\d+)\.(\d{9}) data=(\d+)", count=5, timeout=60)
    finally:
        if publisher is not None:
            publisher.stop()
        subscriber.stop()
    assert len(received) >= 5, f"subscriber log:\n{subscriber.log}\npublisher log:\n{publisher.log}"
    data = [int(m.group(3)) for m in received]
    stamps = [(int(m.group(1)), int(m.group(2))) for m in received]
    assert data[0] >= 100, data  # the start parameter reached the publisher
    assert data == sorted(data) and len(set(data)) == len(data), data
    assert stamps == sorted(stamps) and stamps[0][0] > 0, stamps


@pytest.mark.slow
def test_command_line_build_prints_what_to_source(built_ws, tmp_path_factory):
    with tutorial_workspace.rebuilding(tmp_path_factory):
        done = subprocess.run([sys.executable, "-m", "course_lib", "build", str(built_ws),
                               "--packages-select", "tutorial_nodes"],
                              capture_output=True, text=True, timeout=300, env=rosenv.ros_environment())
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Finished <<< tutorial_nodes" in done.stdout
    assert f"source {built_ws / 'install' / 'setup.bash'}" in done.stdout
