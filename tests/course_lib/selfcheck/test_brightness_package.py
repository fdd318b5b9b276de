"""Tests for course_lib.selfcheck.brightness_package: lesson 02's brightness node as a package,
built and run as ros2 run."""

import pytest
from support import lesson_answers

from course_lib import selfcheck
from course_lib.ros import colcon, pkg_create

LESSON_02 = "02_images_and_brightness.ipynb"
ANSWER_NODE = lesson_answers.brightness_node()
SETUP_STUB = lesson_answers.lesson_file(LESSON_02, "brightness/setup.py")


def setup_with(entry: str) -> str:
    """The lesson's setup.py with `entry` in place of its TODO."""
    return lesson_answers.brightness_setup(SETUP_STUB, entry)


def brightness_package(ws, node=ANSWER_NODE, setup=None, dependencies=("rclpy", "sensor_msgs", "std_msgs")):
    """The lesson's package as `ros2 pkg create` writes it, with this node file and setup.py."""
    package = pkg_create.create_package(ws, "brightness", dependencies=dependencies, exist_ok=True)
    (package / "brightness" / "brightness_node.py").write_text(node)
    (package / "setup.py").write_text(setup_with(selfcheck.BRIGHTNESS_ENTRY_POINT) if setup is None else setup)
    return package


@pytest.mark.parametrize("node, setup, dependencies, expected", [
    (None, None, None, "Not done yet: there is no package brightness"),
    (lesson_answers.lesson_file(LESSON_02, "brightness/brightness_node.py"), SETUP_STUB, None,
     "Not done yet: brightness_node.py creates no subscription and no publisher"),
    (ANSWER_NODE, SETUP_STUB, None, "Not done yet: setup.py has no executable brightness_node"),
    (ANSWER_NODE, None, ("rclpy", "sensor_msgs"), "imports std_msgs (line 8), but package.xml does not declare it"),
    (ANSWER_NODE.replace("import rclpy\n", "import numpy\nimport rclpy\n"), None, None,
     "add <depend>python3-numpy</depend>"),
    (ANSWER_NODE, setup_with("brightness = brightness.brightness_node:main"), None,
     "needs it to be called 'brightness_node'"),
    (ANSWER_NODE, setup_with("brightness_node = brightness_node:main"), None,
     "the node file's module is brightness.brightness_node"),
    (ANSWER_NODE, setup_with("brightness_node = brightness.brightness_node.main"), None, "needs a colon"),
    (ANSWER_NODE, None, None, "not built yet"),
])
def test_brightness_package_check_names_what_is_missing_before_starting_anything(tmp_path, node, setup, dependencies,
                                                                                expected):
    """The stub and wrong files fail by what the files say, without a build or a node process."""
    if node is not None:
        brightness_package(tmp_path, node, setup, dependencies or ("rclpy", "sensor_msgs", "std_msgs"))
    verdict = selfcheck.brightness_package_exercise(tmp_path)
    assert not verdict and expected in str(verdict), str(verdict)


def test_brightness_package_setup_py_stub_hint_does_not_give_the_entry_point(tmp_path):
    brightness_package(tmp_path, ANSWER_NODE, SETUP_STUB)
    text = str(selfcheck.brightness_package_exercise(tmp_path))
    assert "Not done yet" in text and "console_scripts" in text, text
    assert selfcheck.BRIGHTNESS_ENTRY_POINT not in text and "brightness.brightness_node:main" not in text, text


@pytest.fixture(scope="module")
def built_brightness(tmp_path_factory):
    """The lesson's package with the right answer, built with --symlink-install (so node files can change
    without a build)."""
    ws = tmp_path_factory.mktemp("brightness_ws")
    brightness_package(ws)
    colcon.build(ws, ["brightness"], extra_args=["--symlink-install"])
    return ws


