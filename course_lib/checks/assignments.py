"""The graded assignments, one spec each: what the notebook builder (assignments/build.py), the checks,
the grader and the tests read about an assignment.

An assignment is a colcon workspace beside its notebook (``ros2_ws/src/<package>/``), multiple-choice
questions answered in the notebook (``q3 = "b"``), or both. Its spec says which packages the student
writes and the executables each installs (what ``ros2 run`` offers), which module holds the plain
functions the checks call without a build, its questions, where the expected answers of its checks
come from, and the words of its notebook that are its own (assignments/build.py writes the rest: the
packages' cells, the imports, a markdown and an answer cell per question, a test cell per check).
Its checks and their points are in ``course_lib/checks/<name>.py``; its reference packages in
``assignments/reference_ws/src/``.
"""

from __future__ import annotations

import dataclasses

from course_lib.checks.multiple_choice import Question
from course_lib.checks.quiz_questions import QUIZ_QUESTIONS

#: The workspace folder beside an assignment's notebook.
WORKSPACE = "ros2_ws"


@dataclasses.dataclass(frozen=True)
class NotebookText:
    """The words of an assignment's notebook that are its own.

    Attributes:
        intro: the first cell (markdown): the assignment and its contract, what is graded.
        plain_ros: how its packages come about in plain ROS 2 (ends the packages' introduction; "" without packages).
        checks: each check -> its heading (after "Check N: ") and, optionally, markdown under it.
        imports: more lines of the setup cell.
        names: what the notebook imports from the module of the plain functions (Assignment.functions).
        try_text, try_code: the cell the student tries the functions in, and the line before it.
    """

    intro: str
    checks: dict[str, tuple[str, ...]]
    plain_ros: str = ""
    imports: str = ""
    names: str = ""
    try_text: str = ""
    try_code: str = ""


@dataclasses.dataclass(frozen=True)
class Assignment:
    """One graded assignment.

    Attributes:
        name: the assignment's name: its notebook, its checks module, its nbgrader assignment.
        packages: each package the student writes -> the executables it installs (none for a
            message package), in build order; {} for an assignment without a workspace (nothing
            is built).
        functions: (package, dotted module) of the plain functions the checks call, or None.
        questions: its multiple-choice questions, the notebook's variable -> the question ({} for none).
        answers: where the checks' expected answers come from: "key" (the grader's answer key,
            autograder/answers/<name>.py, recorded for self-checks in checks/recorded/<name>.json),
            "secret" (the grader's answer key, asked only when graded and never recorded: a quiz's
            key would be its answers) or "scene" (the ground truth of the scenes the checks draw).
        notebook: the words of its notebook that are its own.
    """

    name: str
    packages: dict[str, tuple[str, ...]]
    notebook: NotebookText
    functions: tuple[str, str] | None = None
    questions: dict[str, Question] = dataclasses.field(default_factory=dict)
    answers: str = "scene"

    def executables(self, package: str) -> tuple[str, ...]:
        return self.packages[package]


# --- the notebooks' introductions (markdown) ----------------------------------------------------

PUBSUB_INTRO = """
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
"""

BRIGHTNESS_INTRO = """
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
"""

BRIGHTNESS_NODE_CHECK = """\
The check starts your node as `ros2 run brightness brightness_node` (build first) in a ROS domain of
its own, publishes frames on `/image` and reads `/brightness`. A Python loop over every byte is too
slow for 30 frames of 1920×1080 per second: let numpy do the sum.
"""

