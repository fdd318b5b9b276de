"""course_lib.launch with real processes: ros2 launch brings up the graph a launch file describes.

The package course_demo lives in a temporary prefix with an ament index marker (support/launch_demo.py):
two small rclpy nodes (chatter_a, chatter_b) and a few shell executables, its launch files and a
parameter file in share/. `ros2 launch` is run as `python -m course_lib.launch` (what the ros2 command
calls); the graph is read with course_lib.ros.graph and the parameters through the nodes' own
parameter services. Leftover processes are found by the prefix's path, which is in the command
line of every process a launch starts (nodes and their supervisors).
"""

import os
import re
import signal
import subprocess
import sys
import textwrap
import time
import types
from pathlib import Path

import psutil
import pytest
from support.launch_demo import CHATTER_NODE, CHATTER_SOURCE, make_prefix
from support.process import in_background_of_a_script

from course_lib import launch
from course_lib.notebook import rqt_graph
from course_lib.ros import colcon, graph, pkg_create, rosenv, session, workspace

EVERY_TAG = """\
<launch>
  <arg name="robot" description="namespace of the robot"/>
  <arg name="rate" default="5"/>
  <let name="greeting" value="hello_$(var robot)"/>
  <set_env name="COURSE_GREETING" value="$(var greeting)"/>
  <include file="$(find-pkg-share course_demo)/launch/listener.launch.yaml">
    <arg name="topic" value="/$(var robot)/chatter"/>
  </include>
  <group>
    <push_ros_namespace namespace="$(var robot)"/>
    <node pkg="course_demo" exec="chatter_a" name="talker" output="screen">
      <param from="$(find-pkg-share course_demo)/config/params.yaml"/>
      <param name="rate" value="$(var rate)"/>
      <param name="camera">
        <param name="width" value="640"/>
        <param name="frame" value="front"/>
      </param>
      <remap from="heard" to="/$(var robot)/answers"/>
    </node>
  </group>
</launch>
"""

LISTENER = """\
launch:
- arg: {name: topic}
- node:
    pkg: course_demo
    exec: chatter_b
    name: listener
    namespace: other
    param:
    - {name: use_color, value: true}
    remap:
    - {from: chatter, to: $(var topic)}
"""

ENDINGS = """\
<launch>
  <node pkg="course_demo" exec="crasher"/>
  <node pkg="course_demo" exec="quitter"/>
  <executable cmd="sh -c 'pwd; echo $COURSE_WORD; exit 3'" cwd="$(dirname)" name="job" output="screen">
    <env name="COURSE_WORD" value="hello"/>
  </executable>
  <executable cmd="sh -c 'echo hidden'"/>
</launch>
"""

SLEEPERS = """\
<launch>
  <node pkg="course_demo" exec="sleeper" output="screen"/>
  <node pkg="course_demo" exec="sleeper"/>
</launch>
"""

STUBBORN = """\
<launch>
  <node pkg="course_demo" exec="deaf_to_int" output="screen"/>
  <node pkg="course_demo" exec="deaf_to_int_and_term" output="screen"/>
</launch>
"""


