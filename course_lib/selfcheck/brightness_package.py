"""The exercise of lesson 02: the brightness node as the package ``brightness``, built, and its node
run as ``ros2 run brightness brightness_node --ros-args -r /image:=...``. The static problems
are named before anything is started.
"""

from __future__ import annotations

from course_lib import progress
from course_lib.selfcheck.verdicts import Verdict, _verdict

#: The package and executable of lesson 02's exercise (the brightness assignment asks for the
#: same package, in its own notebook).
BRIGHTNESS_PACKAGE = "brightness"
BRIGHTNESS_EXECUTABLE = "brightness_node"
BRIGHTNESS_ENTRY_POINT = f"{BRIGHTNESS_EXECUTABLE} = {BRIGHTNESS_PACKAGE}.{BRIGHTNESS_EXECUTABLE}:main"

#: Python modules a node may import that are no ROS packages, and the package.xml (rosdep) key of each.
PYTHON_DEPENDENCIES = {"numpy": "python3-numpy", "cv2": "python3-opencv", "yaml": "python3-yaml"}

#: The topic the check remaps /image to: not the lesson's /camera/image_raw, so that a node that
#: names the camera topic itself instead of subscribing `image` is caught.
CHECK_CAMERA_TOPIC = "/selfcheck/camera"

_BUILD_COMMAND = "cd {ws} && colcon build --symlink-install --packages-select brightness"


def _calls(tree, attribute: str) -> bool:
    import ast

    return any(isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == attribute
               for node in ast.walk(tree))


def _package_files(ws) -> Verdict | None:
    """The static part of the brightness package check: files, imports against package.xml, the entry point."""
    import ast

    from course_lib.ros import ament, package_files

    package_dir = ws / "src" / BRIGHTNESS_PACKAGE
    node_file = package_dir / BRIGHTNESS_PACKAGE / f"{BRIGHTNESS_EXECUTABLE}.py"
    if not (package_dir / "package.xml").is_file():
        return _verdict(False, f"Not done yet: there is no package {BRIGHTNESS_PACKAGE} in {ws / 'src'}. Run the cell "
                               "with `ros2 pkg create` (in the workspace's src/ folder).")
    if not node_file.is_file():
        return _verdict(False, f"Not done yet: {node_file.relative_to(ws)} does not exist. Run the %%writefile cell "
                               "of the node (the node file goes in the package's inner folder of the same name).")
    try:
        tree = ast.parse(node_file.read_text(), str(node_file))
    except SyntaxError as error:
        return _verdict(False, f"{node_file.name} has a syntax error in line {error.lineno}: {error.msg}.")
    missing = [what for what, call in (("subscription", "create_subscription"), ("publisher", "create_publisher"))
               if not _calls(tree, call)]
    if missing:
        return _verdict(False, f"Not done yet: {node_file.name} creates no {' and no '.join(missing)} (the TODOs in "
                               "BrightnessNode.__init__).")
    try:
        declared = package_files.run_dependencies(package_dir / "package.xml")
    except Exception as error:  # ElementTree.ParseError, and what a mangled file may raise
        return _verdict(False, f"package.xml cannot be read ({error}): run `ros2 pkg create` again in a fresh folder, "
                               "or mend the line it names.")
    ros_packages = ament.packages()
    for module, line in package_files.imported_modules(tree).items():
        needed = module if module in ros_packages else PYTHON_DEPENDENCIES.get(module)
        if needed and module != BRIGHTNESS_PACKAGE and needed not in declared:
            return _verdict(False, f"{node_file.name} imports {module} (line {line}), but package.xml does not "
                                   f"declare it: add <depend>{needed}</depend> next to the others (`ros2 pkg create "
                                   "--dependencies ...` writes these lines). Without it the package builds here, "
                                   "but rosdep and colcon on a robot do not know the node needs it.")
    if not any(isinstance(node, ast.FunctionDef) and node.name == "main" for node in tree.body):
        return _verdict(False, f"{node_file.name} has no function main(args=None): the executable calls it.")
    try:
        scripts = package_files.console_scripts(package_dir / "setup.py")
    except (OSError, SyntaxError) as error:
        return _verdict(False, f"setup.py cannot be read: {error}.")
    wanted = f"{BRIGHTNESS_PACKAGE}.{BRIGHTNESS_EXECUTABLE}:main"
    if BRIGHTNESS_EXECUTABLE not in scripts:
        others = [name for name, target in scripts.items() if target == wanted]
        if others:
            return _verdict(False, f"setup.py calls the executable {others[0]!r}; `ros2 run {BRIGHTNESS_PACKAGE} "
                                   f"{BRIGHTNESS_EXECUTABLE}` needs it to be called {BRIGHTNESS_EXECUTABLE!r} "
                                   "(the name left of the = in console_scripts).")
        return _verdict(False, f"Not done yet: setup.py has no executable {BRIGHTNESS_EXECUTABLE}. Add an entry for "
                               "it to the list of 'console_scripts': 'executable = module:function', where the "
                               "module is the node file's (package folder, a dot, file name without .py) and the "
                               "function the one the executable calls.")
    target = scripts[BRIGHTNESS_EXECUTABLE]
    if target != wanted:
        module, colon, function = target.partition(":")
        if not colon:
            why = "it needs a colon between the module and the function"
        elif module != f"{BRIGHTNESS_PACKAGE}.{BRIGHTNESS_EXECUTABLE}":
            why = (f"the node file's module is {BRIGHTNESS_PACKAGE}.{BRIGHTNESS_EXECUTABLE} (package folder, then "
                   f"file name without .py), not {module}")
        else:
            why = f"the function to call is main, not {function}"
        return _verdict(False, f"setup.py runs {target!r} for {BRIGHTNESS_EXECUTABLE}: {why}.")
    return None


