"""What the lessons state and teach agrees with the code and the assignments' contracts.

(nbmake runs every lesson top to bottom; these tests check single facts of them, fast.)
"""

import ast
import re
from itertools import pairwise
from pathlib import Path

import nbformat
import numpy as np
from rclpy.qos import ReliabilityPolicy

from course_lib import contract
from course_lib.checks import assignments
from course_lib.imaging import scenes
from course_lib.ros import session

NOTEBOOKS = contract.ROOT / "notebooks"
LESSON_02 = NOTEBOOKS / "02_images_and_brightness.ipynb"
LESSON_04 = NOTEBOOKS / "04_services_and_actions.ipynb"
LESSON_05 = NOTEBOOKS / "05_recording_and_replaying.ipynb"
LESSON_06 = NOTEBOOKS / "06_mobile_robot.ipynb"


def _cells(path: Path, kind: str) -> list[str]:
    return [cell.source for cell in nbformat.read(path, as_version=4).cells if cell.cell_type == kind]


def _python(source: str) -> str:
    """A code cell as Python: IPython's ! and % lines are no Python, and a `pass` in their place keeps
    an `if` around them valid."""
    return "\n".join(line[:len(line) - len(line.lstrip())] + "pass" if line.lstrip().startswith(("%", "!"))
                     else line for line in source.splitlines())


def _classes_and_functions(sources: list[str]) -> str:
    """The class and function definitions of these cells (without the cells' other statements)."""
    kept = []
    for source in sources:
        if source.startswith("%%writefile"):  # a file of a package, not the notebook's code
            continue
        source = _python(source)
        tree = ast.parse(source)
        kept += [ast.get_source_segment(source, node) for node in tree.body
                 if isinstance(node, (ast.ClassDef, ast.FunctionDef, ast.Import, ast.ImportFrom))]
    return "\n\n".join(kept)


def test_lesson_02_publishes_brightness_with_the_sensor_data_qos_as_the_assignment_asks(domain_id):
    """A student who copies lesson 02's meter into the brightness assignment keeps the publisher
    QoS points: both meters publish (and subscribe) best effort, the sensor-data QoS."""
    session.start(domain_id=domain_id)
    try:
        space: dict = {}
        exec(_classes_and_functions(_cells(LESSON_02, "code")), space)  # noqa: S102 (the lesson's own code)
        space["should_publish"] = lambda *args: True
        for meter in (space["BrightnessMeter"](), space["ChangeMeter"]()):
            publisher = next(p for p in meter.publishers if p.topic_name.startswith("/brightness"))
            assert publisher.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT, meter.get_name()
            assert all(s.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT for s in meter.subscriptions)
            meter.destroy_node()
    finally:
        session.stop()


def test_lesson_02_states_the_light_period_of_its_camera():
    """'about 21 s for this camera, seed 0' is the period of the virtual camera's light."""
    text = "\n".join(_cells(LESSON_02, "markdown"))
    stated = int(re.search(r"about (\d+) s for this camera, seed 0", text).group(1))
    _, period, _ = scenes.CameraPath(seed=0)._waves["gain"]
    assert stated == round(period)
    low, high = map(int, re.search(r"period of (\d+) to (\d+) seconds", text).groups())
    assert low <= period <= high


def test_every_lesson_ends_with_a_summary_that_links_the_next_lesson_and_names_its_assignment():
    lessons = sorted(NOTEBOOKS.glob("*.ipynb"))
    for lesson, following in zip(lessons, lessons[1:] + [None], strict=True):
        last = _cells(lesson, "markdown")[-1]
        assert last.startswith("## Summary"), lesson.name
        if following is not None:
            assert f"]({following.name})" in last, f"{lesson.name} does not link {following.name}"
        else:
            assert "the last lesson" in last, lesson.name
        names = "|".join(assignments.ASSIGNMENTS)
        assert re.search(rf"[*`]({names})[*`]|has none", last), f"{lesson.name} names no assignment"


