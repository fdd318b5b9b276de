"""Writes the nbgrader source notebooks of the graded assignments: ``python assignments/build.py``.

The notebooks under assignments/source/ are what instructors edit in JupyterLab; this script is
how they were first made and how a test checks that their graded cells match the checks
(points of each test cell = points of its check in autograder/checks/). Solution cells hold the
reference solution between ``### BEGIN SOLUTION`` / ``### END SOLUTION`` markers, placed inside
function bodies so that nbgrader's stub (``raise NotImplementedError``) keeps the module importable.
"""

from __future__ import annotations

import sys
from pathlib import Path

import nbformat

HERE = Path(__file__).resolve().parent
SOURCE = HERE / "source"


def _meta(kind: str, grade_id: str, points: float = 0) -> dict:
    base = {"schema_version": 3, "grade_id": grade_id, "task": False}
    if kind == "solution":
        base.update(grade=False, solution=True, locked=False)
    elif kind == "test":
        base.update(grade=True, solution=False, locked=True, points=points)
    elif kind == "locked":
        base.update(grade=False, solution=False, locked=True)
    return {"nbgrader": base}


def md(text: str, grade_id: str | None = None):
    """A markdown cell; only the introduction (grade_id "intro") is locked.

    nbgrader 0.9's add_missing_cells puts a deleted test cell back after the source cell before
    it, and fails (KeyError) unless that cell is a solution or test cell. So no locked cell may
    sit directly before a test cell, counting only cells with nbgrader metadata.
    """
    cell = nbformat.v4.new_markdown_cell(text.strip())
    if grade_id == "intro":
        cell.metadata.update(_meta("locked", grade_id))
    return cell


def code(text: str, kind: str | None = None, grade_id: str | None = None, points: float = 0):
    cell = nbformat.v4.new_code_cell(text.strip())
    if kind:
        cell.metadata.update(_meta(kind, grade_id, points))
    return cell


def test_cell(assignment: str, name: str):
    """The graded cell of one check: the self-check, then the hidden graded run with a fresh seed."""
    from course_lib.checks import registry

    spec = registry.get_check(assignment, name)
    source = (f"# {spec.description} ({spec.points:g} points)\n"
              f"checks.selfcheck({name!r})\n"
              "### BEGIN HIDDEN TESTS\n"
              f"checks.grade({name!r})\n"
              "### END HIDDEN TESTS")
    return code(source, "test", f"check_{name}", spec.points)


def setup_cell(assignment: str, module: str, extra: str = ""):
    return code(f"""
# Run this cell first. It imports the course helpers and this assignment's checks.
import importlib

import numpy as np

from course_lib import images, rosenv
from course_lib.checks import {assignment} as checks
{extra}""", "locked", "setup")


def import_cell(module: str, names: str):
    return code(f"""
# Imports (or re-imports, after you edit and re-run the cell above) your module.
import {module}
importlib.reload({module})
from {module} import {names}
""")  # not locked: see md()


def notebook(cells) -> nbformat.NotebookNode:
    nb = nbformat.v4.new_notebook()
    for index, cell in enumerate(cells):  # stable ids: rebuilding gives the same file
        cell.id = cell.metadata.get("nbgrader", {}).get("grade_id") or f"cell-{index}"
    nb.cells = cells
    nb.metadata["kernelspec"] = {"display_name": "Python 3 (ipykernel)", "language": "python", "name": "python3"}
    nb.metadata["language_info"] = {"name": "python"}
    return nb


# ---------------------------------------------------------------------------------------------

BRIGHTNESS_MODULE = '''
%%writefile brightness_node.py
"""Brightness of camera images: a plain numpy function and the node around it."""
import numpy as np
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import Image
from std_msgs.msg import UInt8

from course_lib import images


def average_brightness(image: np.ndarray) -> int:
    """The mean of all bytes of an image (every channel of every pixel), rounded down, as an int."""
    ### BEGIN SOLUTION
    # One numpy sum instead of a Python loop over millions of bytes; uint64 cannot overflow here.
    return int(image.sum(dtype=np.uint64) // image.size)
    ### END SOLUTION


class BrightnessNode(Node):
    """Subscribes /image and publishes the average brightness of every frame on /brightness."""

    def __init__(self):
        super().__init__("my_node")
        ### BEGIN SOLUTION
        self.publisher = self.create_publisher(UInt8, "/brightness", qos_profile_sensor_data)
        self.subscription = self.create_subscription(Image, "/image", self.on_image, qos_profile_sensor_data)
        ### END SOLUTION

    def on_image(self, msg: Image) -> None:
        ### BEGIN SOLUTION
        frame = images.msg_to_image(msg)  # mono8: (H, W); bgr8: (H, W, 3); no copy
        self.publisher.publish(UInt8(data=average_brightness(frame)))
        ### END SOLUTION


def main(args=None):
    rclpy.init(args=args)
    node = BrightnessNode()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
'''


