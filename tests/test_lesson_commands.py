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
import re
import subprocess
from pathlib import Path

import pytest

from course_lib import colcon, pkg_create, processes, workspace

NOTEBOOKS = Path(__file__).resolve().parents[1] / "notebooks"
LESSON = "02b_packages_launch_parameters.ipynb"

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
    "cd {WS} && colcon build --symlink-install --packages-select image_stats 2>&1 | tail -n 3":
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
    "ros2 --help | head -n 12": r"^usage: ros2 ",
    "ros2 pkg executables my_package": r"^my_package my_node\n$",
    "ros2 node list": r"^/my_node$",
}


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


def lesson_files(notebook: str) -> dict[str, str]:
    """{path: text} of the lesson's %%writefile cells."""
    files = {}
    for cell in json.loads((NOTEBOOKS / notebook).read_text())["cells"]:
        first, _, body = "".join(cell["source"]).partition("\n")
        if cell["cell_type"] == "code" and first.startswith("%%writefile"):
            files[first.split(maxsplit=1)[1]] = body
    return files


def run_shell(command: str, ws: Path, env: dict) -> str:
    line = command.split("#")[0].replace("{WS}", str(ws))
    done = subprocess.run(["bash", "-c", line], env=env, capture_output=True, text=True, timeout=120,
                          stdin=subprocess.DEVNULL)
    assert done.returncode == 0, f"{line}\n{done.stdout}\n{done.stderr}"
    return done.stdout + done.stderr  # what the terminal shows (ros2 param set prints a refusal to stderr)


def check(command: str, output: str, commands: dict = COMMANDS_02B) -> None:
    pattern = commands[command]
    assert re.search(pattern, output, re.M), f"`{command}` printed:\n{output}"


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """The lesson's workspace built by the lesson's own commands and files: (ws, sourced environment)."""
    import os

    root = tmp_path_factory.mktemp("lesson02b")
    ws = root / "packages_ws"
    (ws / "src").mkdir(parents=True)
    env = dict(os.environ)
    files = lesson_files(LESSON)
    outputs = {}
    for command in shown_commands(LESSON)[:4]:
        if command.startswith("cd {WS} && colcon"):
            for path, text in files.items():  # the %%writefile cells ran before the build
                (root / path).parent.mkdir(parents=True, exist_ok=True)
                (root / path).write_text(text)
        outputs[command] = run_shell(command, ws, env)
    return ws, workspace.workspace_environment(ws), outputs


def test_every_command_shown_is_checked():
    assert shown_commands(LESSON) == list(COMMANDS_02B)
    assert shown_commands(LESSON_00) == list(COMMANDS_00)
    assert shown_commands("03_aruco_and_homography.ipynb") == []


def test_create_and_build_commands(built):
    ws, env, outputs = built
    for command, output in outputs.items():
        check(command, output)
    command = "ros2 pkg executables image_stats"
    check(command, run_shell(command, ws, env))


def start(command: str, env: dict) -> processes.NodeProcess:
    return processes.NodeProcess(["bash", "-c", f"exec {command}"], name="-".join(command.split()[1:4]), env=env).start()


def test_ros2_run_with_remapping_and_topic_echo(built):
    ws, env, _ = built
    camera = start("ros2 run image_stats camera --ros-args -r image:=/camera/image_raw -p rate:=10.0", env)
    node = start("ros2 run image_stats dark_fraction --ros-args -r /image:=/camera/image_raw", env)
    try:
        node.wait_for_node("dark_fraction", timeout=30)
        camera.wait_for_node("image_publisher", timeout=30)
        for command in ("ros2 topic list -t", "ros2 topic echo /dark_fraction --once"):
            check(command, run_shell(command, ws, env))
    finally:
        processes.stop_together([camera, node])


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


def test_lesson_00_commands(tmp_path):
    """The lesson's package built as the lesson builds it, its node running: the ! lines print what it shows."""
    ws = tmp_path / "ros2_ws"
    pkg_create.create_package(ws, "my_package", dependencies=["rclpy"], node_name="my_node")
    (ws / "src/my_package/my_package/my_node.py").write_text(lesson_files(LESSON_00)["ros2_ws/src/my_package/my_package/my_node.py"])
    colcon.build(ws, ["my_package"])
    env = workspace.workspace_environment(ws)
    node = workspace.run(ws, "my_package", "my_node")
    try:
        node.wait_for_node("my_node", timeout=30)
        for command in COMMANDS_00:
            check(command, run_shell(command, ws, env), COMMANDS_00)
    finally:
        node.stop()