def test_lesson_02_exercise_uses_the_names_its_self_check_and_the_brightness_assignment_use():
    """Package brightness, executable brightness_node, started on a remapped /image, echoing /brightness."""
    from course_lib import selfcheck

    package, executable = selfcheck.BRIGHTNESS_PACKAGE, selfcheck.BRIGHTNESS_EXECUTABLE
    code = "\n".join(_cells(LESSON_02, "code"))
    assert f"%%writefile brightness_ws/src/{package}/{package}/{executable}.py" in code
    assert f"%%writefile brightness_ws/src/{package}/setup.py" in code
    assert (f"ros2 pkg create --build-type ament_python {package} --dependencies rclpy sensor_msgs std_msgs"
            in code)
    assert f'["ros2", "run", "{package}", "{executable}",\n' in code
    assert '"--ros-args", "-r", "/image:=/camera/image_raw"]' in code
    assert "!ros2 topic echo /brightness --once" in code
    text = "\n".join(_cells(LESSON_02, "markdown"))
    assert f"ros2 run {package} {executable} --ros-args -r /image:=/camera/image_raw" in text


def test_no_lesson_prints_a_count_times_a_number_that_reads_as_hexadecimal():
    """f"turned {k}x90°" prints "turned 0x90°" for k = 0, which reads as a hexadecimal number: a
    lesson writes the product (0°, 90°) or words instead."""
    for lesson in sorted(NOTEBOOKS.glob("*.ipynb")):
        for source in _cells(lesson, "code"):
            if source.startswith("%%writefile"):
                continue
            for node in ast.walk(ast.parse(_python(source))):
                if isinstance(node, ast.JoinedStr):
                    for value, text in pairwise(node.values):
                        assert not (isinstance(value, ast.FormattedValue) and isinstance(text, ast.Constant)
                                    and re.match(r"x\d", text.value)), f"{lesson.name}: {ast.unparse(node)}"


def test_lesson_02_says_truly_where_the_brightness_assignment_starts():
    """The assignment does not start from the lesson's files: its notebook, which is handed in and
    graded, writes the same package into its own workspace ros2_ws. The lesson says so, and says to
    copy the node there, instead of "the assignment continues from this very package"."""
    from course_lib import selfcheck

    package, executable = selfcheck.BRIGHTNESS_PACKAGE, selfcheck.BRIGHTNESS_EXECUTABLE
    assignment = "\n".join(_cells(NOTEBOOKS.parent / "assignments/source/brightness/brightness.ipynb", "code"))
    assert f"%%writefile ros2_ws/src/{package}/{package}/{executable}.py" in assignment
    text = " ".join("\n".join(_cells(LESSON_02, "markdown")).split())
    for claim in ("continues from this very package", "you start from this package", "continues from your"):
        assert claim not in text
    assert "in a workspace of its own (`ros2_ws`, next to the assignment's notebook)" in text
    assert "Copy your `BrightnessNode` into the node file's cell there" in text


def test_every_lesson_ends_with_its_quiz_and_an_answer_cell_for_each_question():
    """Each lesson has a short quiz (course_lib.selfcheck.lesson_quiz) before its clean-up: the
    questions shown, then a blank answer per question and the check."""
    from course_lib.selfcheck.lesson_quiz import quiz_of

    for lesson in sorted(NOTEBOOKS.glob("*.ipynb")):
        key = lesson.name.split("_", 1)[0]
        code = _cells(lesson, "code")
        assert f'selfcheck.show_quiz("{key}")' in code, lesson.name
        blank = "{" + ", ".join(f'{number}: ""' for number in range(1, len(quiz_of(key)) + 1)) + "}"
        assert f'quiz = {blank}\nselfcheck.check_quiz("{key}", quiz)' in code, lesson.name


