"""The questions of the graded quiz (lessons 00-05), without their answers: the grader's answer
key (autograder/answers/quiz.py) holds the right letters and why.

Each question is a variable of the quiz's notebook (``q3 = "b"``), one point each;
assignments/build.py writes a markdown cell and an answer cell per question.
"""

from __future__ import annotations

from course_lib.checks.multiple_choice import Question

_TOPIC_INFO = """
A plotter node shows nothing. You run `ros2 topic info /brightness -v`:

```
$ ros2 topic info /brightness -v
Type: std_msgs/msg/UInt8

Publisher count: 1

Node name: brightness_node
Topic type: std_msgs/msg/UInt8
Endpoint type: PUBLISHER
QoS profile:
  Reliability: BEST_EFFORT
  Durability: VOLATILE

Subscription count: 1

Node name: plotter
Topic type: std_msgs/msg/UInt8
Endpoint type: SUBSCRIPTION
QoS profile:
  Reliability: RELIABLE
  Durability: VOLATILE
```

Why does the plotter get no messages?
"""

_NODE_LIST = """
You run `ros2 node list`:

```
$ ros2 node list
/camera/image_publisher
/brightness_node
/brightness_node
```

What does this output say?
"""

_LAUNCH = """
The package `image_stats` has the launch file `dark.launch.xml`:

```xml
<launch>
  <arg name="threshold" default="60"/>
  <node pkg="image_stats" exec="dark_fraction" name="dark" namespace="robot1">
    <param name="dark.threshold" value="$(var threshold)"/>
    <remap from="image" to="/camera/image_raw"/>
  </node>
</launch>
```
"""

_TOPIC_HZ = """
`ros2 topic hz` on the camera's topic prints:

```
$ ros2 topic hz /camera/image_raw
average rate: 14.982
\tmin: 0.061s max: 0.074s std dev: 0.00310s window: 47
```

About how much time passes between two frames?
"""

_BAG_INFO = """
A recording of the camera and the brightness node, as `ros2 bag info` shows it:

```
$ ros2 bag info run1
Files:             run1_0.mcap
Bag size:          27.9 MiB
Storage id:        mcap
ROS Distro:        jazzy
Duration:          2.000000000s
Messages:          92
Topic information: Topic: /camera/image_raw | Type: sensor_msgs/msg/Image | Count: 61 | Serialization Format: cdr
                   Topic: /brightness | Type: std_msgs/msg/UInt8 | Count: 31 | Serialization Format: cdr
```
"""

#: The graded quiz: variable name -> question, in the order of the notebook.
QUIZ_QUESTIONS: dict[str, Question] = {
    "q1": Question("How do two ROS 2 nodes on one machine find each other?", {
        "a": "through `roscore`, which must run first",
        "b": "only through the `ros2 daemon`, which every node must register with when it starts",
        "c": "by discovery: nodes of one `ROS_DOMAIN_ID` announce themselves and connect directly",
        "d": "through the parameter server"}),
    "q2": Question(_TOPIC_INFO, {
        "a": "the types of the publisher and the subscription differ",
        "b": "the subscription's queue is too short",
        "c": "the plotter runs in another ROS domain, so it never meets the publisher",
        "d": "a reliable subscription does not match a best-effort publisher"}),
    "q3": Question("A node publishes a map once, at its start; nodes started later must still get it. "
                   "Which QoS does its publisher need (and the subscriptions alike)?", {
        "a": "reliable, transient local",
        "b": "best effort, volatile",
        "c": "the sensor-data profile",
        "d": "reliable, volatile, depth 1"}),
    "q4": Question("A camera publishes 1920×1080 frames at 30 Hz; one subscriber cannot keep up. "
                   "Which QoS suits the frames?", {
        "a": "reliable with a queue of 1000, so that no frame is lost",
        "b": "transient local, so that late subscribers get old frames",
        "c": "the sensor-data profile: best effort, keep the last few",
        "d": "any: QoS does not matter on one machine"}),
    "q5": Question(_NODE_LIST, {
        "a": "nothing unusual: each node is listed once per topic it publishes",
        "b": "two nodes have the same name, so `ros2 param` and their services cannot tell them apart",
        "c": "the brightness node restarted, and the old entry stays in the list until the daemon stops",
        "d": "the camera runs twice"}),
    "q6": Question(_LAUNCH + "\nWhat is the full name of the node it starts?", {
        "a": "`/dark_fraction`", "b": "`/dark`", "c": "`/image_stats/dark`", "d": "`/robot1/dark`"}),
    "q7": Question("With the same launch file, `ros2 launch image_stats dark.launch.xml threshold:=80` "
                   "gives the parameter `dark.threshold` which value?", {
        "a": "80", "b": "60", "c": "the string `$(var threshold)`", "d": "none: it is an error"}),
    "q8": Question("The same node publishes on the relative name `dark_fraction`. On which topic do its "
                   "messages appear?", {
        "a": "`/dark_fraction`", "b": "`/robot1/dark/dark_fraction`", "c": "`/robot1/dark_fraction`",
        "d": "`/camera/dark_fraction`"}),
    "q9": Question("`ros2 run brightness brightness_node` answers `No executable found`, though the package "
                   "built. What is the likely cause?", {
        "a": "`package.xml` does not list `rclpy`",
        "b": "the node's class is not called `BrightnessNode`, as the executable's name requires",
        "c": "the camera is not running",
        "d": "`setup.py` has no `brightness_node` entry in `console_scripts`"}),
    "q10": Question("A `sensor_msgs/Image` is 640×480, `mono8`, with `step` 640. How many bytes has `data`?", {
        "a": "640", "b": "307 200", "c": "921 600", "d": "480"}),
    "q11": Question(_TOPIC_HZ, {
        "a": "about 0.067 s", "b": "about 15 s", "c": "about 0.0031 s", "d": "47 ms"}),
    "q12": Question("How many point correspondences does `cv2.getPerspectiveTransform` need for a homography?", {
        "a": "2", "b": "3", "c": "4", "d": "8"}),
    "q13": Question("Which calls find a marker's picture upright in a camera frame?", {
        "a": "detect the markers, then `cv2.resize` the frame to the picture's size",
        "b": "detect the markers, `getPerspectiveTransform` from the picture's corners to a rectangle, "
             "then `warpPerspective`",
        "c": "detect the markers, then `cv2.rotate` the frame by the marker's angle and crop",
        "d": "detect the markers, `cv2.flip` the frame so that the picture is upright, then crop the "
             "markers' bounding box"}),
    "q14": Question(_BAG_INFO + "\nAt what rate did the camera's frames come in?", {
        "a": "92 Hz", "b": "61 Hz", "c": "about 15 Hz", "d": "about 30 Hz"}),
    "q15": Question(_BAG_INFO + "\nThe brightness node should answer every frame. What does the bag say?", {
        "a": "it answered about half of the frames",
        "b": "it answered every frame",
        "c": "it answered more often than the camera sent",
        "d": "nothing: a bag cannot tell"}),
    "q16": Question("A node turns the camera until both pictures are in view, which takes a few seconds; the "
                    "caller wants to see how far it got and must be able to stop it half-way. What should the "
                    "node offer?", {
        "a": "a topic the caller publishes the goal on",
        "b": "an action whose goal names the pictures",
        "c": "a service whose response says when the pictures are in view",
        "d": "a parameter the caller sets to the angle"}),
}