def brightness() -> nbformat.NotebookNode:
    return notebook([
        md("""
# Assignment: image brightness

You write a small vision node in two layers, as in the lecture: a plain numpy function that does
the work, and a ROS 2 node that only converts messages and calls it.

**Contract** (this is exactly what is graded):

1. `average_brightness(image: np.ndarray) -> int`: the mean of *all* bytes of the image (every
   channel of every pixel), rounded **down** as the tutorial's integer division `sum // count`,
   returned as a Python `int`. It works for colour `(H, W, 3)` and grey `(H, W)` images.
2. `BrightnessNode()`: a node named **`my_node`** that subscribes **`/image`**
   (`sensor_msgs/msg/Image`) and publishes **`/brightness`** (`std_msgs/msg/UInt8`), both with the
   **sensor-data QoS** (`qos_profile_sensor_data`), one value per frame. It accepts `bgr8` and
   `mono8` frames, keeps up with 1920×1080 frames at 30 Hz, and its names can be remapped
   (`--ros-args -r __node:=other -r /image:=/camera/image`).
3. `main(args=None)` runs the node until Ctrl-C (it is how the grader starts your node).

Write everything in the cell that starts with `%%writefile brightness_node.py`: running it saves
your module next to this notebook; the cell after it imports it. The grader runs your node in a
separate process, publishes generated frames and compares what comes back with the right answer.

Each check cell prints what is right and what is wrong. At grading, the same checks run again
with frames you have not seen.
""", "intro"),
        setup_cell("brightness", "brightness_node"),
        md("## Your module\n\nReplace each `raise NotImplementedError(...)` with your code, then run the cell.", "task_md"),
        code(BRIGHTNESS_MODULE, "solution", "brightness_node"),
        import_cell("brightness_node", "average_brightness, BrightnessNode"),
        md("Try your function (this cell is yours to change):"),
        code("""
grey = np.array([[0, 255], [255, 255]], dtype=np.uint8)
print(average_brightness(grey))   # (0 + 255 + 255 + 255) // 4 = 191
"""),
        md("## Check 1: `average_brightness`", "check_values_md"),
        test_cell("brightness", "values"),
        md("""
## Check 2: `BrightnessNode`

The check starts your node as `python -c "import brightness_node; brightness_node.main()"` in a
ROS domain of its own, publishes frames on `/image` and reads `/brightness`. A Python loop over
every byte is too slow for 30 frames of 1920×1080 per second: let numpy do the sum.
""", "check_node_md"),
        test_cell("brightness", "node"),
    ])


PUBSUB_MODULE = '''
%%writefile pubsub_nodes.py
"""A counter publisher and a subscriber that records what it hears (std_msgs/Header as the message)."""
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Header

TOPIC = "ros_tutorial_msg"
QUEUE_DEPTH = 100


class CounterPublisher(Node):
    """Publishes Header messages at 10 Hz: stamp = now, frame_id = the counter as text."""

    def __init__(self):
        super().__init__("counter_publisher")
        ### BEGIN SOLUTION
        self.count = 0
        self.publisher = self.create_publisher(Header, TOPIC, QUEUE_DEPTH)
        self.timer = self.create_timer(0.1, self.publish_count)
        ### END SOLUTION

    def publish_count(self) -> None:
        ### BEGIN SOLUTION
        msg = Header(frame_id=str(self.count))
        msg.stamp = self.get_clock().now().to_msg()
        self.publisher.publish(msg)
        self.count += 1
        ### END SOLUTION


class CounterSubscriber(Node):
    """Records (stamp, counter) of every message in self.received and logs 'I heard: N'."""

    def __init__(self):
        super().__init__("counter_subscriber")
        self.received = []
        ### BEGIN SOLUTION
        self.subscription = self.create_subscription(Header, TOPIC, self.on_message, QUEUE_DEPTH)
        ### END SOLUTION

    def on_message(self, msg: Header) -> None:
        ### BEGIN SOLUTION
        counter = int(msg.frame_id)
        self.received.append((msg.stamp, counter))
        self.get_logger().info(f"I heard: {counter}")
        ### END SOLUTION


def _run(node_class, args=None):
    rclpy.init(args=args)
    node = node_class()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


def main_publisher(args=None):
    _run(CounterPublisher, args)


def main_subscriber(args=None):
    _run(CounterSubscriber, args)
'''


