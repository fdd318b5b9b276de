"""Tests for course_lib.selfcheck: stubs get 'not done yet', wrong answers a specific hint."""

import re

import lesson_answers
import pytest
from rclpy.node import Node
from std_msgs.msg import Header, Int32, String

from course_lib import colcon, discovery, pkg_create, selfcheck, session


@pytest.fixture
def my_node(monkeypatch):
    monkeypatch.setattr(discovery, "SETTLE_SECONDS", 0)  # in-process nodes need no discovery wait
    session.start()
    node = session.add_node(Node("my_node"))
    yield node
    session.stop()


@pytest.mark.parametrize("stub", [None, ..., "...", ""])
def test_task1_stub_is_not_done_yet(stub):
    verdict = selfcheck.task1_node_name(stub)
    assert not verdict and "Not done yet" in str(verdict) and "graph.node_list()" in str(verdict)


def test_task1_accepts_the_listed_name(my_node):
    verdict = selfcheck.task1_node_name("/my_node")
    assert verdict and str(verdict).startswith("✔")


def test_task1_missing_slash_gets_the_namespace_hint(my_node):
    verdict = selfcheck.task1_node_name("my_node")
    assert not verdict and "Write '/my_node'" in str(verdict)


def test_task1_someone_elses_node(my_node):
    session.add_node(Node("other"))
    verdict = selfcheck.task1_node_name("/other")
    assert not verdict and "not yours" in str(verdict)


def test_task1_node_not_running(monkeypatch):
    monkeypatch.setattr(discovery, "SETTLE_SECONDS", 0)
    session.start()
    try:
        verdict = selfcheck.task1_node_name("/my_node")
    finally:
        session.stop()
    assert not verdict and "is it still running?" in str(verdict)


def test_task2_verdicts():
    assert "Not done yet" in str(selfcheck.task2_echo(None))
    assert "Nothing was echoed" in str(selfcheck.task2_echo([]))
    assert "carries std_msgs/msg/String" in str(selfcheck.task2_echo([Int32(data=3)]))
    assert "which the talker did not send" in str(selfcheck.task2_echo([String(data="hi")]))
    assert selfcheck.task2_echo([String(data="Hello World: 7")])
    assert selfcheck.task2_echo(String(data="Hello World: 7")), "a single message (not a list) is fine too"


def test_task2_stub_hint_does_not_give_the_answer_away():
    """The hint points at how to find the topic, not at the finished call."""
    hint = str(selfcheck.task2_echo(None))
    assert "topic_list()" in hint and "/chatter" not in hint and "topic_echo(" not in hint


def test_task2_what_the_listener_heard_is_not_an_echo():
    """listener.heard[0] is the right topic's text but the wrong object: the verdict says so."""
    verdict = selfcheck.task2_echo("Hello World: 3")
    assert not verdict and "not a ROS message" in str(verdict) and "listener.heard" in str(verdict)
    assert "right topic" not in str(verdict)


# --- Task 3 (lesson 02): publish brightness only when it changes by more than a threshold -----

def _publish_on_change(last_sent, current, threshold):
    return last_sent is None or abs(int(current) - int(last_sent)) > threshold


@pytest.mark.parametrize("stub", [None, lambda last, current, threshold: None])
def test_task3_stub_is_not_done_yet(stub):
    verdict = selfcheck.task3_brightness_on_change(stub)
    assert not verdict and "Not done yet" in str(verdict)


def test_task3_accepts_a_correct_filter():
    assert selfcheck.task3_brightness_on_change(_publish_on_change)


@pytest.mark.parametrize("wrong, named", [
    (lambda last, current, threshold: abs(int(current) - int(last)) > threshold, "last_sent is None"),
    (lambda last, current, threshold: last is None or int(current) - int(last) > threshold, "a drop of 6 counts too"),
    (lambda last, current, threshold: last is None or abs(int(current) - int(last)) >= threshold, "use >, not >="),
    (lambda last, current, threshold: last is None or abs(current - last) > threshold, "uint8 arithmetic wraps"),
    (lambda last, current, threshold: 1 / 0, "raised ZeroDivisionError"),
    (lambda last, current, threshold: not last or abs(int(current) - int(last)) > threshold, "not `not last_sent`"),
])
def test_task3_names_what_is_wrong(wrong, named):
    verdict = selfcheck.task3_brightness_on_change(wrong)
    assert not verdict and named in str(verdict)