@pytest.fixture(scope="module")
def prefix(tmp_path_factory):
    """The prefix of package course_demo, on AMENT_PREFIX_PATH for this module."""
    prefix = make_prefix(tmp_path_factory.mktemp("course_demo_prefix"), "course_demo", {
        "chatter_a": CHATTER_NODE,
        "chatter_b": CHATTER_NODE,
        "crasher": "#!/bin/sh\necho to stdout\necho to stderr >&2\nexit 1\n",
        "quitter": "#!/bin/sh\nsleep 0.5\nexit 0\n",
        "sleeper": "#!/bin/sh\ntrap 'echo bye; exit 0' INT\necho sleeping\nwhile :; do sleep 0.1; done\n",
        "deaf_to_int": "#!/bin/sh\ntrap '' INT\necho deaf\nwhile :; do sleep 0.1; done\n",
        "deaf_to_int_and_term": "#!/bin/sh\ntrap '' INT TERM\necho deaf\nwhile :; do sleep 0.1; done\n",
    }, {
        "launch/every_tag.launch.xml": EVERY_TAG,
        "launch/listener.launch.yaml": LISTENER,
        "launch/endings.launch.xml": ENDINGS,
        "launch/sleepers.launch.xml": SLEEPERS,
        "launch/stubborn.launch.xml": STUBBORN,
        "config/params.yaml": "/**:\n  ros__parameters:\n    gain: 2\n    rate: 1\n",
    })
    saved = os.environ.get("AMENT_PREFIX_PATH", "")
    os.environ["AMENT_PREFIX_PATH"] = f"{prefix}{os.pathsep}{saved}"
    yield prefix
    os.environ["AMENT_PREFIX_PATH"] = saved


@pytest.fixture(scope="module")
def ros_domain(session_domain):
    """A domain of its own for this module, with the session (graph's tool node) on it."""
    return session_domain


def processes_below(path) -> list[psutil.Process]:
    """Live processes whose command line names something below `path`."""
    found = []
    for process in psutil.process_iter(["cmdline", "status"]):
        try:
            if process.info["status"] != psutil.STATUS_ZOMBIE and any(
                    str(path) in part for part in process.info["cmdline"] or ()):
                found.append(process)
        except (psutil.NoSuchProcess, psutil.AccessDenied):
            pass
    return found


def wait_until(condition, timeout: float = 60.0):
    """Poll `condition` until it holds or `timeout` (a backstop) passes; return its last value."""
    deadline = time.monotonic() + timeout
    while not (result := condition()) and time.monotonic() < deadline:
        time.sleep(0.05)
    return result


def ros2_launch(*argv: str, domain_id: int, env: dict | None = None) -> subprocess.Popen:
    """`ros2 launch ARGV...` as a process, its output (stdout and stderr together) in a pipe."""
    environment = rosenv.ros_environment(domain_id=domain_id, base=env)
    return subprocess.Popen([sys.executable, "-m", "course_lib.launch", *argv], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, env=environment)


def interrupt(process: subprocess.Popen, timeout: float = 60.0) -> str:
    """Ctrl-C to a ros2 launch process; its whole output once it has ended. ``timeout`` is a
    backstop: the launch ends its nodes (each within its 5 s sigterm_timeout) long before."""
    process.send_signal(signal.SIGINT)
    try:
        output, _ = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        process.kill()
        output, _ = process.communicate()
        pytest.fail(f"ros2 launch did not end within {timeout} s of SIGINT:\n{output}")
    return output


def parameters_of(node_name: str, names: list[str]) -> dict:
    """Parameter values read from a running node through its get_parameters service."""
    from rcl_interfaces.srv import GetParameters
    from rclpy.parameter import parameter_value_to_python

    node = session.tool_node()
    client = node.create_client(GetParameters, f"{node_name}/get_parameters")
    try:
        assert client.wait_for_service(timeout_sec=60), f"{node_name}/get_parameters did not appear"
        future = client.call_async(GetParameters.Request(names=names))
        assert session.wait_for(future.done, timeout=60), f"{node_name} did not answer get_parameters"
        return {name: parameter_value_to_python(value)
                for name, value in zip(names, future.result().values, strict=True)}
    finally:
        node.destroy_client(client)