@pytest.mark.slow
def test_brightness_package_check_wants_a_build_after_setup_py_changes_not_after_it_is_written_again(
        built_brightness):
    """Running the %%writefile cell of setup.py again writes the same text, newer: no build is due. A
    setup.py whose executables differ from those the build installed needs one."""
    import os
    import time

    setup = built_brightness / "src/brightness/setup.py"
    script = built_brightness / "install/brightness/lib/brightness/brightness_node"
    text, before = setup.read_text(), setup.stat().st_mtime
    later = (time.time() + 10, time.time() + 10)
    try:
        os.utime(setup, later)
        verdict = selfcheck.brightness_package_exercise(built_brightness)
        assert verdict, str(verdict)
        entry = f"'{selfcheck.BRIGHTNESS_ENTRY_POINT}',"
        setup.write_text(text.replace(entry, entry + "\n            'other = brightness.other:main',"))
        os.utime(setup, later)
        verdict = selfcheck.brightness_package_exercise(built_brightness)
    finally:
        setup.write_text(text)
        os.utime(setup, (before, before))
    assert not verdict and "setup.py changed after the last build: its executables are brightness_node = " \
                           "brightness.brightness_node:main, other = brightness.other:main, the build installed " \
                           "brightness_node = brightness.brightness_node:main" in str(verdict), str(verdict)
    hidden = script.with_name("hidden")
    script.rename(hidden)  # built while setup.py had no entry point
    try:
        verdict = selfcheck.brightness_package_exercise(built_brightness)
    finally:
        hidden.rename(script)
    assert not verdict and "the last build did not install it" in str(verdict), str(verdict)


@pytest.mark.slow
def test_brightness_package_check_finds_a_stale_copy_of_a_build_without_symlinks(built_brightness):
    import sys

    version = f"python{sys.version_info.major}.{sys.version_info.minor}"
    copy = built_brightness / f"install/brightness/lib/{version}/site-packages/brightness/brightness_node.py"
    copy.parent.mkdir(parents=True)
    copy.write_text(ANSWER_NODE.replace("centre_value(frame):", "centre_value(frame):  # an older version"))
    try:
        verdict = selfcheck.brightness_package_exercise(built_brightness)
    finally:
        copy.unlink()
        copy.parent.rmdir()
    assert not verdict and "built without --symlink-install" in str(verdict), str(verdict)


@pytest.mark.parametrize("change, expected", [
    ({}, "✔"),
    ({"Image, 'image'": "Image, '/camera/image_raw'"}, "still subscribes /camera/image_raw"),
    ({"int(frame[height // 2, width // 2, 0])": "frame[height // 2, width // 2, 0]"}, "wrap it in int(...)"),
    ({"frame[height // 2, width // 2, 0]": "frame[width // 2, height // 2, 0]"}, "numpy indexes [row, column]"),
    ({"import UInt8": "import Float32", "UInt8": "Float32"}, "publishes std_msgs/msg/Float32 on /brightness"),
    # Answers wrong, computes for a while, then fails: judged by its crash however long it takes to come
    # (a wait of 1 s took a crash on a busy machine for a wrong value: "published 255").
    ({"self.publisher.publish(UInt8(data=centre_value(images.msg_to_image(msg))))":
      "self.publisher.publish(UInt8(data=255)); sum(range(60_000_000)); raise ValueError('late failure')"},
     "crashed on the first frame"),
])
@pytest.mark.slow
def test_brightness_package_check_runs_the_node_as_ros2_run_would(built_brightness, change, expected):
    """With --symlink-install a changed node file runs without a build; the check sends it frames."""
    node = ANSWER_NODE
    for old, new in change.items():
        assert old in node
        node = node.replace(old, new)
    (built_brightness / "src/brightness/brightness/brightness_node.py").write_text(node)
    verdict = selfcheck.brightness_package_exercise(built_brightness)
    assert bool(verdict) == (expected == "✔") and expected in str(verdict), str(verdict)
    if verdict:
        assert "17, 201, 90" in str(verdict), "the three frames' centre values"
