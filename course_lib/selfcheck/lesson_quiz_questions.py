"""The questions of the lessons' short quizzes (ungraded), with their answers and why: the data
that :mod:`.lesson_quiz` shows and checks, keyed by the lesson's number ("00", "01b", ...)."""

from __future__ import annotations

import dataclasses

from course_lib.checks.multiple_choice import Question


@dataclasses.dataclass(frozen=True)
class Answered:
    """A lesson quiz's question with its right letter, why it is right (said to a right answer),
    and for each wrong letter why that choice is wrong (said to that answer; it never names the
    right one, so that a student tries again rather than copies)."""

    question: Question
    answer: str
    why: str
    wrong: dict[str, str]


LESSON_QUIZZES: dict[str, tuple[Answered, ...]] = {
    "00": (
        Answered(Question("What does ROS 2 use where ROS 1 needed `roscore`?", {
            "a": "a master process that `ros2 daemon start` starts, and every node registers with",
            "b": "the first node started, which then acts as the master",
            "c": "discovery: nodes of one `ROS_DOMAIN_ID` announce themselves and find each other",
            "d": "the parameter server"}),
            "c", "ROS 2 has no master: DDS discovery connects the nodes of one domain directly.", {
                "a": "The daemon only caches the graph for the `ros2` command; nodes find each other whether "
                     "it runs or not.",
                "b": "No node is special in ROS 2: there is no master, neither the first node nor another.",
                "d": "ROS 2 has no central parameter server: each node holds its own parameters, and they "
                     "play no part in how nodes meet."}),
        Answered(Question("After `colcon build`, a new terminal says `Package 'my_package' not found`. "
                          "What is missing?", {
            "a": "`source install/setup.bash` in that terminal",
            "b": "`colcon build` once more",
            "c": "`pip install my_package`",
            "d": "`ros2 pkg create my_package` once more, in that terminal"}),
            "a", "Each new shell must source the workspace's install/setup.bash to see its packages.", {
                "b": "The build worked, and another changes nothing: the new terminal does not know the "
                     "workspace yet.",
                "c": "A package of your workspace is found through the workspace's environment; pip does "
                     "not know it.",
                "d": "The package exists and is built; creating it again only fails, as its folder exists."}),
        Answered(Question("Which file declares the ROS packages that a package depends on?", {
            "a": "`setup.cfg`", "b": "`package.xml`", "c": "`resource/<package>`", "d": "`install/setup.bash`"}),
            "b", "package.xml lists the dependencies (`<depend>`); setup.py lists executables and installed "
                 "files.", {
                "a": "setup.cfg only tells setuptools where to install the scripts.",
                "c": "That file is an empty marker that puts the package into the ament index.",
                "d": "colcon writes that script, which sets up a shell's environment; it declares nothing."}),
    ),
    "01": (
        Answered(Question("A publisher is best effort and a subscription on its topic is reliable. What happens?", {
            "a": "the messages arrive reliably",
            "b": "both fall back to best effort",
            "c": "creating the subscription raises an error",
            "d": "the subscription receives nothing"}),
            "d", "A reliable subscription needs a reliable publisher: the two do not match (an incompatible "
                 "QoS). Best effort on both sides, or a best-effort subscription, would match.", {
                "a": "A best-effort publisher never sends a lost message again, so it cannot serve a "
                     "subscription that asks for that.",
                "b": "QoS is never lowered to make endpoints match: each keeps the profile it was created "
                     "with.",
                "c": "Creating it succeeds: endpoints compare their QoS only when they discover each other."}),
        Answered(Question("What does `ros2 run demo talker --ros-args -r chatter:=news` change?", {
            "a": "the node's name becomes news",
            "b": "the node publishes on `/news` instead of `/chatter`",
            "c": "it sets the node's parameter `chatter` to the value news",
            "d": "it starts a second talker called news"}),
            "b", "`-r from:=to` remaps a topic name; `-r __node:=name` would rename the node.", {
                "a": "`-r __node:=news` would rename the node; `chatter` is not the node's name.",
                "c": "Parameters are set with `-p name:=value`; `-r` is a remap.",
                "d": "`ros2 run` starts one process, and `--ros-args` adds no node to it."}),
        Answered(Question("Who calls a subscription's callback?", {
            "a": "your own `while True` loop",
            "b": "the publisher, inside its `publish()` call",
            "c": "an executor that spins the node, when a message has arrived",
            "d": "DDS, in a thread of its own, whether or not the node spins"}),
            "c", "Callbacks run only while an executor spins the node (`rclpy.spin`, or the notebook's "
                 "session).", {
                "a": "A loop of your own never calls a callback; without spinning, messages wait in the queue.",
                "b": "publish() hands the message to the middleware; the subscriber may be in another process.",
                "d": "DDS only stores the message; nothing runs your callback unless the node is spun."}),
    ),
    "01b": (
        Answered(Question("Why does the `MsgTutorial` message live in a package of its own?", {
            "a": "an `ament_cmake` package generates it, and other packages use it without depending on a node",
            "b": "colcon builds one message per package",
            "c": "Python cannot import a message from the package it is in",
            "d": "a message package builds faster on its own than in a package that also holds the Python nodes"}),
            "a", "Interface packages are ament_cmake (rosidl_generate_interfaces); nodes stay in "
                 "ament_python packages that depend on them.", {
                "b": "A package may hold many messages: std_msgs holds dozens.",
                "c": "A built message imports the same way from any package, its own included.",
                "d": "Speed is not the reason: the build time hardly changes."}),
        Answered(Question("You add a field to `msg/MsgTutorial.msg`. What must happen before a node can send it?", {
            "a": "nothing: each node reads the .msg file again when it starts, and sends the new field",
            "b": "only restart the nodes",
            "c": "edit the nodes' `setup.py`",
            "d": "build the interface package again, then restart the nodes that use it"}),
            "d", "The message's Python and C code are generated at build time.", {
                "a": "Nodes never read the .msg file: they import code generated from it.",
                "b": "A restarted node imports the same generated code as before, without the new field.",
                "c": "setup.py lists the node package's executables and files; the message is defined "
                     "elsewhere."}),
        Answered(Question("What does the line `builtin_interfaces/Time stamp` in a .msg file declare?", {
            "a": "a comment, as a line with a slash is",
            "b": "a field named `stamp` of the type `Time` of the package builtin_interfaces",
            "c": "a constant named `stamp` of the type `Time`",
            "d": "a dependency on the package builtin_interfaces, which declares no field of its own"}),
            "b", "Each line is `type name`; a type from another package is written `package/Type`.", {
                "a": "A comment in a .msg file starts with `#`.",
                "c": "A constant has a value after an equals sign (`int32 LIMIT=5`); this line has none.",
                "d": "Dependencies are declared in package.xml and CMakeLists.txt, not in a message "
                     "definition."}),
    ),
    "02": (
        Answered(Question("A `sensor_msgs/Image` is 640×480, `bgr8`, with `step` 1920. How many bytes has `data`?", {
            "a": "307 200", "b": "921 600", "c": "1 920", "d": "640"}),
            "b", "step × height = 1920 × 480 = 921 600 (3 bytes a pixel, no row padding).", {
                "a": "That would be one byte a pixel, as in mono8; bgr8 has three.",
                "c": "1 920 is step, the bytes of one row; data holds all 480 rows.",
                "d": "640 is the width in pixels: neither the bytes of a row nor those of the image."}),
        Answered(Question("Why do the camera frames travel with the sensor-data QoS?", {
            "a": "it keeps every frame until each subscriber has it, so that none is ever lost",
            "b": "it compresses the images",
            "c": "best effort with a small queue: a slow subscriber skips old frames",
            "d": "ROS 2 requires it for `sensor_msgs`"}),
            "c", "Sensor data wants the newest sample, not all of them: best effort, keep last 5.", {
                "a": "Keeping every frame is reliable delivery with a deep queue, which holds a slow "
                     "subscriber ever further behind.",
                "b": "QoS says how messages are delivered, never how they are encoded.",
                "d": "Any QoS works with any message type: the profile is a choice that suits sensors."}),
        Answered(Question("Why does the brightness node use numpy rather than a Python loop over the bytes?", {
            "a": "numpy is about 70 times faster, so the node keeps up with 30 frames a second",
            "b": "the loop computes another value",
            "c": "a ROS 2 node must compute with numpy, as rclpy hands every message over as arrays",
            "d": "a loop cannot read `msg.data`"}),
            "a", "Both give the same number; only numpy's sum is fast enough for the camera's rate.", {
                "b": "Both compute the same mean: the lesson compared them side by side.",
                "c": "A node may compute as it likes; rclpy does not require numpy.",
                "d": "msg.data is a sequence of bytes that a loop can read: the lesson's first version did."}),
    ),
    "02b": (
        Answered(Question("You added a launch file to `data_files` in `setup.py`. What do you run before "
                          "`ros2 launch` finds it?", {
            "a": "nothing: `--symlink-install` links every file",
            "b": "`ros2 pkg create` again",
            "c": "a new terminal",
            "d": "`colcon build` again"}),
            "d", "A new installed file (or a change of setup.py) needs a build; --symlink-install only "
                 "spares rebuilding for changes of files already installed.", {
                "a": "`--symlink-install` links the files the last build installed; a file added since was "
                     "not installed then.",
                "b": "That makes a new package; yours exists already.",
                "c": "A new terminal sources the same install folder, which does not hold the new file yet."}),
        Answered(Question("In a node named `dark_fraction`, which topic is `~/frames`?", {
            "a": "`/dark_fraction/frames`", "b": "`/frames`", "c": "`~/frames`, literally", "d": "a parameter"}),
            "a", "`~` stands for the node's own name: a private name.", {
                "b": "The `~` is not dropped: it stands for a name.",
                "c": "A resolved ROS name holds no `~`: it is replaced when the name is resolved.",
                "d": "`~/frames` is a topic here; a parameter's name has no `~`."}),
        Answered(Question('What does `<remap from="image" to="/camera/image_raw"/>` inside a launch file\'s '
                          "`<node>` do?", {
            "a": "it renames the node",
            "b": "the node publishes on both `image` and `/camera/image_raw`",
            "c": "the node's topic `image` becomes `/camera/image_raw`",
            "d": "it starts a camera"}),
            "c", "A remap in a launch file is `-r image:=/camera/image_raw` on the command line.", {
                "a": "A node is renamed by the `name` attribute of `<node>` (or `-r __node:=`).",
                "b": "A remap replaces a name: the node uses one of the two, not both.",
                "d": "Only `<node>` and `<executable>` start processes; a remap changes a name."}),
    ),
    "03": (
        Answered(Question("How many point correspondences does `cv2.getPerspectiveTransform` take?", {
            "a": "3", "b": "8", "c": "exactly 4", "d": "any number of at least 2"}),
            "c", "A homography has 8 unknowns; 4 point pairs give 8 equations. findHomography takes 4 or more.", {
                "a": "3 pairs give 6 equations for the 8 unknowns of a homography; `getAffineTransform` is "
                     "the one that takes 3.",
                "b": "8 is the number of unknowns of a homography, and each point pair gives two equations.",
                "d": "Too few pairs leave the homography undetermined, and this function takes no more "
                     "pairs than it needs."}),
        Answered(Question("What does `cv2.findHomography(src, dst, cv2.RANSAC)` add over `getPerspectiveTransform`?", {
            "a": "nothing: it is the same function",
            "b": "it finds the markers in the frame itself, so no detector is needed",
            "c": "it warps the picture",
            "d": "it takes more than 4 pairs and leaves out those that do not fit"}),
            "d", "RANSAC fits many pairs at once and ignores the wrong ones.", {
                "a": "They take different inputs and give different results when one of the pairs is wrong.",
                "b": "It takes point pairs that you found; finding the markers is the detector's job.",
                "c": "It returns only the 3×3 matrix; `warpPerspective` warps with it."}),
        Answered(Question("In which order does OpenCV give the four corners of a detected ArUco marker?", {
            "a": "counter-clockwise, starting at the picture's bottom-left corner",
            "b": "clockwise, starting at the marker's own top-left corner",
            "c": "sorted by x, then y, in the picture",
            "d": "in any order"}),
            "b", "The order follows the marker, not the picture: a turned marker's corner 0 is still its top-left.", {
                "a": "Neither the direction nor the first corner is that; lesson 03 draws the corners' "
                     "numbers.",
                "c": "The order follows the marker, not the picture: turn the marker and its corner 0 turns "
                     "with it.",
                "d": "The order is fixed; the course relies on it to tell which corner of a marker touches "
                     "the picture."}),
    ),
    "04": (
        Answered(Question("A node should answer \"which markers would the camera see at 30 degrees?\" at once. "
                          "Which pattern fits?", {
            "a": "a service: one request, one response",
            "b": "a topic the node publishes on at 10 Hz",
            "c": "an action with feedback",
            "d": "a parameter"}),
            "a", "A quick question with one answer is a service; an action is for jobs that take a while.", {
                "b": "A topic answers no question: the caller could only wait for the next message, and "
                     "could not ask about an angle of its own.",
                "c": "An action is for a job that takes a while; an answer that is ready at once needs "
                     "neither feedback nor cancel.",
                "d": "A parameter configures a node; setting or reading one asks the camera nothing."}),
        Answered(Question("An action server's `execute` runs for seconds; the node is spun by `rclpy.spin(node)` "
                          "(one thread). What happens to a cancel request sent meanwhile?", {
            "a": "it stops the goal at once",
            "b": "it raises an exception in the client",
            "c": "it waits until `execute` has returned",
            "d": "it is lost"}),
            "c", "One thread runs one callback at a time: the cancel callback runs only after execute ended. "
                 "A MultiThreadedExecutor and a ReentrantCallbackGroup let it in while execute runs.", {
                "a": "The cancel request is handled by a callback too, and the node's one thread is busy "
                     "with execute.",
                "b": "The client sends its request without an error; what is late is the server's answer.",
                "d": "Nothing drops the request: the middleware keeps it for the node."}),
        Answered(Question("What does `ros2 action send_goal --feedback /find_pictures "
                          "camera_interfaces/action/FindPictures \"{pictures: [cat]}\"` print before the result?", {
            "a": "nothing", "b": "the goal's type definition, with its goal, result and feedback fields",
            "c": "the list of action servers",
            "d": "each feedback message the server publishes while the goal runs"}),
            "d", "--feedback prints every feedback message; then the result and the goal's final status.", {
                "a": "`--feedback` is an option that adds output to what send_goal prints without it.",
                "b": "`ros2 interface show` prints a type's definition; send_goal sends a goal.",
                "c": "`ros2 action list` lists the action servers; send_goal talks to one of them."}),
    ),
    "05": (
        Answered(Question("What does `ros2 bag record -o run1 /camera/image_raw /brightness` write on Jazzy?", {
            "a": "one file `run1.bag`",
            "b": "a folder `run1` with `metadata.yaml` and `run1_0.mcap`",
            "c": "a CSV file per topic",
            "d": "nothing yet: the bag is written only when `ros2 bag info` reads it"}),
            "b", "A rosbag2 bag is a folder: the metadata and the storage files (MCAP, Jazzy's default).", {
                "a": "A single .bag file is a ROS 1 bag; rosbag2 writes more than one file.",
                "c": "A bag holds the messages serialized (CDR), not as text.",
                "d": "`ros2 bag info` only reads a bag; the recorder writes the messages as they come."}),
        Answered(Question("Why does a replayed bag make a node's test repeatable?", {
            "a": "a bag plays faster than the camera, so the test ends before the machine gets busy",
            "b": "a bag makes DDS reliable, so no message is ever lost",
            "c": "the node needs no spinning while a bag plays",
            "d": "the node gets the same messages every run, so its answers can be compared"}),
            "d", "The same input gives the same output: the bag fixes the input, the test compares the output.", {
                "a": "A test that ends sooner is not repeatable for that; and a bag plays at the recorded "
                     "rate unless told otherwise.",
                "b": "A bag plays with the recorded QoS: delivery is no more reliable than the camera's.",
                "c": "The node spins as always: a replayed message reaches it through the same subscription."}),
        Answered(Question("`ros2 bag play --loop run1 --topics /camera/image_raw` runs while the brightness node "
                          "runs. What happens?", {
            "a": "the node gets the recorded frames again and again and publishes their brightness",
            "b": "the node gets the frames, and the bag's recorded `/brightness` values are played as well",
            "c": "nothing: the node needs the camera",
            "d": "the play stops after the first pass"}),
            "a", "--topics plays only the frames; --loop starts again at the end until Ctrl-C.", {
                "b": "`--topics` plays only the topics it names.",
                "c": "The node subscribes to a topic, not to a camera: a player's messages serve as well.",
                "d": "`--loop` starts the play again at its end, until Ctrl-C."}),
    ),
    "06": (
        Answered(Question("A LaserScan has `angle_min` = -2.356, `angle_increment` = 0.00873 (half a degree) and "
                          "541 ranges. Where does `ranges[100]` point?", {
            "a": "at 0.873 rad (100 × angle_increment), to the left",
            "b": "at -1.483 rad (angle_min + 100 × angle_increment), to the right",
            "c": "at 100°, to the left",
            "d": "straight ahead: the beams are counted from the middle"}),
            "b", "Beam i points at angle_min + i × angle_increment; a negative angle is to the right (REP 103).", {
                "a": "Beam 0 points at angle_min, not at 0 rad: the angle of beam 100 starts from there.",
                "c": "ROS angles are in radians, and beam 0 is not straight ahead.",
                "d": "Beam 0 is the first beam of the sweep, at angle_min, and the beams count up from there."}),
        Answered(Question("A node answers each scan with one `/cmd_vel`, and the simulator runs with "
                          "`lock_step:=true`. Why does the drive end at the same place on a busy machine as on "
                          "an idle one?", {
            "a": "lock-step makes DDS deliver the messages faster",
            "b": "the simulator follows the wall clock more closely",
            "c": "the node reads the computer's clock instead of `/clock`",
            "d": "the simulator advances one tick only after the answer to each scan has come"}),
            "d", "The robot never moves on before the node has answered, so the node sees the same scans and sends "
                 "the same commands, however slowly it answers.", {
                "a": "Lock-step changes nothing in how DDS delivers; the messages take as long as they take.",
                "b": "Lock-step does the opposite: the simulated time no longer follows the wall clock at all.",
                "c": "A node that works with a simulator should read /clock (use_sim_time); the computer's clock is "
                     "what differs from one run to the next."}),
        Answered(Question("`buffer.lookup_transform(\"odom\", \"laser\", Time())` returns a transform. What is its "
                          "translation?", {
            "a": "where the laser is in the odom frame, now",
            "b": "where odom's origin is in the laser's frame, now",
            "c": "how far the robot has driven since the last scan",
            "d": "where the laser was when the simulator started (time zero)"}),
            "a", "lookup_transform(target, source, time) carries points from source to target: its translation is "
                 "the source frame's origin in the target frame. Time() asks for the newest.", {
                "b": "The first frame named is the target, the second the source: this asks the other way round.",
                "c": "A transform is a pose between two frames, not a distance driven; the odometry's twist holds "
                     "the robot's speed.",
                "d": "Time() (zero) asks for the newest transform the buffer has, not for the one at time zero."}),
    ),
}
