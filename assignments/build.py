"""Writes the nbgrader source notebooks of the graded assignments: ``python assignments/build.py``.

The notebooks under assignments/source/ are what instructors edit in JupyterLab; this script is
how they are made and how a test checks that their graded cells match the checks (points of each
test cell = points of its check in course_lib/checks/).

The solutions are the reference packages in assignments/reference_ws/src (the only copy): each
file of an assignment's packages becomes a ``%%writefile ros2_ws/src/<package>/<file>`` cell. A
file with ``### BEGIN SOLUTION`` / ``### END SOLUTION`` regions (inside function bodies, so that
nbgrader's stub ``raise NotImplementedError`` keeps the module importable) is a solution cell.
"""

from __future__ import annotations

import sys
from pathlib import Path, PurePosixPath

import nbformat

from course_lib.checks.assignments import WORKSPACE

HERE = Path(__file__).resolve().parent
SOURCE = HERE / "source"
REFERENCE_SRC = HERE / "reference_ws" / "src"


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


def setup_cell(assignment: str, extra: str = ""):
    return code(f"""
# Run this cell first. It imports the course helpers and this assignment's checks.
import importlib
import sys

import numpy as np

from course_lib import images, rosenv
from course_lib.checks import {assignment} as checks
{extra}""", "locked", "setup")


def import_cell(package: str, module: str, names: str):
    """Imports the student's module from its package's source (no build needed for plain functions)."""
    folder = f"{WORKSPACE}/src/{package}"
    return code(f"""
# Imports (or re-imports, after you edit and re-run the cells above) your module from its package.
if {folder!r} not in sys.path:
    sys.path.insert(0, {folder!r})
import {module}
importlib.reload({module})
from {module} import {names}
""")  # not locked: see md()


def package_files(package: str) -> list[tuple[str, str]]:
    """(path beside the notebook, text) of each file of a reference package, its tests left out."""
    folder = REFERENCE_SRC / package
    files = []
    for path in sorted(p for p in folder.rglob("*") if p.is_file() and "__pycache__" not in p.parts):
        relative = PurePosixPath(path.relative_to(folder).as_posix())
        if relative.parts[0] == "test":
            continue
        files.append((f"{WORKSPACE}/src/{package}/{relative}", path.read_text()))
    return files


def package_cells(packages: list[str], plain_ros: str) -> list:
    """The cells that write the packages: the folders, then one %%writefile cell per file (a
    solution cell when the file has solution regions), then the build."""
    files = [item for package in packages for item in package_files(package)]
    folders = sorted({str(PurePosixPath(path).parent) for path, _ in files})
    empty = [path for path, text in files if not text]  # %%writefile refuses an empty cell
    cells = [md(f"""
## Your packages

Each cell below writes one file of your workspace `{WORKSPACE}/src/`: run them all after every change
(or edit the files in JupyterLab's file browser and copy your changes back here: the notebook is what
you hand in, and grading runs it). {plain_ros}
"""),
             code("# The package folders and empty files (in a terminal: the same commands).\n"
                  f"!mkdir -p {' '.join(folders)}\n!touch {' '.join(empty)}")]
    for path, text in files:
        if not text:
            continue
        source = f"%%writefile {path}\n{text}"
        if "### BEGIN SOLUTION" in text:
            cells.append(code(source, "solution", PurePosixPath(path).stem))
        else:
            cells.append(code(source))
    cells.append(md("""
### Build

The next cell builds the workspace, as `cd ros2_ws && colcon build --symlink-install` does in a
terminal (on the course's pip install `python -m course_lib build` also sets what the wheels need
for message packages). Build again after changing `setup.py`, `package.xml` or a `.msg` file; with
`--symlink-install` a change of a Python file needs no new build. At grading the grader builds your
workspace itself, in its sandbox, and this cell does nothing.
"""))
    cells.append(code(f"""
if not rosenv.under_grading():
    !python -m course_lib build {WORKSPACE} --symlink-install
"""))
    return cells