def test_lesson_04_defines_the_interfaces_the_services_actions_assignment_gives():
    """The .srv and .action lesson 04 builds are the reference camera_interfaces, word for word:
    the assignment's contract is what the lesson taught."""
    reference = contract.ROOT / "assignments" / "reference_ws" / "src" / "camera_interfaces"
    code = "\n".join(_cells(LESSON_04, "code"))
    for name, path in (("MARKERS_IN_VIEW", "srv/MarkersInView.srv"), ("FIND_PICTURES", "action/FindPictures.action")):
        assert f'{name} = """{(reference / path).read_text()}"""' in code, path


def test_lesson_04_pan_camera_figure_titles_stay_apart():
    """Lesson 04's three views of the pan camera: each title (the markers, the pictures framed, what
    ArUco finds) fits beside its neighbours as matplotlib lays the figure out for the notebook. In
    the walkthrough in Chromium the -10 degree title's "framed ['cat', 'dog']" ran into "pan 0:"."""
    import cv2
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from course_lib.imaging import pan_camera

    (source,) = [s for s in _cells(LESSON_04, "code") if "ax.set_title(" in s and "pan_camera.frame_at" in s]
    exec(source, {"cv2": cv2, "plt": plt, "pan_camera": pan_camera})
    figure = plt.gcf()
    try:
        figure.canvas.draw()
        boxes = [ax.title.get_window_extent(figure.canvas.get_renderer()) for ax in figure.axes]
        assert len(boxes) == 3
        gaps = [right.x0 - left.x1 for left, right in pairwise(boxes)]
        assert min(gaps) > 5, f"the titles overlap or touch: gaps {gaps} pixels"
    finally:
        plt.close(figure)


def test_lesson_05_says_no_fixed_order_of_the_recorders_subscriptions():
    """Lesson 05's text before its last plot explains why the topics start apart without saying
    which the recorder subscribed first: discovery decides (in the walkthrough in Chromium the plot's
    title said "frames recorded from 0.69 s, /brightness from 0.00 s" under text that said
    /brightness came after the frames)."""
    (text,) = [s for s in _cells(LESSON_05, "markdown") if "plot the frames' own brightness" in s]
    flat = " ".join(text.split())
    assert "in the order discovery found them" in flat and "after the frames" not in flat


def test_lesson_06_drives_its_plain_functions_to_the_pillar_for_other_seeds_too():
    """Lesson 06's pillar_in_scan and p_controller, in the plain simulation as its drive_in_simulation
    runs them: within the lesson's 20 simulated seconds the front of the robot (0.495 m ahead of
    base_link) stops about half a metre from the pillar, as the lesson says, never touching it, for
    the lesson's seed and for pillars far off to either side; its PILLAR_RADIUS is the world's."""
    import math

    from course_lib.robot.simulation import Simulation, pillar_position

    code = "\n".join(_cells(LESSON_06, "code"))
    constants = {name: float(re.search(rf"^{name} = ([\d.]+)", code, re.M).group(1))
                 for name in ("SEED", "PILLAR_RADIUS", "SCAN_RATE", "DRIVE_SECONDS")}
    assert constants["PILLAR_RADIUS"] == Simulation("pillar").pillar_radius
    space: dict = dict(constants)
    exec(_classes_and_functions(_cells(LESSON_06, "code")), space)  # noqa: S102 (the lesson's own code)
    for seed in (int(constants["SEED"]), 7, 10):
        sim, path = space["drive_in_simulation"](seed, constants["DRIVE_SECONDS"])
        x, y, _ = sim.pose()
        px, py = pillar_position(seed)
        front_gap = math.hypot(px - x, py - y) - constants["PILLAR_RADIUS"] - 0.495
        assert 0.4 < front_gap < 0.55, (seed, front_gap)
        assert len(path) == constants["DRIVE_SECONDS"] * constants["SCAN_RATE"] + 1
        assert not sim.touching() and float(np.hypot(*np.diff(path[-5:], axis=0).T).max()) < 1e-3, seed
