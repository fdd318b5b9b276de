"""The terminal commands the lessons show run, and print what the lessons say they print.

A lesson shows commands in two ways: `!command` lines in code cells (run by the notebook) and
```bash blocks in its text (typed in a terminal, often long-running, like `ros2 run`). Every one
of them is listed here with the output it must give; a command added to a lesson without an
entry here fails test_every_command_shown_is_checked. The commands run as a terminal runs them
(bash, the workspace sourced), on one workspace built once per module from the lesson's own
files (its %%writefile cells).
"""

from __future__ import annotations

import json
import os
import re
import subprocess
from pathlib import Path

import pexpect
import pytest
from support import lesson_answers
from support.process import wait_until

from course_lib import contract
from course_lib.ros import colcon, pkg_create, processes, rosenv, session, workspace

NOTEBOOKS = contract.ROOT / "notebooks"
LESSON = "02b_packages_launch_parameters.ipynb"

#: The build cells of lessons 02b and 02: colcon build through the course's command, which shows
#: colcon's package lines and, when the build fails, ends with its cause (course_lib.ros.colcon).
#: (colcon also reminds of what it builds every 30 s: "[Processing: brightness]".)
BUILD_02B = "course-lib build {WS} --symlink-install --packages-select image_stats"
BUILD_02 = "course-lib build {WS} --symlink-install --packages-select brightness"

#: Lesson 02b's commands, in the lesson's order: the command ({WS}: the workspace) -> a pattern
#: its output must contain (None: a long-running command started in the background).
COMMANDS_02B = {
    "cd {WS}/src && ros2 pkg create --build-type ament_python --dependencies rclpy sensor_msgs std_msgs "
    "--node-name dark_fraction image_stats": r"package name: image_stats",
    "cd {WS}/src && find image_stats -type f | sort": r"^image_stats/image_stats/__init__\.py\n"
                                                     r"image_stats/image_stats/dark_fraction\.py\n"
                                                     r"image_stats/package\.xml\nimage_stats/resource/image_stats\n"
                                                     r"image_stats/setup\.cfg\nimage_stats/setup\.py\n",
    "cd {WS}/src/image_stats && mkdir -p launch config": r"^$",
    BUILD_02B: r"^Starting >>> image_stats\n(\[Processing: image_stats\]\n)*Finished <<< image_stats \[[\d.]+s\]\n\n"
              r"Summary: 1 package finished",
    "ros2 pkg executables image_stats": r"^image_stats camera\nimage_stats dark_fraction\n$",
    "ros2 run image_stats camera --ros-args -r image:=/camera/image_raw -p rate:=10.0": None,
    "ros2 run image_stats dark_fraction --ros-args -r /image:=/camera/image_raw": None,
    "ros2 topic list -t": r"/camera/image_raw \[sensor_msgs/msg/Image\]\n/dark_fraction \[std_msgs/msg/Float32\]\n"
                          r"/dark_fraction/frames \[std_msgs/msg/UInt32\]",
    "ros2 topic echo /dark_fraction --once": r"^data: 0\.\d+\n---\n$",
    "ros2 launch image_stats dark.launch.xml": None,
    "ros2 launch image_stats dark.launch.xml --show-args": r"No arguments",
    "ros2 param list /dark_fraction": r"^  dark\.threshold\n",
    "ros2 param get /dark_fraction dark.threshold": r"^Integer value is: 60\n$",
    "ros2 param set /dark_fraction dark.threshold 100": r"^Set parameter successful\n$",
    "ros2 param set /dark_fraction dark.threshold 300":
        r"^Setting parameter failed: dark\.threshold must be 0\.\.255, not 300\n$",
    "ros2 param get /dark_fraction dark.threshold#2": r"^Integer value is: 100\n$",
    "ros2 topic echo /dark_fraction/frames --once": r"^data: \d+\n---\n$",
}


LESSON_00 = "00_setup_and_workspace.ipynb"

#: Lesson 00's commands, in order, with the pattern their output must contain.
COMMANDS_00 = {
    # What the lesson says it shows: the commands, which real ros2's help lists after its options.
    "ros2 --help": r"^usage: ros2 (.*\n)+Commands:\n(  [a-z]+ +\S.*\n){5,}",
    "ros2 pkg executables my_package": r"^my_package my_node\n$",
    "ros2 node list": r"^/my_node$",
}