# --- Task 4 (lesson 03): order four shuffled corners ------------------------------------------

def _order_by_angle(points):
    import numpy as np

    points = np.asarray(points, dtype=float)
    centre = points.mean(axis=0)
    points = points[np.argsort(np.arctan2(points[:, 1] - centre[1], points[:, 0] - centre[0]))]
    return np.roll(points, -int(np.argmin(points.sum(axis=1))), axis=0)


def _sum_and_difference(points):
    """The well-known shortcut: top-left has the smallest x + y, top-right the smallest y - x, ..."""
    import numpy as np

    points = np.asarray(points, dtype=float)
    total, difference = points.sum(axis=1), points[:, 1] - points[:, 0]
    return points[[total.argmin(), difference.argmin(), total.argmax(), difference.argmax()]]


def test_task4_stub_and_correct_answer():
    assert "Not done yet" in str(selfcheck.task4_order_corners(None))
    assert "Not done yet" in str(selfcheck.task4_order_corners(lambda points: None))
    assert selfcheck.task4_order_corners(_order_by_angle)


@pytest.mark.parametrize("wrong, named", [
    (lambda p: _order_by_angle(p)[[0, 3, 2, 1]], "anticlockwise"),
    (lambda p: __import__("numpy").roll(_order_by_angle(p), 1, axis=0), "starts at the bottom-left"),
    (lambda p: _order_by_angle(p) * 2, "not the four points it was given"),
    (lambda p: [1, 2, 3], "numpy array of shape (4, 2)"),
    (lambda p: [tuple(corner) for corner in _order_by_angle(p)], "numpy array of shape (4, 2)"),
    (lambda p: _sum_and_difference(p), "picks one point twice"),
])
def test_task4_names_what_is_wrong(wrong, named):
    verdict = selfcheck.task4_order_corners(wrong)
    assert not verdict and named in str(verdict)


def test_task4_catches_taking_the_two_highest_points_as_the_top():
    import numpy as np

    def two_highest_are_top(points):
        points = np.asarray(points)
        by_y = points[np.argsort(points[:, 1])]
        top, bottom = by_y[:2][np.argsort(by_y[:2, 0])], by_y[2:][np.argsort(by_y[2:, 0])]
        return np.array([top[0], top[1], bottom[1], bottom[0]])

    verdict = selfcheck.task4_order_corners(two_highest_are_top)
    assert not verdict and "long rectangle tilted by 30 degrees" in str(verdict)


# --- the exercises of lessons 01 (a publisher) and 01b (the MsgTutorial subscriber) -----------

def _announcer(period=0.5, topic="announcements", text="Announcement {}", msg_type=None, timer=True, depth=10,
               publish=True):
    """A publisher node class for the lesson 01 exercise, right by default, wrong as asked."""
    from std_msgs.msg import String

    class Announcer(Node):
        def __init__(self):
            super().__init__("announcer")
            self.count = 0
            self.publisher = self.create_publisher(msg_type or String, topic, depth)
            if timer:
                self.create_timer(period, self.announce)

        def announce(self):
            if publish:
                self.publisher.publish(String(data=text.format(self.count)))
            self.count += 1

    return Announcer


class AnnouncerStub(Node):
    def __init__(self):
        super().__init__("announcer")
        self.count = 0
        # TODO: a publisher and a timer


@pytest.fixture
def exercise_session(domain_id, monkeypatch):
    monkeypatch.setattr(discovery, "SETTLE_SECONDS", 0)
    session.start(domain_id=domain_id)
    yield
    session.stop()


def test_publisher_exercise_passes_a_correct_node(exercise_session):
    verdict = selfcheck.publisher_exercise(_announcer())
    assert verdict, verdict
    assert session.nodes() == []  # the check removes the node it ran