def test_every_tag_brings_up_the_expected_graph_and_ctrl_c_ends_it(prefix, ros_domain):
    """include with args, group + push_ros_namespace, params from a file, inline and nested, remaps
    and set_env give exactly the graph and the parameter values the launch file describes."""
    process = ros2_launch("course_demo", "every_tag.launch.xml", "robot:=r2", "rate:=7", domain_id=ros_domain)
    try:
        nodes = graph.node_list(wait_for=["/r2/talker", "/other/listener"], timeout=40)
        assert nodes == ["/other/listener", "/r2/talker"], f"nodes: {nodes}"
        topics = graph.topic_list(types=True, wait_for=["/r2/chatter", "/r2/answers", "/other/heard"], timeout=20)
        assert [(name, kinds) for name, kinds in topics if name not in rqt_graph.DEFAULT_HIDDEN_TOPICS] == [
            ("/other/heard", ["std_msgs/msg/String"]), ("/r2/answers", ["std_msgs/msg/String"]),
            ("/r2/chatter", ["std_msgs/msg/String"])]
        assert parameters_of("/r2/talker", ["gain", "rate", "camera.width", "camera.frame"]) == {
            "gain": 2, "rate": 7, "camera.width": 640, "camera.frame": "front"}
        assert parameters_of("/other/listener", ["use_color"]) == {"use_color": True}
        running = processes_below(prefix)
        assert len(running) == 4  # two nodes, each under its supervisor
    finally:
        output = interrupt(process)
    assert process.returncode == 0, output
    lines = output.splitlines()
    # The include comes first: the listener is process 1. Its output="log" shows only its stderr.
    assert "[chatter_a-2] COURSE_GREETING=hello_r2" in lines  # output="screen": stdout is shown too
    assert not any(line.startswith("[chatter_b-1] COURSE_GREETING") for line in lines)
    assert any(line.startswith("[chatter_b-1] [INFO]") and "[other.listener]: started" in line for line in lines)
    assert "[WARNING] [launch]: user interrupted with ctrl-c (SIGINT)" in lines
    for name in ("chatter_b-1", "chatter_a-2"):
        assert any(line.startswith(f"[INFO] [{name}]: process has finished cleanly [pid ") for line in lines), output
    assert wait_until(lambda: not processes_below(prefix), timeout=30), "processes outlived ros2 launch"
    log_dir = lines[0].rsplit(" ", 1)[1]
    assert "[chatter_b-1] COURSE_GREETING=hello_r2" in (Path(log_dir) / "launch.log").read_text()


def test_processes_that_end_are_reported_and_then_the_launch_ends(prefix, ros_domain):
    """Nodes and <executable> programs alike: launch's process names ([job-3]; an executable
    without a name takes its program's, [sh-4]), output, cwd and env, and its end-of-process lines."""
    process = ros2_launch("course_demo", "endings.launch.xml", domain_id=ros_domain)
    output, _ = process.communicate(timeout=30)
    assert process.returncode == 0, output
    lines = output.splitlines()
    crasher = next(line for line in lines if "[crasher-" in line and "process started with pid" in line)
    name, pid = crasher.split("] [")[1].split("]")[0], crasher.rsplit("[", 1)[1].rstrip("]")
    assert f"[{name}] to stderr" in lines and f"[{name}] to stdout" not in lines  # default output="log"
    assert (f"[ERROR] [{name}]: process has died [pid {pid}, exit code 1, "
            f"cmd '{prefix}/lib/course_demo/crasher --ros-args'].") in lines
    assert any("[quitter-" in line and "process has finished cleanly" in line for line in lines)
    job = next(line for line in lines if line.startswith("[INFO] [job-") and "process started with pid" in line)
    job_name, job_pid = job.split("] [")[1].split("]")[0], job.rsplit("[", 1)[1].rstrip("]")
    assert [line for line in lines if line.startswith(f"[{job_name}] ")] == [
        f"[{job_name}] {prefix}/share/course_demo/launch", f"[{job_name}] hello"]  # cwd, env; output="screen"
    assert (f"[ERROR] [{job_name}]: process has died [pid {job_pid}, exit code 3, cmd 'sh -c pwd; echo "
            "$COURSE_WORD; exit 3'].") in lines
    sh = next(line.split("] [")[1].split("]")[0] for line in lines if line.startswith("[INFO] [sh-"))
    assert f"[INFO] [{sh}]: process has finished cleanly" in "\n".join(lines)
    assert f"[{sh}] hidden" not in lines  # output="log" by default: stdout only in launch.log
    # The catdog check's launch item stops waiting on these lines (a marker_reader that died at start
    # kept it waiting for its whole backstop while the launch's camera went on).
    from course_lib.checks.assignments.catdog_warp import _ended

    finished = types.SimpleNamespace(log=output)
    assert _ended(finished, "crasher") and _ended(finished, "quitter") and not _ended(finished, "endings")
    shown_all = ros2_launch("-a", "course_demo", "endings.launch.xml", domain_id=ros_domain)
    output, _ = shown_all.communicate(timeout=30)
    assert any(line.startswith("[crasher-") and line.endswith("] to stdout") for line in output.splitlines())


