"""Answer key of the quiz: the right letter of each question and why, which the feedback of a
wrong answer shows (the questions: course_lib/checks/quiz_questions.py)."""

KEY = {
    "q1": ("b", "ROS 2 has no master such as ROS 1's roscore: the middleware's (DDS) discovery connects "
                "the nodes of one ROS_DOMAIN_ID directly; the daemon only caches the graph for the ros2 command."),
    "q2": ("b", "The publisher offers BEST_EFFORT and the subscription asks for RELIABLE: a reliable "
                "subscription needs a reliable publisher, so the two never connect. Make the plotter best "
                "effort (or the sensor-data QoS); the type and the domain are the same on both sides."),
    "q3": ("b", "Transient local keeps the last messages for subscriptions that join later, and it needs "
                "reliable delivery; volatile publishers forget a message once it is sent."),
    "q4": ("b", "For a stream of sensor data the newest sample counts: best effort with a small queue lets "
                "a slow subscriber skip frames, where a reliable queue of 1000 would hold it ever further behind."),
    "q5": ("a", "Node names must be unique: two nodes named /brightness_node make `ros2 param` and the "
                "node's services ambiguous. Start one with `--ros-args -r __node:=other_name`."),
    "q6": ("b", "name=\"dark\" renames the node and namespace=\"robot1\" puts it in a namespace: /robot1/dark. "
                "The executable's name and the package's name are not part of it."),
    "q7": ("b", "A launch argument given on the command line (threshold:=80) replaces its default, and "
                "$(var threshold) is replaced by its value."),
    "q8": ("b", "A relative name is resolved in the node's namespace: dark_fraction becomes "
                "/robot1/dark_fraction (only `~/name` would add the node's name). The remap changes image only."),
    "q9": ("a", "`ros2 run` starts the executables that setup.py's console_scripts entry points install; "
                "without the entry (or without a new build after adding it) there is none to find."),
    "q10": ("b", "data holds step × height bytes: 640 × 480 = 307 200 (one byte a pixel in mono8)."),
    "q11": ("b", "The average rate is about 15 messages a second, so 1/15 ≈ 0.067 s between frames (min 0.061 s, "
                 "max 0.074 s); the std dev is the spread, the window the number of messages."),
    "q12": ("c", "A homography has 8 unknowns and each point pair gives 2 equations: 4 pairs. "
                 "cv2.findHomography takes 4 or more (with RANSAC against outliers)."),
    "q13": ("a", "The picture's corners in the frame and the corners of an upright rectangle give the "
                 "homography; warpPerspective maps the picture onto that rectangle. A resize, rotation or "
                 "flip cannot undo a perspective."),
    "q14": ("b", "61 frames in 2 s of recording: about 30 frames a second. 92 counts the messages of both topics."),
    "q15": ("a", "31 brightness values for 61 frames: the node answered about every second frame (too slow "
                 "a callback, or a frame dropped on the way); it should be about 61."),
    "q16": ("c", "A long task with progress and a way to stop it is an action (lesson 04): the goal starts it, "
                 "feedback says how far it got, cancel stops it, the result ends it. A service call blocks until "
                 "its one response and cannot be stopped; a topic or a parameter has no reply at all."),
}


def explain(question: str, answer: str) -> str | None:
    """None when `answer` (a letter, lower case) is right for `question`, else why it is not and
    what is: the feedback of the wrong answer."""
    right, why = KEY[question]
    return None if answer == right else f"the answer is {right}: {why}"