@pytest.mark.parametrize("answer, named", [
    (None, "Not done yet"),
    (AnnouncerStub, "Not done yet: the node has no publisher"),
    (_announcer(topic="announcement"), "not on /announcements"),
    (_announcer(timer=False), "Not done yet: the node has no timer"),
    (_announcer(publish=False), "but no message arrived on /announcements after"),
    (_announcer(text="Announcement"), "'Announcement 0', then"),
    (_announcer(period=0.1), "every 0.1 s; the exercise asks for every 0.5 s"),
    (_announcer(depth=1), "queue depth 1; the exercise asks for 10"),
])
def test_publisher_exercise_names_what_is_wrong(exercise_session, answer, named):
    verdict = selfcheck.publisher_exercise(answer)
    assert not verdict and named in str(verdict), verdict


#: A call written out with its arguments, as in "self.create_publisher(String, 'announcements', 10)".
CALL_WITH_ARGUMENTS = re.compile(r"\w+\([^()]*,[^()]*\)")


@pytest.mark.parametrize("stub, named", [
    (AnnouncerStub, "no publisher"),
    (_announcer(timer=False), "no timer"),
])
def test_publisher_exercise_stub_hints_say_what_to_do_without_the_line_to_write(exercise_session, stub, named):
    text = str(selfcheck.publisher_exercise(stub))
    assert "Not done yet" in text and named in text and not CALL_WITH_ARGUMENTS.search(text), text


@pytest.mark.parametrize("period", [2.0, 5.0])
def test_publisher_exercise_judges_the_timer_period_the_node_has(exercise_session, period):
    """A slow timer fails by its period, read from the node's timer (not from how many messages came
    in a moment): a 2 s timer does not pass as "every 0.5 s", a 5 s one is not "no timer"."""
    verdict = selfcheck.publisher_exercise(_announcer(period=period))
    assert not verdict and f"every {period:g} s; the exercise asks for every 0.5 s" in str(verdict), verdict
    assert "create a timer" not in str(verdict)


def _tutorial_listener(keep, topic="ros_tutorial_msg", msg_type=Header, depth=100):
    class TutorialListener(Node):
        def __init__(self):
            super().__init__("tutorial_listener")
            self.received = []
            self.create_subscription(msg_type, topic, self.on_message, depth)

        def on_message(self, msg):
            self.received.append(keep(msg))

    return TutorialListener


def _stamp(msg):
    return msg.stamp.sec + msg.stamp.nanosec * 1e-9


class ListenerStub(Node):
    def __init__(self):
        super().__init__("tutorial_listener")
        self.received = []


@pytest.mark.parametrize("answer, named", [
    (_tutorial_listener(lambda msg: (_stamp(msg), int(msg.frame_id))), None),
    (None, "Not done yet"),
    (ListenerStub, "Not done yet: the node has no subscription"),
    (_tutorial_listener(lambda msg: (msg.stamp.sec, int(msg.frame_id))), "lost its nanoseconds"),
    (_tutorial_listener(lambda msg: (int(msg.frame_id), _stamp(msg))), "(stamp, data), not (data, stamp)"),
    (_tutorial_listener(lambda msg: (_stamp(msg), int(msg.frame_id)), topic="chatter"), "not to /ros_tutorial_msg"),
    (_tutorial_listener(lambda msg: (_stamp(msg), 0)), "has none of them"),
    (_tutorial_listener(lambda msg: (_stamp(msg), int(msg.frame_id)), depth=10),
     "queue depth 10; the exercise asks for 100"),
])
def test_subscriber_exercise(exercise_session, answer, named):
    """Header stands in for MsgTutorial (its counter in frame_id), as in lesson 01b without a build."""
    verdict = selfcheck.subscriber_exercise(answer, Header)
    if named is None:
        assert verdict, verdict
    else:
        assert not verdict and named in str(verdict), verdict


def test_subscriber_exercise_stub_hint_says_what_to_do_without_the_line_to_write(exercise_session):
    text = str(selfcheck.subscriber_exercise(ListenerStub, Header))
    assert "Not done yet" in text and not CALL_WITH_ARGUMENTS.search(text), text