def test_a_launch_file_error_is_reported_like_ros2_launch_and_starts_nothing(tmp_path, prefix, ros_domain):
    path = tmp_path / "bad.launch.xml"
    path.write_text('<launch>\n  <node pkg="course_demo" exec="sleeper"/>\n'
                    '  <node pkg="course_demo" exec="nope"/>\n</launch>\n')
    process = ros2_launch(str(path), domain_id=ros_domain)
    output, _ = process.communicate(timeout=30)
    assert process.returncode == 1
    assert (f"[ERROR] [launch]: Caught exception in launch (see debug for traceback): {path}:3: No executable "
            "'nope' found in package 'course_demo'") in output
    assert "process started" not in output


def test_a_script_s_background_command_inherits_sigint_ignored(tmp_path, ros_domain):
    """What the next test relies on: sh gives `command &` SIGINT ignored."""
    code = "import signal; print(signal.getsignal(signal.SIGINT) is signal.SIG_IGN)"
    shell, _ = in_background_of_a_script([sys.executable, "-c", code], tmp_path / "out",
                                         rosenv.ros_environment(domain_id=ros_domain))
    assert shell.wait(timeout=60) == 0
    assert (tmp_path / "out").read_text() == "True\n"


def test_kill_int_stops_a_launch_started_with_ampersand_by_a_script(tmp_path, prefix, ros_domain):
    """launch installs its own SIGINT handler, as ros2/launch's LaunchService does, so an
    inherited SIG_IGN does not leave the launch and its nodes running for good."""
    output = tmp_path / "launch.out"
    shell, pid = in_background_of_a_script([sys.executable, "-m", "course_lib.launch", "-a", "course_demo",
                                            "sleepers.launch.xml"], output,  # -a: both say "sleeping"
                                           rosenv.ros_environment(domain_id=ros_domain))
    try:
        assert wait_until(lambda: output.read_text().count("sleeping") == 2), output.read_text()
        os.kill(pid, signal.SIGINT)
        assert shell.wait(timeout=60) == 0  # `wait $!` ends when the launch has: its exit code
    finally:
        shell.kill()
        shell.wait()
    lines = output.read_text().splitlines()
    assert "[WARNING] [launch]: user interrupted with ctrl-c (SIGINT)" in lines
    # Like a Ctrl-C in ros2 launch's terminal: no "sending signal 'SIGINT'" line (interactive).
    assert not any("sending signal" in line for line in lines), lines
    assert sum("process has finished cleanly" in line for line in lines) == 2, lines
    assert wait_until(lambda: not processes_below(prefix), timeout=30), "processes outlived ros2 launch"