def pubsub() -> nbformat.NotebookNode:
    return notebook([
        md("""
# Assignment: publisher and subscriber

Two nodes that talk over a topic, as in the ROS 2 tutorial. The course's own `MsgTutorial`
message comes later; until then the message is the stock **`std_msgs/msg/Header`**: its `stamp`
is the time of publishing and its `frame_id` holds the counter as text (`"0"`, `"1"`, ...).

**Contract** (this is exactly what is graded):

1. `CounterPublisher()`: node **`counter_publisher`**; publishes on **`ros_tutorial_msg`** with a
   queue depth of **100**, at **10 Hz** (a 0.1 s timer); the counter starts at 0 and grows by one
   per message; each message's stamp is later than the one before.
2. `CounterSubscriber()`: node **`counter_subscriber`**; subscribes `ros_tutorial_msg` with a queue
   depth of 100; appends `(stamp, counter)` to `self.received` and logs **`I heard: <counter>`**
   for every message.
3. `main_publisher(args=None)` and `main_subscriber(args=None)` run one node each until Ctrl-C.

The grader starts your nodes in separate processes, listens to your publisher, talks to your
subscriber (reading its log), and runs both together.
""", "intro"),
        setup_cell("pubsub", "pubsub_nodes"),
        md("## Your module", "task_md"),
        code(PUBSUB_MODULE, "solution", "pubsub_nodes"),
        import_cell("pubsub_nodes", "CounterPublisher, CounterSubscriber"),
        md("## Check 1: the publisher", "check_publisher_md"),
        test_cell("pubsub", "publisher"),
        md("## Check 2: the subscriber", "check_subscriber_md"),
        test_cell("pubsub", "subscriber"),
        md("## Check 3: both together", "check_together_md"),
        test_cell("pubsub", "together"),
    ])


MARKER_MODULE = '''
%%writefile marker_reader.py
"""Finds the cat and dog pictures on the marker board and warps them upright."""
import cv2
import numpy as np
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import CompressedImage, Image

from course_lib import boards, images, marker_board

# The board convention lives in course_lib.marker_board: marker_board.PICTURES (the markers framing each
# picture, top-left, top-right, bottom-right, bottom-left), marker_board.CORNER_OF_MARKER (which corner
# of each marker touches the picture) and marker_board.detector() (DICT_4X4_50).
DETECTOR = marker_board.detector()


def crop_pictures(frame_bgr: np.ndarray, size=(320, 240)) -> dict:
    """The pictures whose four markers are all in the frame, warped to `size` (width, height)."""
    ### BEGIN SOLUTION
    def detect(image):
        corners, ids, _rejected = DETECTOR.detectMarkers(image)
        return {} if ids is None else {int(i): c.reshape(4, 2) for i, c in zip(ids.ravel(), corners)}

    board_ids = [i for ids in marker_board.PICTURES.values() for i in ids]
    found = detect(frame_bgr)
    if not all(i in found for i in board_ids):
        # A marker touching a dark picture corner merges with it in the threshold image. Look again
        # with the dark areas thinned (a maximum filter; at twice the size for a finer step), and
        # move the corners found back out by the amount thinned.
        grey = frame_bgr if frame_bgr.ndim == 2 else cv2.cvtColor(frame_bgr, cv2.COLOR_BGR2GRAY)
        for scale, kernel in ((1, 3), (2, 5)):
            bigger = cv2.resize(grey, None, fx=scale, fy=scale) if scale > 1 else grey
            lighter = cv2.dilate(bigger, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (kernel, kernel)))
            for i, c in detect(lighter).items():
                if i in board_ids and i not in found:
                    c = (c + 0.5) / scale - 0.5
                    out = (c - c.mean(axis=0)) / np.linalg.norm(c - c.mean(axis=0), axis=1, keepdims=True)
                    found[i] = (c + out * (kernel // 2 / scale) * np.sqrt(2)).astype(np.float32)
        known = [i for i in board_ids if i in found]
        if 2 <= len(known) < len(board_ids):
            # Two markers give the board's homography: paint the pictures white and look again.
            board = boards.default_board()
            H, _ = cv2.findHomography(np.concatenate([board.marker_square(i) for i in known]).astype(np.float32),
                                      np.concatenate([found[i] for i in known]).astype(np.float32))
            painted = grey.copy()
            for name in marker_board.PICTURES if H is not None else ():
                slot = cv2.perspectiveTransform(board.picture_slot(name)[None].astype(np.float32), H)[0]
                cv2.fillConvexPoly(painted, np.round(slot * 16).astype(np.int32), 255, cv2.LINE_AA, shift=4)
            for i, c in (detect(painted) if H is not None else {}).items():
                if i in board_ids and i not in found:
                    c = np.ascontiguousarray(c, dtype=np.float32).reshape(-1, 1, 2)
                    cv2.cornerSubPix(grey, c, (3, 3), (-1, -1), (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_COUNT, 30, 0.01))
                    found[i] = c.reshape(4, 2)
    width, height = size
    target = marker_board.crop_corners(size)
    crops = {}
    for name, markers in marker_board.PICTURES.items():
        if all(m in found for m in markers):
            source = np.float32([found[m][c] for m, c in zip(markers, marker_board.CORNER_OF_MARKER)])
            H = cv2.getPerspectiveTransform(source, target)
            crops[name] = cv2.warpPerspective(frame_bgr, H, (width, height))
    return crops
    ### END SOLUTION


class MarkerReader(Node):
    """Subscribes image; publishes each picture it finds on cropped_img/<name> as a PNG."""

    def __init__(self):
        super().__init__("marker_reader")
        ### BEGIN SOLUTION
        self.publishers_ = {name: self.create_publisher(CompressedImage, f"cropped_img/{name}", 10)
                            for name in marker_board.PICTURES}
        self.subscription = self.create_subscription(Image, "image", self.on_image, qos_profile_sensor_data)
        ### END SOLUTION

    def on_image(self, msg: Image) -> None:
        ### BEGIN SOLUTION
        frame = images.msg_to_image(msg, want="bgr8")
        for name, crop in crop_pictures(frame).items():
            self.publishers_[name].publish(images.image_to_compressed(crop, "png", header=msg.header))
        ### END SOLUTION


def main(args=None):
    rclpy.init(args=args)
    node = MarkerReader()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
'''