def test_subscriber_exercise_with_a_data_field(exercise_session):
    """With a message that has a data field (as MsgTutorial has), data is the counter."""
    from builtin_interfaces.msg import Time  # noqa: F401 (Header's stamp type)
    from std_msgs.msg import Int32

    wrong_type = _tutorial_listener(lambda msg: (_stamp(msg), msg.data), msg_type=Int32)
    assert "sends std_msgs/msg/Header" in str(selfcheck.subscriber_exercise(wrong_type, Header))


# ---- lesson 02b: the launch file in YAML ------------------------------------------------------

def lesson_file(notebook: str, relative: str) -> str:
    """The text a lesson's %%writefile cell writes to a path ending in `relative`."""
    import json
    from pathlib import Path

    cells = json.loads((Path(__file__).resolve().parents[1] / "notebooks" / notebook).read_text())["cells"]
    for cell in cells:
        source = "".join(cell["source"])
        first, _, body = source.partition("\n")
        if first.startswith("%%writefile") and first.endswith(relative):
            return body
    raise LookupError(f"{notebook} writes no {relative}")


LAUNCH_NODE = """\
- node:
    pkg: image_stats
    exec: {}
    output: screen
    param:
    - {{from: $(find-pkg-share image_stats)/config/dark_fraction.yaml}}
    remap:
    - {{from: image, to: /camera/image_raw}}
"""
LAUNCH_YAML = "launch:\n" + LAUNCH_NODE.format("camera") + LAUNCH_NODE.format("dark_fraction")


@pytest.fixture
def image_stats_launch(tmp_path, monkeypatch):
    """The lesson's XML launch file, and image_stats installed (ament index, executables, share files)."""
    import os

    from launch_demo import make_prefix

    prefix = make_prefix(tmp_path / "install", "image_stats", {"camera": "#!/bin/sh\n", "dark_fraction": "#!/bin/sh\n"},
                         {"config/dark_fraction.yaml": lesson_file("02b_packages_launch_parameters.ipynb",
                                                                   "config/dark_fraction.yaml")})
    monkeypatch.setenv("AMENT_PREFIX_PATH", f"{prefix}{os.pathsep}{os.environ.get('AMENT_PREFIX_PATH', '')}")
    xml = tmp_path / "dark.launch.xml"
    xml.write_text(lesson_file("02b_packages_launch_parameters.ipynb", "launch/dark.launch.xml"))
    return xml


@pytest.mark.parametrize("answer, expected", [
    (lesson_file("02b_packages_launch_parameters.ipynb", "launch/dark.launch.yaml"), "Not done yet"),
    (LAUNCH_YAML.replace("    remap:\n    - {from: image, to: /camera/image_raw}\n", "", 1),
     "remaps are none, the XML file gives image:=/camera/image_raw"),
    (LAUNCH_YAML.replace("    output: screen\n", "", 1), "output is 'log'"),
    (LAUNCH_YAML.replace("exec: dark_fraction", "exec: camera"), "Node 2 runs image_stats/camera"),
    (LAUNCH_YAML.replace("remap:\n    - {from", "remap:\n      {from"), "cannot run"),
    (LAUNCH_YAML, "✔"),
])
def test_launch_yaml_check_fails_the_stub_and_wrong_files_and_passes_the_xml_twin(image_stats_launch, tmp_path,
                                                                                   answer, expected):
    yaml_file = tmp_path / "dark.launch.yaml"
    yaml_file.write_text(answer)
    verdict = selfcheck.task_launch_yaml(yaml_file, image_stats_launch)
    assert bool(verdict) == (expected == "✔") and expected in str(verdict), str(verdict)


SHARED_PARAMS = "$(find-pkg-share image_stats)/config/dark_fraction.yaml"