def test_sigterm_escalates_like_ros2_launch(tmp_path, prefix, ros_domain):
    """ros2/launch's ExecuteLocal: SIGINT, SIGTERM after sigterm_timeout, SIGKILL after
    sigkill_timeout more, each with its log lines (launch/actions/execute_local.py: "process[{}]
    failed to terminate '{}' seconds after receiving '{}', escalating to '{}'", "sending signal
    '{}' to process[{}]"); launch_service.py's three lines for SIGTERM; exit code 1."""
    output = tmp_path / "launch.out"
    shell, pid = in_background_of_a_script([sys.executable, "-m", "course_lib.launch", "course_demo",
                                            "stubborn.launch.xml", "sigterm_timeout:=1", "sigkill_timeout:=1"],
                                           output, rosenv.ros_environment(domain_id=ros_domain))
    try:
        assert wait_until(lambda: output.read_text().count("] deaf") == 2), output.read_text()
        os.kill(pid, signal.SIGTERM)
        assert shell.wait(timeout=60) == 1
    finally:
        shell.kill()
        shell.wait()
    text = output.read_text()
    first, second = (re.search(rf"\[INFO\] \[({name}-\d+)\]: process started with pid \[(\d+)\]", text).groups()
                     for name in ("deaf_to_int", "deaf_to_int_and_term"))
    expected = ["[ERROR] [launch]: user interrupted with ctrl-\\ (SIGTERM), terminating...",
                "[ERROR] [launch]: using SIGTERM can result in orphaned processes",
                "[ERROR] [launch]: make sure no processes launched are still running"]
    expected += [f"[INFO] [{name}]: sending signal 'SIGINT' to process[{name}]" for name, _ in (first, second)]
    for name, _ in (first, second):
        expected += [f"[ERROR] [{name}]: process[{name}] failed to terminate '1' seconds after receiving 'SIGINT', "
                     "escalating to 'SIGTERM'", f"[INFO] [{name}]: sending signal 'SIGTERM' to process[{name}]"]
    name = second[0]
    expected += [f"[ERROR] [{name}]: process[{name}] failed to terminate '2.0' seconds after receiving 'SIGTERM', "
                 "escalating to 'SIGKILL'", f"[INFO] [{name}]: sending signal 'SIGKILL' to process[{name}]"]
    lines = text.splitlines()
    assert [line for line in lines if line in expected] == expected, text
    for (name, process_id), code in ((first, -signal.SIGTERM), (second, -signal.SIGKILL)):
        assert any(line.startswith(f"[ERROR] [{name}]: process has died [pid {process_id}, exit code {code}, ")
                   for line in lines), text
    assert wait_until(lambda: not processes_below(prefix), timeout=30), "processes outlived ros2 launch"


def test_a_stop_timeout_that_is_not_a_number_is_a_launch_file_error(prefix, ros_domain):
    process = ros2_launch("course_demo", "sleepers.launch.xml", "sigterm_timeout:=soon", domain_id=ros_domain)
    output, _ = process.communicate(timeout=60)
    assert process.returncode == 1
    assert "sigterm_timeout is 'soon': give it in seconds, e.g. sigterm_timeout:=5" in output
    assert "process started" not in output


def test_notebook_start_replaces_its_previous_run_and_stop_ends_all(prefix):
    first = launch.start("course_demo", "sleepers.launch.xml")
    try:
        assert wait_until(lambda: "sleeping" in first.log)
        assert all(process.running() for process in first.processes) and len(first.processes) == 2
        second = launch.start("course_demo", "sleepers.launch.xml")  # the cell run again
        assert not any(process.running() for process in first.processes)
        assert all(process.running() for process in second.processes)
        assert "process has finished cleanly" in first.log
    finally:
        launch.stop_all()
    assert not any(process.running() for process in second.processes)
    assert wait_until(lambda: not processes_below(prefix), timeout=30)
    assert repr(second).startswith("<Launch sleepers.launch.xml: sleeper-") and "exit code 0" in repr(second)


def test_notebook_start_raises_on_a_bad_file_and_starts_nothing(tmp_path, prefix):
    path = tmp_path / "bad.launch.yaml"
    path.write_text("launch:\n- node: {pkg: course_demo, exec: sleeper}\n- arg: {name: needed}\n")
    with pytest.raises(launch.LaunchFileError, match="missing required argument 'needed'"):
        launch.start(path)
    assert not processes_below(prefix)