def _entries(scripts: dict[str, str]) -> str:
    return ", ".join(f"{name} = {target}" for name, target in sorted(scripts.items())) or "none"


def _build_state(ws) -> Verdict | None:
    """Is what ros2 run would start built from the current files?"""
    from course_lib.ros import package_files

    install = ws / "install" / BRIGHTNESS_PACKAGE
    build = _BUILD_COMMAND.format(ws=ws)
    if not install.is_dir():
        return _verdict(False, f"The package is not built yet: run the colcon build cell ({build}).")
    script = install / "lib" / BRIGHTNESS_PACKAGE / BRIGHTNESS_EXECUTABLE
    if not script.is_file():
        return _verdict(False, f"setup.py names {BRIGHTNESS_EXECUTABLE}, but the last build did not install it: build "
                               f"again ({build}). A new or changed executable always needs a build, also with "
                               "--symlink-install.")
    source = ws / "src" / BRIGHTNESS_PACKAGE
    # A %%writefile cell run again rewrites setup.py with the same text: what counts is whether the
    # executables it declares are those the build installed.
    if (source / "setup.py").stat().st_mtime > script.stat().st_mtime + 0.5:
        declared = package_files.console_scripts(source / "setup.py")
        built = package_files.built_console_scripts(ws, BRIGHTNESS_PACKAGE)
        if built != declared:
            return _verdict(False, f"setup.py changed after the last build: its executables are "
                                   f"{_entries(declared)}, the build installed {_entries(built or {})}. Build again "
                                   f"({build}); changes to setup.py need a build, also with --symlink-install.")
    node_file = f"{BRIGHTNESS_EXECUTABLE}.py"
    for copy in install.glob(f"lib/python*/site-packages/{BRIGHTNESS_PACKAGE}/{node_file}"):
        if not copy.is_symlink() and copy.read_bytes() != (source / BRIGHTNESS_PACKAGE / node_file).read_bytes():
            return _verdict(False, f"The installed copy of {node_file} is not the one you wrote last: the workspace "
                                   f"was built without --symlink-install, so build again after every change "
                                   f"({build}).")
    return None


def _send_until_answered(probe, process, camera, msg, replies: list, expected: int) -> None:
    """Publish the frame `msg` on `camera` until the node process answers (into `replies`) or ends;
    when its first answer is missing or wrong, wait for a right answer or its end, as long as it
    computes."""
    from course_lib.checks.student_server import ProcessorTime

    replies.clear()
    for _ in range(6):  # sent again until answered: the first frames may come before discovery ends
        camera.publish(msg)
        if probe.spin_until(lambda: replies or not process.running(), 0.5):
            break
    if not replies or replies[0] != expected:
        # A node that fails on a frame takes a moment to end (publish() with a numpy integer in
        # UInt8.data even sends 255 before it raises), a busy machine's more: wait until it has
        # ended, answered right, or waits for frames without answering (processor time, not a
        # clock, tells).
        idle = ProcessorTime(process)
        probe.spin_until(lambda: (replies and replies[0] == expected) or not process.running()
                         or idle.waiting(), 60.0)