LESSON_02 = "02_images_and_brightness.ipynb"

#: Lesson 02's commands, in order (its exercise builds the package brightness in the same
#: workspace as lesson 02b's image_stats; the node file is a right answer to the exercise).
COMMANDS_02 = {
    "ros2 topic info -v /brightness": r"^Type: std_msgs/msg/UInt8\n\nPublisher count: 1\n\n"
                                      r"((?!Subscription count).*\n)*  Reliability: BEST_EFFORT\n",
    "cd {WS}/src && ros2 pkg create --build-type ament_python brightness --dependencies rclpy sensor_msgs std_msgs":
        r"package name: brightness\n(.*\n)*dependencies: \['rclpy', 'sensor_msgs', 'std_msgs'\]",
    'grep "<depend>" {WS}/src/brightness/package.xml': r"^  <depend>rclpy</depend>\n  <depend>sensor_msgs</depend>\n"
                                                       r"  <depend>std_msgs</depend>\n$",
    BUILD_02: r"^Starting >>> brightness\n(\[Processing: brightness\]\n)*Finished <<< brightness \[[\d.]+s\]\n\n"
              r"Summary: 1 package finished",
    "ros2 pkg executables brightness": r"^brightness brightness_node\n$",
    "ros2 run brightness brightness_node --ros-args -r /image:=/camera/image_raw": None,
    "ros2 topic echo /brightness --once": r"^data: \d+\n---\n$",
}

LESSON_01 = "01_publisher_subscriber.ipynb"

#: Lesson 01's commands, in order, while its talker (a process) and listener (in the notebook) run.
COMMANDS_01 = {
    "ros2 node list": r"^/listener\n/talker\n$",
    "ros2 topic info /chatter": r"^Type: std_msgs/msg/String\nPublisher count: 1\nSubscription count: 1\n$",
    "ros2 interface show geometry_msgs/msg/Twist": r"^Vector3  linear\n\tfloat64 x\n(.*\n)*Vector3  angular\n",
}

#: Lesson 01b's commands are not run here: they need its interface package, whose colcon build
#: (ament_cmake and rosidl) takes about 35 s on its own; tests/course_lib/ros/test_workspace.py builds the same
#: message and runs its nodes.
UNCHECKED_01B = ["ros2 interface show tutorial_interfaces/msg/MsgTutorial", "ros2 node list", "ros2 topic list -t"]


def shown_commands(notebook: str) -> list[str]:
    """The `!` lines of the code cells and the lines of the ```bash blocks, in order; repeats get #2, #3..."""
    commands = []
    for cell in json.loads((NOTEBOOKS / notebook).read_text())["cells"]:
        source = "".join(cell["source"])
        if cell["cell_type"] == "code":
            commands += [line.strip()[1:] for line in source.splitlines() if line.strip().startswith("!")]
        else:
            for block in re.findall(r"```bash\n(.*?)```", source, re.S):
                commands += [line.strip() for line in block.splitlines() if line.strip()]
    numbered, seen = [], {}
    for command in commands:
        seen[command] = seen.get(command, 0) + 1
        numbered.append(command if seen[command] == 1 else f"{command}#{seen[command]}")
    return numbered


def run_shell(command: str, ws: Path, env: dict) -> str:
    line = command.split("#")[0].replace("{WS}", str(ws))
    done = subprocess.run(["bash", "-c", line], env=env, capture_output=True, text=True, timeout=120,
                          stdin=subprocess.DEVNULL)
    assert done.returncode == 0, f"{line}\n{done.stdout}\n{done.stderr}"
    return done.stdout + done.stderr  # what the terminal shows (ros2 param set prints a refusal to stderr)


def run_in_notebook(command: str, ws: Path, env: dict) -> tuple[str, int]:
    """(output, exit code) of `!command` in a notebook: IPython runs it with pexpect, in a
    pseudo-terminal, so the program sees a terminal; stdout and stderr arrive as one."""
    line = command.split("#")[0].replace("{WS}", str(ws))
    child = pexpect.spawn("bash", ["-c", line], env=env, timeout=120, encoding="utf-8", codec_errors="replace")
    output = child.read()
    child.close()
    return output.replace("\r\n", "\n"), child.exitstatus