@pytest.mark.parametrize("ending", ["exit", "SIGKILL"])
def test_a_kernel_that_ends_takes_its_launches_with_it(prefix, ending):
    """atexit stops a notebook's launches; if the kernel is killed, their supervisors do."""
    code = textwrap.dedent(f"""
        import sys, time
        from course_lib import launch
        running = launch.start("course_demo", "sleepers.launch.xml")
        while running.log.count("sleeping") < 1:
            time.sleep(0.05)
        print("up", flush=True)
        sys.stdin.readline()
        {"sys.exit(0)" if ending == "exit" else "time.sleep(60)"}
        """)
    kernel = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                              text=True, env=rosenv.ros_environment())
    try:
        assert kernel.stdout.readline().strip() == "up"
        assert wait_until(lambda: len(processes_below(prefix)) == 4)  # two sleepers, each under its supervisor
        kernel.stdin.write("go on\n")
        kernel.stdin.flush()
        if ending == "SIGKILL":
            kernel.kill()
        kernel.wait(timeout=60)  # a backstop
    finally:
        kernel.kill()
        kernel.communicate()
    assert wait_until(lambda: not processes_below(prefix), timeout=30)


# --- a real colcon-built package ---------------------------------------------------------------

TALK_XML = """<launch>
  <arg name="rate" default="2.0"/>
  <node pkg="launch_tutorial" exec="talker" namespace="tutorial">
    <param name="rate" value="$(var rate)"/>
    <remap from="chatter" to="talk"/>
  </node>
</launch>
"""

TALK_YAML = """launch:
- arg: {name: rate, default: "2.0"}
- node:
    pkg: launch_tutorial
    exec: talker
    namespace: tutorial
    param: [{name: rate, value: $(var rate)}]
    remap: [{from: chatter, to: talk}]
"""


@pytest.fixture(scope="module")
def tutorial_ws(tmp_path_factory):
    """An ament_python package with a talker (launch_demo's node) and the same launch file as XML
    and YAML, installed to share/launch_tutorial/launch by setup.py, built once with the real colcon."""
    ws = tmp_path_factory.mktemp("launch_ws")
    package = pkg_create.create_package(ws, "launch_tutorial", dependencies=["rclpy", "std_msgs"], node_name="talker")
    (package / "launch_tutorial" / "talker.py").write_text(CHATTER_SOURCE)
    (package / "launch").mkdir()
    (package / "launch" / "talk.launch.xml").write_text(TALK_XML)
    (package / "launch" / "talk.launch.yaml").write_text(TALK_YAML)
    setup = (package / "setup.py").read_text()
    installed = "('share/' + package_name, ['package.xml']),"
    assert installed in setup
    launch_files = "('share/' + package_name + '/launch', ['launch/talk.launch.xml', 'launch/talk.launch.yaml']),"
    (package / "setup.py").write_text(setup.replace(installed, f"{installed}\n        {launch_files}"))
    colcon.build(ws, timeout=600)
    return ws


@pytest.mark.slow
@pytest.mark.parametrize("launch_file", ["talk.launch.xml", "talk.launch.yaml"])
def test_a_colcon_built_package_launches_by_package_and_file_name(tutorial_ws, ros_domain, launch_file):
    environment = workspace.workspace_environment(tutorial_ws, domain_id=ros_domain)
    process = ros2_launch("launch_tutorial", launch_file, "rate:=5.0", domain_id=ros_domain, env=environment)
    try:
        assert "/tutorial/talker" in graph.node_list(wait_for=["/tutorial/talker"], timeout=40)
        assert "/tutorial/talk" in graph.topic_list(wait_for=["/tutorial/talk"], timeout=60)
        assert parameters_of("/tutorial/talker", ["rate"]) == {"rate": 5.0}
        assert len(graph.topic_echo("/tutorial/talk", count=2, timeout=60)) == 2
    finally:
        output = interrupt(process)
    assert "process has finished cleanly" in output, output
    assert wait_until(lambda: not processes_below(tutorial_ws), timeout=30)