def _test_frames():
    """bgr8 frames 80 wide and 60 high whose centre pixels (row 30, column 40) differ, with what the exercise's
    node should answer for each: the first channel (blue) of the centre pixel."""
    import numpy as np

    rng = np.random.default_rng(2)
    frames = []
    for blue, green, red in ((17, 140, 230), (201, 33, 90), (90, 250, 5)):
        frame = rng.integers(0, 256, (60, 80, 3), dtype=np.uint8)
        frame[30, 40] = (blue, green, red)
        frames.append((frame, blue))
    return frames


def _wrong_value_hint(frame, value) -> str:
    """Why a node may have answered `value` for a frame: the answers of common slips."""
    import numpy as np

    slips = [
        (int(frame[40, 30, 0]), "the pixel at row 40, column 30: numpy indexes [row, column], so the centre is "
                                "frame[height // 2, width // 2]"),
        (int(frame[30, 40, 2]), "the red value, the last channel: bgr8 stores blue first, so take channel 0"),
        (int(frame[30, 40, 1]), "the green value: take channel 0 (blue)"),
        (int(frame.sum(dtype=np.uint64)) // frame.size, "the average brightness: that is the assignment's job; this "
                                                        "exercise publishes the centre pixel's first channel"),
        (int(round(float(frame.mean()))), "the average brightness: that is the assignment's job; this exercise "
                                         "publishes the centre pixel's first channel"),
    ]
    return next((f" {value} is {why}." for expected, why in slips if expected == value), "")


def _node_endpoints(probe, name: str, namespace: str) -> tuple[dict, dict]:
    """({topic: [types]} of the subscriptions, and of the publishers) of a node, without ROS's own topics."""
    own = ("/rosout", "/parameter_events")
    subscriptions = dict(probe.node.get_subscriber_names_and_types_by_node(name, namespace))
    publishers = dict(probe.node.get_publisher_names_and_types_by_node(name, namespace))
    return ({t: types for t, types in subscriptions.items() if t not in own},
            {t: types for t, types in publishers.items() if t not in own})


def _crash_text(process) -> str:
    log = process.log_tail(12).strip()
    hint = ""
    if "SystemError" in log and "publish" in log:
        hint = (" publish() raises this SystemError when a field holds a value of the wrong type: UInt8(data=...) "
                "takes a Python int, and a pixel read from a numpy array is a numpy.uint8, so wrap it in int(...).")
    elif "NotImplementedError" in log:
        hint = " Not done yet: replace the raise NotImplementedError with your code."
    return f"{hint}\nIts last output:\n{log}" if log else hint