CATDOG_WARP_INTRO = """
# Assignment: cat and dog, warped upright

A camera looks at the course's marker board: a cat picture framed by ArUco markers 1-4 and a dog
picture framed by markers 5-8 (dictionary `DICT_4X4_50`), in the order top-left, top-right,
bottom-right, bottom-left. Each marker touches its picture with one corner: marker 1 with its
corner 2, marker 2 with corner 3, marker 3 with corner 0, marker 4 with corner 1
(`course_lib.imaging.marker_board.PICTURES` and `CORNER_OF_MARKER`; OpenCV numbers a marker's corners
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

The grader renders scenes (`course_lib.imaging.scenes.render_scene`) with poses and lighting you have not
seen, and compares your crops with the true ones (`marker_board.crop_similarity`, passing at
`marker_board.SAME_CROP_THRESHOLD`). Try your function on `scenes.render_scene(seed).frame`.
"""

QUIZ_INTRO = """
# Quiz: lessons 00-05

Sixteen multiple-choice questions on what the lessons taught: ROS 2's concepts, reading what the
`ros2` command prints, choosing a QoS, reading a launch file, images, markers, actions and bags. Each has one
right answer and earns one point.

**How to answer:** write the letter of your choice as a string into the cell under the question,
e.g. `q3 = "b"`, and run it. The check cell at the end saves your answers and says whether each is
one of the question's letters; whether it is right is graded after you hand the quiz in, and the
feedback explains each wrong answer. Run every cell (Run All) before you hand it in.
"""


SERVICES_ACTIONS_INTRO = """
# Assignment: the pan camera's service and action

The camera of Lesson 04 sits on a pan head in front of the marker board (`course_lib.pan_camera`):
turned to `pan` degrees (positive to the right) it sees some of the board's markers, and at about
0 degrees both pictures. You write the node that offers what Lesson 04 taught: a service that answers
a question at once, and an action that takes a while, reports its progress and can be canceled.

**Contract** (this is exactly what is graded). Your workspace `ros2_ws/src` holds two packages:

1. **`camera_interfaces`** (given, as built in Lesson 04): `srv/MarkersInView.srv` and
   `action/FindPictures.action`.
2. **`pan_camera`** (`ament_python`, depending on `rclpy` and `camera_interfaces`) with the
   executable **`pan_camera_node`** (`pan_camera/pan_camera_node.py`, class `PanCameraNode`, node
   **`pan_camera`**), whose camera starts at the parameter **`start_pan`** (degrees; default
   `pan_camera.START_PAN`):
   - the service **`markers_in_view`** (`camera_interfaces/srv/MarkersInView`): for the request's
     `pan`, `ids` = `markers_in_view(pan)`, `framed` = `framed_at(pan)` (as lists), `success` true and
     a short `message`; asking does not turn the camera;
   - the action **`find_pictures`** (`camera_interfaces/action/FindPictures`): from where the camera
     is, turn `STEP_DEGREES` (5) per step, one step per `STEP_SECONDS` (0.1 s), until every picture
     of the goal's `pictures` (empty: both) is framed; after each step publish feedback (`pan`, and the
     `ids` in view there); then succeed with the result `pan` and `framed`. A goal naming another
     picture is rejected. A cancel request is accepted, and the search stops before its next step
     (status CANCELED, the result where it stopped): the service and cancel requests must be served
     while a goal runs (a `ReentrantCallbackGroup`, spun by the `MultiThreadedExecutor` that `main`
     already uses).

The grader builds your workspace, starts `ros2 run pan_camera pan_camera_node` (with `-p
start_pan:=...` for the action) in a ROS domain of its own, asks the service about angles it draws
fresh, sends goals from start angles it draws fresh, and compares with what `course_lib.pan_camera`
says the camera sees. Try your node from a terminal, as in Lesson 04:
`ros2 service call /markers_in_view camera_interfaces/srv/MarkersInView "{pan: -10.0}"` and
`ros2 action send_goal --feedback /find_pictures camera_interfaces/action/FindPictures "{pictures: [cat]}"`.
"""