def catdog_warp() -> nbformat.NotebookNode:
    return notebook([
        md("""
# Assignment: cat and dog, warped upright

A camera looks at the course's marker board: a cat picture framed by ArUco markers 1-4 and a dog
picture framed by markers 5-8 (dictionary `DICT_4X4_50`), in the order top-left, top-right,
bottom-right, bottom-left. Each marker touches its picture with one corner: marker 1 with its
corner 2, marker 2 with corner 3, marker 3 with corner 0, marker 4 with corner 1
(`course_lib.marker_board.PICTURES` and `CORNER_OF_MARKER`; OpenCV numbers a marker's corners
clockwise from its top-left).

**Contract** (this is exactly what is graded):

1. `crop_pictures(frame_bgr, size=(320, 240)) -> dict`: `{"cat": crop, "dog": crop}`, with a key
   **only when all four markers** of that picture are found; each crop is a BGR `uint8` image of
   `size` = (width, height), upright and not mirrored (the picture's top-left corner at pixel (0, 0)).
2. `MarkerReader()`: node **`marker_reader`**; subscribes **`image`** (`sensor_msgs/msg/Image`);
   for every frame publishes the crops it finds on **`cropped_img/cat`** and **`cropped_img/dog`**
   (`sensor_msgs/msg/CompressedImage`, e.g. `images.image_to_compressed(crop, "png")`).
3. `main(args=None)` runs the node until Ctrl-C.

The grader renders scenes (`course_lib.scenes.render_scene`) with poses and lighting you have not
seen, and compares your crops with the true ones (`marker_board.crop_similarity`, passing at
`marker_board.SAME_CROP_THRESHOLD`). Try your function on `scenes.render_scene(seed).frame`.
""", "intro"),
        setup_cell("catdog_warp", "marker_reader", "from course_lib import marker_board, scenes\n"),
        md("## Your module", "task_md"),
        code(MARKER_MODULE, "solution", "marker_reader"),
        import_cell("marker_reader", "crop_pictures, MarkerReader"),
        md("Try it on a generated scene (this cell is yours to change):"),
        code("""
scene = scenes.render_scene(1)
print(sorted(crop_pictures(scene.frame)))   # ['cat', 'dog']
"""),
        md("## Check 1: easy views", "check_easy_md"),
        test_cell("catdog_warp", "easy"),
        md("## Check 2: hard views", "check_hard_md"),
        test_cell("catdog_warp", "hard"),
        md("## Check 3: missing markers", "check_missing_md"),
        test_cell("catdog_warp", "missing_and_none"),
        md("## Check 4: noise, blur, another size", "check_noisy_md"),
        test_cell("catdog_warp", "noisy"),
        md("## Check 5: the node", "check_node_md"),
        test_cell("catdog_warp", "node"),
    ])


NOTEBOOKS = {"brightness": brightness, "pubsub": pubsub, "catdog_warp": catdog_warp}


def build(names=None) -> list[Path]:
    """Write the source notebooks (all, or the given assignments) and return their paths."""
    sys.path.insert(0, str(HERE.parent))
    written = []
    for name in names or NOTEBOOKS:
        path = SOURCE / name / f"{name}.ipynb"
        path.parent.mkdir(parents=True, exist_ok=True)
        nbformat.write(NOTEBOOKS[name](), path)
        written.append(path)
    return written


if __name__ == "__main__":
    for path in build(sys.argv[1:] or None):
        print(path)