def _run_brightness_node(ws) -> Verdict:
    """Start the built node as `ros2 run` would, with /image remapped, in a ROS domain of its own; send it frames."""
    from rclpy.qos import QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
    from sensor_msgs.msg import Image
    from std_msgs.msg import UInt8

    from course_lib.checks.probe import RosProbe
    from course_lib.imaging import images
    from course_lib.ros import rosenv, workspace

    command = (f"ros2 run {BRIGHTNESS_PACKAGE} {BRIGHTNESS_EXECUTABLE} --ros-args -r /image:={CHECK_CAMERA_TOPIC}")
    with rosenv.reserve_domain_id() as reservation, RosProbe(reservation.domain_id) as probe:
        try:
            process = workspace.run(ws, BRIGHTNESS_PACKAGE, BRIGHTNESS_EXECUTABLE,
                                    remap={"/image": CHECK_CAMERA_TOPIC}, domain_id=reservation.domain_id,
                                    name=f"{BRIGHTNESS_EXECUTABLE} (self-check)")
        except (OSError, RuntimeError) as error:  # FileNotFoundError names what the build lacks
            return _verdict(False, f"`{command}` could not start: {error}")
        try:
            def student_nodes():
                return [(n, ns) for n, ns in probe.node.get_node_names_and_namespaces() if n != probe.node.get_name()]

            probe.spin_until(lambda: student_nodes() or not process.running(), 25.0)
            if not student_nodes():
                if not process.running():
                    return _verdict(False, f"`{command}` ended ({process.describe_exit()}) before its node "
                                           f"appeared.{_crash_text(process)}")
                return _verdict(False, f"`{command}` runs, but no node appeared in 25 s: does main() call "
                                       "rclpy.init(args=args), create the node and spin it?")
            name, namespace = student_nodes()[0]
            if name != BRIGHTNESS_EXECUTABLE:
                return _verdict(False, f"The node is called {name!r}; call it {BRIGHTNESS_EXECUTABLE!r} "
                                       f"(super().__init__({BRIGHTNESS_EXECUTABLE!r})), the name the lesson waits for.")
            probe.spin_until(lambda: all(_node_endpoints(probe, name, namespace)) or not process.running(), 5.0)
            subscriptions, publishers = _node_endpoints(probe, name, namespace)
            if not subscriptions:
                return _verdict(False, "The node subscribes to nothing: create its subscription of 'image' in "
                                       "__init__, where rclpy.spin finds it.")
            if CHECK_CAMERA_TOPIC not in subscriptions:
                topic = next(iter(subscriptions))
                return _verdict(False, f"Started with -r /image:={CHECK_CAMERA_TOPIC}, the node still subscribes "
                                       f"{topic}: subscribe the topic 'image' and let the remap (-r /image:=...) "
                                       "choose the camera's topic, instead of naming the camera's topic in the code.")
            if subscriptions[CHECK_CAMERA_TOPIC] != ["sensor_msgs/msg/Image"]:
                return _verdict(False, f"The subscription takes {subscriptions[CHECK_CAMERA_TOPIC][0]}; camera "
                                       "frames are sensor_msgs/msg/Image.")
            if "/brightness" not in publishers:
                shown = ", ".join(publishers) or "nothing"
                return _verdict(False, f"The node publishes {shown}, not /brightness: create its publisher "
                                       "of 'brightness' in __init__.")
            if publishers["/brightness"] != ["std_msgs/msg/UInt8"]:
                return _verdict(False, f"The node publishes {publishers['/brightness'][0]} on /brightness; the "
                                       "exercise (and the assignment) publish std_msgs/msg/UInt8, a number 0-255.")
            reliable = [what for what, infos in (
                ("subscription", probe.node.get_subscriptions_info_by_topic(CHECK_CAMERA_TOPIC)),
                ("publisher", probe.node.get_publishers_info_by_topic("/brightness")))
                if any(i.node_name == name and i.qos_profile.reliability == ReliabilityPolicy.RELIABLE for i in infos)]
            if reliable:
                return _verdict(False, f"The node's {' and '.join(reliable)} is reliable; camera frames and what is "
                                       "measured from them use the sensor-data QoS (best effort), as §5 explains: "
                                       "pass qos_profile_sensor_data instead of a depth.")
            replies: list[int] = []
            probe.node.create_subscription(UInt8, "/brightness", lambda msg: replies.append(msg.data),
                                           qos_profile_sensor_data)
            camera = probe.node.create_publisher(Image, CHECK_CAMERA_TOPIC, QoSProfile(depth=5))
            probe.wait_for_subscriber(camera, 5.0)
            answers = []
            for frame, expected in _test_frames():
                _send_until_answered(probe, process, camera, images.image_to_msg(frame, "bgr8"), replies, expected)
                if not process.running():
                    return _verdict(False, f"The node crashed on the first frame the check sent "
                                           f"({process.describe_exit()}).{_crash_text(process)}")
                if not replies:
                    return _verdict(False, "The check sent frames on the remapped topic, but nothing came back on "
                                           "/brightness, and the node waits for more: does on_image publish a UInt8 "
                                           "with the node's publisher?")
                if replies[0] != expected:
                    return _verdict(False, f"For a frame 80 wide and 60 high whose centre pixel (row 30, column 40) is "
                                           f"(blue, green, red) = {tuple(int(v) for v in frame[30, 40])}, the node "
                                           f"published {replies[0]}; expected {expected}, the first channel of the "
                                           f"centre pixel.{_wrong_value_hint(frame, replies[0])}")
                answers.append(replies[0])
        finally:
            process.stop(timeout=2.0)
    return _verdict(True, f"`{command}` answers frames on the remapped topic with their centre pixels' first channel "
                          f"({', '.join(map(str, answers))}) on /brightness, as std_msgs/msg/UInt8. The package is "
                          "ready for the brightness assignment, which replaces centre_value with the average.")


@progress.while_running("self-check: your brightness package")
def brightness_package_exercise(ws_dir) -> Verdict:
    """Exercise (lesson 02): the brightness package, built, and its node run as `ros2 run brightness
    brightness_node --ros-args -r /image:=...`: package.xml declares what the node imports, setup.py has
    the executable, the build is current, and the node answers frames with the centre pixel's first channel.
    The static problems are named before anything is started."""
    from pathlib import Path

    ws = Path(ws_dir).absolute()
    for step in (_package_files, _build_state):  # (a failing Verdict is false: no `or` here)
        problem = step(ws)
        if problem is not None:
            return problem
    return _run_brightness_node(ws)