#: Every graded assignment, in the order the course teaches them.
ASSIGNMENTS: dict[str, Assignment] = {spec.name: spec for spec in (
    Assignment("pubsub", {"tutorial_interfaces": (), "pubsub": ("topic_publisher", "topic_subscriber")},
               NotebookText(intro=PUBSUB_INTRO, plain_ros=(
                   "In plain ROS 2: `ros2 pkg create --build-type ament_cmake tutorial_interfaces` and "
                   "`ros2 pkg create --build-type ament_python --dependencies rclpy tutorial_interfaces "
                   "--node-name topic_publisher pubsub`, then the edits of Lesson 01b."),
                   checks={"publisher": ("the publisher",), "subscriber": ("the subscriber",),
                           "together": ("both together",)})),
    Assignment("brightness", {"brightness": ("brightness_node",)},
               NotebookText(intro=BRIGHTNESS_INTRO, plain_ros=(
                   "In plain ROS 2 the package comes from `ros2 pkg create --build-type "
                   "ament_python --dependencies rclpy sensor_msgs std_msgs --node-name brightness_node brightness`."),
                   checks={"values": ("`average_brightness`",), "node": ("`BrightnessNode`", BRIGHTNESS_NODE_CHECK)},
                   names="average_brightness, BrightnessNode",
                   try_text="Try your function (this cell is yours to change):", try_code="""
grey = np.array([[0, 255], [255, 255]], dtype=np.uint8)
try:
    print(average_brightness(grey))   # (0 + 255 + 255 + 255) // 4 = 191
except NotImplementedError:  # the stub: Run All goes on to the checks, which say what is missing
    print("Not done yet: average_brightness still raises NotImplementedError. Write it in the "
          "brightness_node.py cell above, run that cell and the import cell, then this one.")
"""),
               functions=("brightness", "brightness.brightness_node"), answers="key"),
    Assignment("catdog_warp", {"catdog_interfaces": (), "webcam": ("image_publisher",),
                               "readmarker": ("marker_reader",)},
               NotebookText(intro=CATDOG_WARP_INTRO, plain_ros=(
                   "In plain ROS 2 the packages come from `ros2 pkg create` (`--build-type ament_cmake` for "
                   "`catdog_interfaces`, `ament_python` for the others)."),
                   checks={"easy": ("easy views",), "hard": ("hard views",), "missing_and_none": ("missing markers",),
                           "noisy": ("noise, blur, another size",), "node": ("the node",)},
                   imports="from course_lib import marker_board, scenes\n", names="crop_pictures",
                   try_text="Try it on a generated scene (this cell is yours to change):", try_code="""
scene = scenes.render_scene(1)
try:
    print(sorted(crop_pictures(scene.frame)))   # ['cat', 'dog']
except NotImplementedError:  # the stub: Run All goes on to the checks, which say what is missing
    print("Not done yet: crop_pictures still raises NotImplementedError. Write it in the crop.py "
          "cell above, run that cell and the import cell, then this one.")
"""),
               functions=("readmarker", "readmarker.crop")),
    Assignment("services_actions", {"camera_interfaces": (), "pan_camera": ("pan_camera_node",)},
               NotebookText(intro=SERVICES_ACTIONS_INTRO, plain_ros=(
                   "In plain ROS 2 the packages come from `ros2 pkg create --build-type ament_cmake camera_interfaces` "
                   "(then the edits of Lesson 04) and `ros2 pkg create --build-type ament_python --dependencies rclpy "
                   "camera_interfaces --node-name pan_camera_node pan_camera`."),
                   checks={"service": ("the service `markers_in_view`",),
                           "action": ("the action `find_pictures`",),
                           "cancel": ("canceling a goal",)})),
    Assignment("quiz", {}, NotebookText(intro=QUIZ_INTRO, checks={"answers": ("your answers",)}),
               questions=QUIZ_QUESTIONS, answers="secret"),
)}


def spec(name: str) -> Assignment:
    """The spec of an assignment; KeyError naming the assignments there are."""
    if name not in ASSIGNMENTS:
        raise KeyError(f"no graded assignment {name!r}; the assignments are {sorted(ASSIGNMENTS)}")
    return ASSIGNMENTS[name]