@pytest.mark.parametrize("given, expected", [
    ("config/dark_fraction.yaml", "parameter files are {cwd}/config/dark_fraction.yaml, the XML file gives "
                                  f"{SHARED_PARAMS}: $(find-pkg-share) finds the installed file"),
    ("dark_fraction.yaml", f"names the parameter file {{cwd}}/dark_fraction.yaml, which is no file (ros2 launch "
                           f"warns and starts the node without it). The XML file names {SHARED_PARAMS}"),
])
def test_launch_yaml_check_names_a_relative_parameter_file_and_find_pkg_share(image_stats_launch, tmp_path,
                                                                               monkeypatch, given, expected):
    """A relative path is relative to the folder ros2 launch runs in: the verdict names the file it
    found (or did not find) and the XML file's $(find-pkg-share ...), not parameter files' YAML."""
    cwd = tmp_path / "notebooks"
    (cwd / "config").mkdir(parents=True)
    (cwd / "config" / "dark_fraction.yaml").write_text(lesson_file("02b_packages_launch_parameters.ipynb",
                                                                   "config/dark_fraction.yaml"))
    monkeypatch.chdir(cwd)
    yaml_file = tmp_path / "dark.launch.yaml"
    yaml_file.write_text(LAUNCH_YAML.replace(SHARED_PARAMS, given))
    verdict = str(selfcheck.task_launch_yaml(yaml_file, image_stats_launch))
    assert expected.format(cwd=cwd) in verdict and "\\n" not in verdict and "ros__parameters" not in verdict, verdict


def test_launch_yaml_check_shows_inline_parameters_on_one_line(image_stats_launch, tmp_path):
    yaml_file = tmp_path / "dark.launch.yaml"
    yaml_file.write_text(LAUNCH_YAML.replace("    - {from: " + SHARED_PARAMS + "}", "    - {name: rate, value: 5.0}", 1))
    verdict = str(selfcheck.task_launch_yaml(yaml_file, image_stats_launch))
    assert "parameter files are parameters {/**: {ros__parameters: {rate: 5.0}}}, the XML file gives " \
           f"{SHARED_PARAMS}" in verdict and "\n" not in verdict, verdict


# ---- lesson 03: the cat/dog corner mapping ----------------------------------------------------

def corners_using(marker_corner):
    """A picture_corners_of that takes corner marker_corner[k] of the k-th marker of the picture."""
    import numpy as np

    from course_lib import marker_board

    def picture_corners_of(markers, picture):
        return np.array([markers[m][c] for m, c in zip(marker_board.PICTURES[picture], marker_corner)])
    return picture_corners_of


@pytest.mark.parametrize("answer, expected", [
    (lambda markers, picture: None, "Not done yet"),
    (corners_using((0, 0, 0, 0)), "you took corner 0 of marker 1, which does not touch the picture"),
    (lambda markers, picture: corners_using((2, 3, 0, 1))(markers, "dog" if picture == "cat" else "cat"),
     "you took a corner of marker 5; that corner lies on marker 1"),
    (lambda markers, picture: [[0, 0]] * 4, "no corner of a marker"),
    (corners_using((2, 3, 0, 1)), "✔"),
])
def test_picture_corner_check_fails_the_stub_and_wrong_corners_and_passes_the_convention(answer, expected):
    verdict = selfcheck.task_picture_corners(answer)
    assert bool(verdict) == (expected == "✔") and expected in str(verdict), str(verdict)


# ---- lesson 02: the brightness node as a package ----------------------------------------------

LESSON_02 = "02_images_and_brightness.ipynb"
ANSWER_NODE = lesson_answers.brightness_node()
SETUP_STUB = lesson_file(LESSON_02, "brightness/setup.py")


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
    (lesson_file(LESSON_02, "brightness/brightness_node.py"), SETUP_STUB, None, "Not done yet: brightness_node.py "
                                                                                "creates no subscription and no publisher"),
    (ANSWER_NODE, SETUP_STUB, None, "Not done yet: setup.py has no executable brightness_node"),
    (ANSWER_NODE, None, ("rclpy", "sensor_msgs"), "imports std_msgs (line 8), but package.xml does not declare it"),
    (ANSWER_NODE.replace("import rclpy\n", "import numpy\nimport rclpy\n"), None, None,
     "add <depend>python3-numpy</depend>"),
    (ANSWER_NODE, setup_with("brightness = brightness.brightness_node:main"), None, "needs it to be called 'brightness_node'"),
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
