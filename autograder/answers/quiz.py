"""Answer key of the quiz: the right letter of each question, why it is right, and for each wrong
letter why that choice is wrong (the feedback of a wrong answer, which never names the right one:
a student who grades again learns why a choice fails, not which to pick). The questions:
course_lib/checks/quiz_questions.py."""

from __future__ import annotations

from typing import NamedTuple


class Key(NamedTuple):
    """One question's key: the right letter, why it is right, and wrong letter -> why it is wrong."""

    answer: str
    why: str
    wrong: dict[str, str]


KEY = {
    "q1": Key("c", "ROS 2 has no master such as ROS 1's roscore: the middleware's (DDS) discovery connects the "
                   "nodes of one ROS_DOMAIN_ID directly; the daemon only caches the graph for the ros2 command.", {
        "a": "roscore is ROS 1's master; ROS 2 has no master, and its nodes run without one.",
        "b": "The ros2 daemon merely caches the graph for the command line; nodes connect whether it runs "
             "or not.",
        "d": "Each ROS 2 node keeps its own parameters: there is no central parameter server, and parameters "
             "play no part in how nodes connect."}),
    "q2": Key("d", "The publisher offers BEST_EFFORT and the subscription asks for RELIABLE: a reliable "
                   "subscription needs a reliable publisher, so the two never connect. Make the plotter best "
                   "effort (or the sensor-data QoS).", {
        "a": "Both endpoints show the type std_msgs/msg/UInt8: the types are the same.",
        "b": "A short queue drops old messages when the subscriber is slow, but some would still arrive; "
             "here none do. Compare the two QoS profiles.",
        "c": "ros2 topic info lists the endpoints of its own domain only, and it lists the plotter: both "
             "are in one domain."}),
    "q3": Key("a", "Transient local keeps the last messages for subscriptions that join later, and it needs "
                   "reliable delivery; volatile publishers forget a message once it is sent.", {
        "b": "Volatile keeps nothing for a subscription that joins later, and best effort may drop the one "
             "message besides.",
        "c": "The sensor-data profile is volatile: made for streams where the newest sample counts, it keeps "
             "nothing for a subscription that joins later.",
        "d": "Reliable delivers to the subscriptions that exist when it publishes; volatile keeps nothing for "
             "those that join later, whatever the depth."}),
    "q4": Key("c", "For a stream of sensor data the newest sample counts: best effort with a small queue lets "
                   "a slow subscriber skip frames, where a reliable queue of 1000 would hold it ever further "
                   "behind.", {
        "a": "A reliable queue of 1000 frames holds a slow subscriber ever further behind the camera (and "
             "about 6 GB of frames): an old frame is worth little.",
        "b": "A subscriber wants the current frame, not old ones; keeping frames for late subscribers only "
             "costs memory, and it does not help one that cannot keep up.",
        "d": "QoS decides which endpoints match and what happens when a reader falls behind, on one machine "
             "as on many."}),
    "q5": Key("b", "Node names must be unique: two nodes named /brightness_node make `ros2 param` and the "
                   "node's services ambiguous. Start one with `--ros-args -r __node:=other_name`.", {
        "a": "ros2 node list lists each node once, whatever it publishes.",
        "c": "A node that has ended leaves the graph: every entry of the list is a node that runs now.",
        "d": "The camera's node, /camera/image_publisher, is listed once."}),
    "q6": Key("d", "name=\"dark\" renames the node and namespace=\"robot1\" puts it in a namespace: /robot1/dark. "
                   "The executable's name and the package's name are not part of it.", {
        "a": "dark_fraction is the executable's name; the name attribute of the node tag renames the node.",
        "b": "That leaves out the namespace attribute of the node tag, which puts the node in a namespace.",
        "c": "A package's name is never part of a node's name."}),
    "q7": Key("a", "A launch argument given on the command line (threshold:=80) replaces its default, and "
                   "$(var threshold) is replaced by its value.", {
        "b": "60 is only the argument's default: a value given on the command line replaces it.",
        "c": "Launch performs the substitution $(var threshold): the parameter gets the argument's value, "
             "not the text.",
        "d": "threshold is an argument the file declares, so the command line may give it."}),
    "q8": Key("c", "A relative name is resolved in the node's namespace: dark_fraction becomes "
                   "/robot1/dark_fraction (only `~/name` would add the node's name). The remap changes image "
                   "only.", {
        "a": "A relative name is resolved in the node's namespace, which the launch file sets; only a name "
             "that starts with a slash stays as written.",
        "b": "Only a private name (~/dark_fraction) would add the node's own name; a relative name is "
             "resolved in the namespace alone.",
        "d": "The remap in the launch file changes the topic image only; the node's other names stay as "
             "they were."}),
    "q9": Key("d", "`ros2 run` starts the executables that setup.py's console_scripts entry points install; "
                   "without the entry (or without a new build after adding it) there is none to find.", {
        "a": "A dependency missing from package.xml does not stop ros2 run from finding an executable; at "
             "worst the node fails where rclpy is not installed.",
        "b": "ros2 run looks for an executable by its name; the class inside the module may be called "
             "anything.",
        "c": "ros2 run finds an executable whether or not other nodes run; without a camera the node would "
             "only get no frames."}),
    "q10": Key("b", "data holds step × height bytes: 640 × 480 = 307 200 (one byte a pixel in mono8).", {
        "a": "640 is step, the bytes of one row; data holds every row.",
        "c": "That would be three bytes a pixel, as in rgb8 or bgr8; mono8 has one.",
        "d": "480 is the height, the number of rows; each of them has step bytes."}),
    "q11": Key("a", "The average rate is about 15 messages a second, so 1/15 ≈ 0.067 s between frames (min "
                    "0.061 s, max 0.074 s); the std dev is the spread, the window the number of messages.", {
        "b": "About 15 is the average rate: messages a second, not seconds between them.",
        "c": "0.0031 s is the standard deviation: how much the gaps vary, not how long they are.",
        "d": "47 is the window: the number of messages the figures were computed over."}),
    "q12": Key("c", "A homography has 8 unknowns and each point pair gives 2 equations: 4 pairs. "
                    "cv2.findHomography takes 4 or more (with RANSAC against outliers).", {
        "a": "A homography has 8 unknowns and each point pair gives 2 equations: 2 pairs leave it "
             "undetermined.",
        "b": "Three point pairs fix an affine transform (cv2.getAffineTransform); a homography has 8 "
             "unknowns, and three pairs give only 6 equations.",
        "d": "A homography has 8 unknowns, and every point pair gives two equations: 8 pairs are more than "
             "it needs."}),
    "q13": Key("b", "The picture's corners in the frame and the corners of an upright rectangle give the "
                    "homography; warpPerspective maps the picture onto that rectangle. A resize, rotation or "
                    "flip cannot undo a perspective.", {
        "a": "A resize scales the whole frame: the picture stays where it is, turned and seen at an angle.",
        "c": "A rotation undoes a turn in the image plane only: a picture seen at an angle stays a skewed "
             "quadrilateral.",
        "d": "A flip mirrors the frame; neither it nor a crop undoes the perspective of a picture seen at an "
             "angle."}),
    "q14": Key("d", "61 frames in 2 s of recording: about 30 frames a second. 92 counts the messages of both "
                    "topics.", {
        "a": "92 counts the messages of both topics, and a count is not yet a rate: divide by the duration.",
        "b": "61 is how many frames the bag holds; a rate divides that count by the bag's duration.",
        "c": "About 15 frames a second over the bag's duration would make about half the frames it "
             "holds."}),
    "q15": Key("a", "31 brightness values for 61 frames: the node answered about every second frame (too slow "
                    "a callback, or a frame dropped on the way); it should be about 61.", {
        "b": "Compare the counts of the two topics: a node that answers every frame publishes as many "
             "values as there are frames.",
        "c": "The bag holds fewer brightness values than frames.",
        "d": "A bag records each topic's messages with their times: their counts can be compared."}),
    "q16": Key("b", "A long task with progress and a way to stop it is an action (lesson 04): the goal starts "
                    "it, feedback says how far it got, cancel stops it, the result ends it. A service call "
                    "blocks until its one response and cannot be stopped; a topic or a parameter has no reply "
                    "at all.", {
        "a": "Publishing on a topic gets no reply: the caller would see neither progress nor the end, and "
             "could not stop it.",
        "c": "A service call has one response, at the end: no progress on the way, and it cannot be stopped "
             "half-way.",
        "d": "Setting a parameter returns at once; it reports no progress and offers no way to stop the "
             "turn."}),
}


def explain(question: str, answer: str) -> str | None:
    """None when `answer` (a letter, lower case) is right for `question`, else why that choice is
    wrong: the feedback of the wrong answer, which does not name the right one."""
    key = KEY[question]
    return None if answer == key.answer else key.wrong[answer]