def notebook(cells) -> nbformat.NotebookNode:
    nb = nbformat.v4.new_notebook()
    for index, cell in enumerate(cells):  # stable ids: rebuilding gives the same file
        cell.id = cell.metadata.get("nbgrader", {}).get("grade_id") or f"cell-{index}"
    nb.cells = cells
    nb.metadata["kernelspec"] = {"display_name": "Python 3 (ipykernel)", "language": "python", "name": "python3"}
    nb.metadata["language_info"] = {"name": "python"}
    return nb


# ---------------------------------------------------------------------------------------------

def brightness() -> nbformat.NotebookNode:
    return notebook([
        md("""
# Assignment: image brightness

You write a small vision node in two layers, as in the lecture: a plain numpy function that does
the work, and a ROS 2 node that only converts messages and calls it, in an `ament_python` package.

**Contract** (this is exactly what is graded):

1. The package **`brightness`** in `ros2_ws/src/brightness`, with the executable
   **`brightness_node`** (`ros2 run brightness brightness_node`), whose `package.xml` declares every
   ROS package its code imports (`rclpy`, `sensor_msgs`, `std_msgs`).
2. In `brightness/brightness_node.py`: `average_brightness(image: np.ndarray) -> int`, the mean of
   *all* bytes of the image (every channel of every pixel), rounded **down** as the tutorial's integer
   division `sum // count`, returned as a Python `int`. It works for colour `(H, W, 3)` and grey
   `(H, W)` images.
3. `BrightnessNode()`: a node named **`brightness_node`** (the name lesson 02 gives it) that subscribes **`/image`**
   (`sensor_msgs/msg/Image`) and publishes **`/brightness`** (`std_msgs/msg/UInt8`), both with the
   **sensor-data QoS** (`qos_profile_sensor_data`), one value per frame. It accepts `bgr8` and
   `mono8` frames, keeps up with 1920×1080 frames at 30 Hz, and its names can be remapped
   (`--ros-args -r __node:=other -r /image:=/camera/image`). `main(args=None)` runs it until Ctrl-C
   (the executable calls it).

The grader builds your workspace, runs `ros2 run brightness brightness_node` in a separate process,
publishes generated frames and compares what comes back with the right answer. Each check cell prints
what is right and what is wrong; at grading the same checks run again with frames you have not seen.
""", "intro"),
        setup_cell("brightness"),
        *package_cells(["brightness"], "In plain ROS 2 the package comes from `ros2 pkg create --build-type "
                       "ament_python --dependencies rclpy sensor_msgs std_msgs --node-name brightness_node brightness`."),
        import_cell("brightness", "brightness.brightness_node", "average_brightness, BrightnessNode"),
        md("Try your function (this cell is yours to change):"),
        code("""
grey = np.array([[0, 255], [255, 255]], dtype=np.uint8)
print(average_brightness(grey))   # (0 + 255 + 255 + 255) // 4 = 191
"""),
        md("## Check 1: `average_brightness`", "check_values_md"),
        test_cell("brightness", "values"),
        md("""
## Check 2: `BrightnessNode`

The check starts your node as `ros2 run brightness brightness_node` (build first) in a ROS domain of
its own, publishes frames on `/image` and reads `/brightness`. A Python loop over every byte is too
slow for 30 frames of 1920×1080 per second: let numpy do the sum.
""", "check_node_md"),
        test_cell("brightness", "node"),
    ])