def run_together(commands, ws: Path, env: dict) -> dict[str, str]:
    """{command: output} of commands started at once (most of a `ros2` command's time is waiting for
    discovery, so side by side they take little longer than one)."""
    running = {command: subprocess.Popen(["bash", "-c", command.split("#")[0].replace("{WS}", str(ws))], env=env,
                                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                         stdin=subprocess.DEVNULL) for command in commands}
    outputs = {}
    for command, process in running.items():
        outputs[command], _ = process.communicate(timeout=120)
        assert process.returncode == 0, f"{command}\n{outputs[command]}"
    return outputs


def check(command: str, output: str, commands: dict = COMMANDS_02B) -> None:
    pattern = commands[command]
    assert re.search(pattern, output, re.M), f"`{command}` printed:\n{output}"


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """The lesson's workspace built by the lesson's own commands and files: (ws, sourced environment)."""
    root = tmp_path_factory.mktemp("lesson02b")
    ws = root / "packages_ws"
    (ws / "src").mkdir(parents=True)
    env = dict(os.environ)
    files = lesson_answers.lesson_files(LESSON)
    outputs = {}
    for command in shown_commands(LESSON)[:4]:
        if command in (BUILD_02B, BUILD_02):
            for path, text in files.items():  # the %%writefile cells ran before the build
                (root / path).parent.mkdir(parents=True, exist_ok=True)
                (root / path).write_text(text)
            outputs[command], code = run_in_notebook(command, ws, env)
            assert code == 0, outputs[command]
            continue
        outputs[command] = run_shell(command, ws, env)
    # Lesson 02's exercise: the package brightness, in the same workspace, with a right answer.
    files = lesson_answers.lesson_files(LESSON_02)
    files["brightness_ws/src/brightness/brightness/brightness_node.py"] = lesson_answers.brightness_node()
    files["brightness_ws/src/brightness/setup.py"] = lesson_answers.brightness_setup(
        files["brightness_ws/src/brightness/setup.py"])
    for command in shown_commands(LESSON_02)[1:5]:
        if command in (BUILD_02B, BUILD_02):
            for path, text in files.items():
                (ws / Path(path).relative_to("brightness_ws")).write_text(text)
            outputs[command], code = run_in_notebook(command, ws, env)
            assert code == 0, outputs[command]
            continue
        if command.startswith("ros2 pkg executables"):
            env = workspace.workspace_environment(ws)
        outputs[command] = run_shell(command, ws, env)
    return ws, workspace.workspace_environment(ws), outputs


def test_every_command_shown_is_checked():
    assert shown_commands(LESSON) == list(COMMANDS_02B)
    assert shown_commands(LESSON_00) == list(COMMANDS_00)
    assert shown_commands(LESSON_01) == list(COMMANDS_01)
    assert shown_commands("01b_custom_messages.ipynb") == UNCHECKED_01B
    assert shown_commands(LESSON_02) == list(COMMANDS_02)
    assert shown_commands("03_aruco_and_homography.ipynb") == []
    # Lesson 05 runs its two commands itself, on the bag it has just recorded (a lesson run checks them).
    assert shown_commands("05_recording_and_replaying.ipynb") == ["ls {BAG}", "ros2 bag info {BAG}"]


@pytest.mark.slow
def test_create_and_build_commands(built):
    ws, env, outputs = built
    for command, output in outputs.items():
        check(command, output, COMMANDS_02B if command in COMMANDS_02B else COMMANDS_02)
    command = "ros2 pkg executables image_stats"
    check(command, run_shell(command, ws, env))


@pytest.mark.slow
def test_build_cell_ends_with_a_setup_py_syntax_error(tmp_path):
    """Lesson 02's build cell on a setup.py that lacks a comma ends with Python's words for it and
    names colcon's log (colcon's own output ends with its traceback and the command it ran)."""
    ws = tmp_path / "brightness_ws"
    pkg_create.create_package(ws, "brightness", dependencies=["rclpy", "sensor_msgs", "std_msgs"])
    setup = ws / "src/brightness/setup.py"
    setup.write_text(setup.read_text().replace("zip_safe=True,", "zip_safe=True"))
    output, code = run_in_notebook(BUILD_02, ws, dict(os.environ))
    assert code != 0, output
    assert output.rstrip().splitlines()[-1] == "SyntaxError: invalid syntax. Perhaps you forgot a comma?", output
    assert "Failed   <<< brightness" in output and "Traceback" not in output, output
    assert str(colcon.package_log_path(ws, "brightness")) in output, output


def start(command: str, env: dict) -> processes.NodeProcess:
    return processes.NodeProcess(["bash", "-c", f"exec {command}"], name="-".join(command.split()[1:4]),
                                 env=env).start()


@pytest.mark.slow
def test_ros2_run_with_remapping_and_topic_echo(built):
    """Lesson 02b's nodes, and lesson 02's brightness node on the same camera."""
    ws, env, _ = built
    camera = start("ros2 run image_stats camera --ros-args -r image:=/camera/image_raw -p rate:=10.0", env)
    node = start("ros2 run image_stats dark_fraction --ros-args -r /image:=/camera/image_raw", env)
    brightness = start(next(c for c in COMMANDS_02 if c.startswith("ros2 run")), env)
    try:
        node.wait_for_node("dark_fraction", timeout=30)
        camera.wait_for_node("image_publisher", timeout=30)
        brightness.wait_for_node("brightness_node", timeout=30)
        outputs = run_together(["ros2 topic list -t", "ros2 topic echo /dark_fraction --once",
                                "ros2 topic echo /brightness --once", "ros2 topic info -v /brightness"], ws, env)
        for command, output in outputs.items():
            check(command, output, COMMANDS_02B if command in COMMANDS_02B else COMMANDS_02)
    finally:
        processes.stop_together([camera, node, brightness])


@pytest.mark.slow
def test_launch_file_and_parameter_commands(built):
    ws, env, _ = built
    check("ros2 launch image_stats dark.launch.xml --show-args",
          run_shell("ros2 launch image_stats dark.launch.xml --show-args", ws, env))
    demo = start("ros2 launch image_stats dark.launch.xml", env)
    try:
        demo.wait_for_node("dark_fraction", timeout=30)
        for command in list(COMMANDS_02B)[11:]:
            check(command, run_shell(command, ws, env))
    finally:
        demo.stop()
    log = demo.log
    assert "[dark_fraction-2]" in log and "now counting pixels darker than 100" in log, log


@pytest.mark.slow
def test_lesson_00_commands(tmp_path):
    """The lesson's package built as the lesson builds it, its node running: the ! lines print what it shows."""
    ws = tmp_path / "ros2_ws"
    pkg_create.create_package(ws, "my_package", dependencies=["rclpy"], node_name="my_node")
    node_file = "ros2_ws/src/my_package/my_package/my_node.py"
    (ws / "src/my_package/my_package/my_node.py").write_text(lesson_answers.lesson_files(LESSON_00)[node_file])
    colcon.build(ws, ["my_package"])
    env = workspace.workspace_environment(ws)
    node = workspace.run(ws, "my_package", "my_node")
    try:
        node.wait_for_node("my_node", timeout=30)
        for command, output in run_together(COMMANDS_00, ws, env).items():
            check(command, output, COMMANDS_00)
    finally:
        node.stop()


@pytest.mark.slow
def test_lesson_01_commands(tmp_path):
    """The lesson's talker (its own file, as a process) and a listener in this process, as in the
    notebook: the ! lines print what the lesson shows."""
    from rclpy.node import Node
    from std_msgs.msg import String

    (tmp_path / "talker.py").write_text(lesson_answers.lesson_files(LESSON_01)["nodes_01/talker.py"])
    talker = processes.python_node("talker:main", name="talker", cwd=tmp_path)
    session.start()
    try:
        heard = []
        listener = session.add_node(Node("listener"))
        listener.create_subscription(String, "chatter", heard.append, 10)
        session.wait_for(lambda: heard, timeout=30)  # as the lesson: the listener has heard the talker
        env = rosenv.ros_environment()
        # Another process learns the listener's name from this process's graph message, which on a
        # busy machine can come after the listener has heard (a clean clone's run listed /talker
        # alone): the lesson's commands run once another process lists it.
        assert wait_until(lambda: "/listener\n" in run_together(["ros2 node list"], tmp_path, env)["ros2 node list"])
        for command, output in run_together(COMMANDS_01, tmp_path, env).items():
            check(command, output, COMMANDS_01)
    finally:
        session.stop()
        talker.stop()