def pubsub() -> nbformat.NotebookNode:
    return notebook([
        md("""
# Assignment: publisher and subscriber

Two nodes that talk over a topic with the lecture's own message, `MsgTutorial`, as in Lesson 01b:
a message package and a package of nodes that depends on it.

**Contract** (this is exactly what is graded):

1. The interface package **`tutorial_interfaces`** (`ament_cmake`) with `msg/MsgTutorial.msg`:
   `builtin_interfaces/Time stamp` and `int32 data`.
2. The package **`pubsub`** (`ament_python`, depending on `rclpy` and `tutorial_interfaces`) with two
   executables:
   - **`topic_publisher`** (`pubsub/topic_publisher.py`, class `TopicPublisher`, node
     **`topic_publisher`**): publishes `MsgTutorial` on **`ros_tutorial_msg`** with a queue depth of
     **100**, at **10 Hz** (a 0.1 s timer); `stamp` is the time of publishing, `data` a counter that
     starts at 0 and grows by one per message.
   - **`topic_subscriber`** (`pubsub/topic_subscriber.py`, class `TopicSubscriber`, node
     **`topic_subscriber`**): subscribes `ros_tutorial_msg` with a queue depth of 100 and logs each
     field of every message: `I heard: stamp <sec>.<nanosec> data <data>`.

The grader builds your workspace, starts your executables as `ros2 run pubsub topic_publisher` and
`ros2 run pubsub topic_subscriber` in separate processes, listens to your publisher, talks to your
subscriber (reading its log), and runs both together.
""", "intro"),
        setup_cell("pubsub"),
        *package_cells(["tutorial_interfaces", "pubsub"],
                       "In plain ROS 2: `ros2 pkg create --build-type ament_cmake tutorial_interfaces` and "
                       "`ros2 pkg create --build-type ament_python --dependencies rclpy tutorial_interfaces "
                       "--node-name topic_publisher pubsub`, then the edits of Lesson 01b."),
        md("## Check 1: the publisher", "check_publisher_md"),
        test_cell("pubsub", "publisher"),
        md("## Check 2: the subscriber", "check_subscriber_md"),
        test_cell("pubsub", "subscriber"),
        md("## Check 3: both together", "check_together_md"),
        test_cell("pubsub", "together"),
    ])


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

**Contract** (this is exactly what is graded). Your workspace `ros2_ws/src` holds three packages:

1. **`catdog_interfaces`**: the message `msg/CroppedPicture.msg` with `int32 picture` (constants
   `CAT=1`, `DOG=2`) and `sensor_msgs/CompressedImage image`.
2. **`webcam`**: the executable **`image_publisher`** (given: the course's simulated board, a video
   file or a real camera on `image`).
3. **`readmarker`**:
   - `readmarker/crop.py`: `crop_pictures(frame_bgr, size=(320, 240)) -> dict`, `{"cat": crop,
     "dog": crop}` with a key **only when all four markers** of that picture are found; each crop is
     a BGR `uint8` image of `size` = (width, height), upright and not mirrored (the picture's
     top-left corner at pixel (0, 0));
   - `readmarker/marker_reader.py`: the node **`marker_reader`** (executable `marker_reader`);
     subscribes **`image`** (`sensor_msgs/msg/Image`) and for every frame publishes each crop it
     finds on **`cropped_img`** as a `CroppedPicture` (`picture` 1 for the cat, 2 for the dog; the
     crop as a PNG, `images.image_to_compressed(crop, "png")`);
   - `launch/catdog_warp.launch.xml`, starting `image_publisher` and `marker_reader`
     (`ros2 launch readmarker catdog_warp.launch.xml`); `package.xml` declares every ROS package the
     code imports.

The grader renders scenes (`course_lib.scenes.render_scene`) with poses and lighting you have not
seen, and compares your crops with the true ones (`marker_board.crop_similarity`, passing at
`marker_board.SAME_CROP_THRESHOLD`). Try your function on `scenes.render_scene(seed).frame`.
""", "intro"),
        setup_cell("catdog_warp", "from course_lib import marker_board, scenes\n"),
        *package_cells(["catdog_interfaces", "webcam", "readmarker"],
                       "In plain ROS 2 the packages come from `ros2 pkg create` (`--build-type ament_cmake` for "
                       "`catdog_interfaces`, `ament_python` for the others)."),
        import_cell("readmarker", "readmarker.crop", "crop_pictures"),
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
