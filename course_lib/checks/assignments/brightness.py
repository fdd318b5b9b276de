"""The brightness assignment: its spec, its notebook's words and its checks (``average_brightness``
and ``BrightnessNode``).

The contract is the notebook's introduction (BRIGHTNESS_INTRO). Whether the node keeps up with
30 Hz is judged on processor time against a yardstick node (:mod:`course_lib.checks.brightness_throughput`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from course_lib.checks import packages
from course_lib.checks.context import Context, scaled
from course_lib.checks.registry import check
from course_lib.checks.spec import Assignment, NotebookText

if TYPE_CHECKING:
    import numpy as np

# --- the notebook's words (markdown) and the spec ----------------------------------------

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

#: The spec: what assignments/build.py, the grader and the checks below read about it.
SPEC = Assignment("brightness", "02", {"brightness": ("brightness_node",)},
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
           functions=("brightness", "brightness.brightness_node"), answers="key")
selfcheck, grade = SPEC.selfcheck, SPEC.grade  # what the notebook calls: checks.selfcheck("...")

#: The package and executable of the node: ``ros2 run brightness brightness_node``.
(PACKAGE,) = SPEC.packages
EXECUTABLE = SPEC.executable(PACKAGE)


def _test_images(rng: np.random.Generator) -> list[tuple[str, np.ndarray]]:
    """Generated images; one whose mean has a fraction above .5 tells floor from round."""
    import numpy as np

    bgr = rng.integers(0, 256, size=(int(rng.integers(40, 120)), int(rng.integers(40, 160)), 3), dtype=np.uint8)
    grey = rng.integers(0, 256, size=(int(rng.integers(30, 90)), int(rng.integers(30, 90))), dtype=np.uint8)
    dark = rng.integers(0, 40, size=(48, 64, 3), dtype=np.uint8)
    bright = np.full((20, 30, 3), 255, np.uint8)
    rounding = np.zeros((1, 10, 3), np.uint8)   # mean = level + 0.7: floor and round differ
    level = int(rng.integers(10, 240))
    rounding[:] = level
    rounding.reshape(-1)[:21] = level + 1
    return [("a colour (BGR) image", bgr), ("a grey image", grey), ("a dark image", dark),
            ("a white image (all 255)", bright), ("an image whose mean is N.7", rounding)]


@check(points=4, timeout=45)
def values(ctx: Context) -> None:
    """average_brightness returns the floor of the mean byte, as an int, for colour and grey images."""
    cases = _test_images(ctx.rng)
    outcomes = ctx.call("average_brightness", [((image,), {}) for _, image in cases],
                        labels=[label for label, _ in cases])
    for (label, image), outcome in zip(cases, outcomes, strict=True):
        expected = ctx.expected("average_brightness", image)
        mean = float(image.mean())
        if not outcome.ok:
            hint = ""
            if outcome.error.startswith("NotImplementedError"):
                hint = " (replace `raise NotImplementedError()` with your code)"
            ctx.item(False, f"{label}: average_brightness failed: {outcome.error}{hint}")
            continue
        value = outcome.value
        if isinstance(value, bool) or outcome.pytype in ("float", "float64", "float32", "float16"):
            ctx.item(False, f"{label}: returned {outcome.pytype} {value!r}; the contract asks for an int "
                            f"like the tutorial's integer division: use sum // count or int(...)")
            continue
        if outcome.pytype != "int":
            # numpy's integer scalars (uint64 from image.sum() // image.size) are not ints: a
            # std_msgs UInt8 refuses them, so the node built on this function would crash.
            fix = " wrap it in int(...)" if isinstance(value, int) else ""
            ctx.item(False, f"{label}: returned a {outcome.pytype} {value!r}, not a Python int;{fix} "
                            f"(the node puts it into a std_msgs UInt8, which takes only a Python int)")
            continue
        if value == expected:
            ctx.item(True, f"{label}: {value}")
        elif value == round(mean) and round(mean) != expected:
            ctx.item(False, f"{label}: returned {value}, the mean rounded to nearest; the contract rounds down "
                            f"(integer division) to {expected}")
        elif abs(value - expected) == 1:
            ctx.item(False, f"{label}: returned {value}, expected {expected} (off by one: divide the sum of "
                            f"all bytes by their number, rounding down)")
        elif image.ndim == 3 and value == int(image[:, :, 0].sum() // image[:, :, 0].size):
            ctx.item(False, f"{label}: returned {value}, the mean of the first channel only; average all "
                            f"channels: expected {expected}")
        else:
            ctx.item(False, f"{label}: returned {value}, expected {expected} (mean of all bytes {mean:.2f})")


# -- the node ---------------------------------------------------------------------------------

NODE_NAME = "brightness_node"
#: The name the remapping test gives the student's node, and its topics.
REMAPPED_NODE_NAME = "renamed_by_grader"
REMAPPED_IMAGE, REMAPPED_BRIGHTNESS = "/grader/image", "/grader/brightness"


#: Answers to one frame, none of them right (and none the answer to a frame sent before, which a
#: slow node may still be working through), after which the node's answer counts as wrong.
WRONG_ANSWERS = 3


def _wrong(replies: list, earlier: set) -> int:
    """How many of `replies` are neither right nor late answers to earlier frames (`earlier`)."""
    return sum(1 for value in replies if value not in earlier)


def _node_names(probe) -> set[str]:
    return {name for name, _ns in probe.node.get_node_names_and_namespaces()}


def _send_until_answered(ctx, probe, node, publisher, replies: list, msg, expected: int, earlier: set) -> None:
    """Publish the frame `msg` until the node answers `expected` (collected in `replies`), ends,
    gives WRONG_ANSWERS wrong answers or computes without answering (ctx.no_answer_coming).

    Resent every 0.3 s (best effort may drop a frame). `earlier` holds the right answers of all
    frames sent before: a slow node's late answers to them are not wrong answers to this one.
    """
    replies.clear()
    gave_up = ctx.no_answer_coming(node, 4.0)

    def done() -> bool:
        return (expected in replies or not node.running()
                or _wrong(replies, earlier - {expected}) >= WRONG_ANSWERS or gave_up())

    probe.resend_until(publisher, msg, done, scaled(4.0))


def _exchange(ctx, probe, node, publisher, replies: list, frames, encoding: str, label: str,
              earlier: set) -> bool | None:
    """Publish each frame until its brightness comes back; record one item for all frames.

    Returns True (all answered right), False (an item failed), or None when the node process
    ended during the exchange (nothing is recorded then: the caller reports the crash, the cause).
    """
    from course_lib.imaging import images

    for image in frames:
        expected = ctx.expected("average_brightness", image)
        _send_until_answered(ctx, probe, node, publisher, replies, images.image_to_msg(image, encoding), expected,
                             earlier)
        earlier.add(expected)
        if not node.running():
            return None
        if expected not in replies:
            if replies:
                return ctx.item(False, f"{label}: for a frame of brightness {expected} the node published "
                                       f"{sorted(set(replies))[:5]}")
            return ctx.item(False, f"{label}: no value on /brightness after publishing a {encoding} frame "
                                   f"on /image, while the node runs; see the node's output below")
    return ctx.item(True, f"{label}: the right brightness for {len(frames)} {encoding} frames")


def _topic_items(ctx, probe) -> str | None:
    """Items for the node's two endpoints (names, types, QoS). Returns the cause, in words, that
    keeps camera frames from reaching the node or its answers from reaching a camera-QoS reader,
    or None when the graph shows nothing in the way."""
    from rclpy.qos import ReliabilityPolicy

    def endpoints():  # the node's own (the yardstick subscribes /image too)
        return ([i for i in probe.node.get_subscriptions_info_by_topic("/image") if i.node_name == NODE_NAME],
                [i for i in probe.node.get_publishers_info_by_topic("/brightness") if i.node_name == NODE_NAME])

    probe.spin_until(lambda: all(endpoints()), scaled(3.0))
    subs, pubs = endpoints()
    topics = {name: types for name, types in probe.node.get_topic_names_and_types()}
    blocker = None
    if not subs:
        other = sorted(t for t in topics if "image" in t.lower() and t != "/image")
        ctx.item(False, f"{NODE_NAME} does not subscribe /image" + (f" (topics seen: {other})" if other else "")
                 + ": create_subscription(Image, '/image', ..., qos_profile_sensor_data)")
        blocker = "the node does not subscribe /image"
    elif subs[0].qos_profile.reliability != ReliabilityPolicy.BEST_EFFORT:
        ctx.item(False, f"the subscription on /image is {subs[0].qos_profile.reliability.name.lower()}, and a "
                        "camera publishes best effort: ROS reports an incompatible QoS and no frame reaches your "
                        "node. Camera topics use the sensor-data QoS: pass qos_profile_sensor_data")
        blocker = "no camera frame reaches the node (its /image subscription is reliable: incompatible QoS)"
    else:
        ctx.item(True, "subscribes /image with the sensor-data QoS")
    if not pubs:
        other = sorted(t for t in topics if "bright" in t.lower() and t != "/brightness")
        ctx.item(False, f"{NODE_NAME} does not publish /brightness" + (f" (topics seen: {other})" if other else "")
                 + ": create_publisher(UInt8, '/brightness', qos_profile_sensor_data)")
        blocker = blocker or "the node does not publish /brightness"
    elif pubs[0].topic_type != "std_msgs/msg/UInt8":
        ctx.item(False, f"/brightness carries {pubs[0].topic_type}; the contract says std_msgs/msg/UInt8")
        blocker = blocker or f"/brightness carries {pubs[0].topic_type}, which a std_msgs/UInt8 reader does not match"
    elif pubs[0].qos_profile.reliability != ReliabilityPolicy.BEST_EFFORT:
        # A reliable publisher still reaches best-effort readers: nothing blocked, one item lost.
        ctx.item(False, f"the publisher on /brightness is {pubs[0].qos_profile.reliability.name.lower()}; "
                        "use qos_profile_sensor_data (best effort), as the contract says")
    else:
        ctx.item(True, "publishes std_msgs/UInt8 on /brightness with the sensor-data QoS")
    return blocker


def _node_died(ctx, node) -> bool:
    """Record the crash as the cause when the node process has ended; True if it has."""
    if node.running():
        return False
    log = node.log
    message = f"the node process ended ({node.describe_exit()}). Its last output:\n{node.log_tail(8)}"
    if "SystemError" in log and "publish" in log:
        message += ("\n(publish() raises this SystemError when a message field holds a value of the wrong type, "
                    "e.g. a numpy.uint64 in UInt8.data: put a Python int in it, int(value))")
    ctx.precondition(False, message)  # the items it cut short are recorded as its consequences
    return True


#: The items of the node check after the endpoint items, with their weights (the consequences
#: recorded when a cause stops them from being tested).
_LATER_ITEMS = (("bgr8 frames", 1.0), ("mono8 frames", 1.0), ("remapped names", 1.0),
                ("throughput at 1920x1080, 30 Hz", 2.0))


def _consequences(ctx, cause: str, done: int) -> None:
    """Record the later items from index `done` on as consequences of `cause`."""
    for label, weight in _LATER_ITEMS[done:]:
        ctx.consequence(f"{label}: not tested, because {cause}", weight=weight)


@check(points=7, timeout=90)
def node(ctx: Context) -> None:
    """BrightnessNode: name brightness_node, /image -> /brightness with sensor-data QoS, bgr8 and mono8, 30 Hz at 1080p, remappable."""  # noqa: E501 (the check's description, one line: registry.check)
    # Every input is drawn first: what is drawn must not depend on how the run goes (the
    # self-check's answers were recorded for exactly these inputs).
    import numpy as np

    from course_lib.checks import brightness_throughput

    colour = [ctx.rng.integers(0, 256, size=(480, 640, 3), dtype=np.uint8) // int(d) for d in (1, 2, 3)]
    grey = [ctx.rng.integers(0, 256, size=(240, 320), dtype=np.uint8) // int(d) for d in (1, 4)]
    remapped_image = ctx.rng.integers(0, 256, size=(120, 160, 3), dtype=np.uint8)
    burst = brightness_throughput.burst_images(ctx.rng)
    # All three nodes start at once (their start-up and discovery overlap): the student's node,
    # the same node under remapped names (its topics are apart), and the yardstick.
    node = packages.run(ctx, PACKAGE, EXECUTABLE)  # ros2 run brightness brightness_node
    remapped = packages.run(ctx, PACKAGE, EXECUTABLE, "--ros-args", "-r", f"__node:={REMAPPED_NODE_NAME}",
                            "-r", f"/image:={REMAPPED_IMAGE}", "-r", f"/brightness:={REMAPPED_BRIGHTNESS}",
                            tag="-remapped")
    packages.dependency_items(ctx, PACKAGE)
    yardstick = brightness_throughput.start_yardstick(ctx)
    crashed = False
    try:
        with ctx.probe() as probe:
            publisher, replies = _frames_and_replies(probe, "/image", "/brightness")
            yardstick_replies = _replies(probe, brightness_throughput.YARDSTICK_ANSWERS)
            appeared = ctx.wait_for_node(probe, node, NODE_NAME)
            if _node_died(ctx, node):
                crashed = True
                return _consequences(ctx, "the node process ended", 0)
            if not appeared or NODE_NAME not in _node_names(probe):
                names = sorted(_node_names(probe) - {probe.node.get_name(), brightness_throughput.YARDSTICK_NODE_NAME,
                                                  REMAPPED_NODE_NAME})
                if ctx.import_hung():
                    hint = (f"; importing {ctx.module} never finished in the values check: a spin() or loop at the "
                            "top level of the module runs before main() does")
                else:
                    hint = f"; nodes seen: {names}: pass '{NODE_NAME}' to super().__init__()" if names else ""
                ctx.item(False, f"no node named {NODE_NAME} appeared within {scaled(25):.0f} s" + hint)
                return _consequences(ctx, f"no node named {NODE_NAME} ran", 0)
            ctx.precondition(True, f"a node named {NODE_NAME} runs")
            blocker = _topic_items(ctx, probe)
            answered, earlier = False, set()
            for done, (frames, encoding) in enumerate(((colour, "bgr8"), (grey, "mono8"))):
                ok = _exchange(ctx, probe, node, publisher, replies, frames, encoding, f"{encoding} frames", earlier)
                if ok is None:
                    crashed = _node_died(ctx, node)
                    return _consequences(ctx, "the node process ended (see above)", done)
                answered = answered or ok or bool(replies)
                if not ok and blocker and not answered:
                    ctx.items[-1].update(consequence=True, message=f"{encoding} frames: no answer, because {blocker}")
                    return _consequences(ctx, blocker, done + 1)
            if not answered:
                return _consequences(ctx, "the node answered none of the frames above", 2)
            _remapped(ctx, probe, remapped, remapped_image)
            # Stopped before the burst: a node that did not take the remapped names would answer it too.
            remapped.stop(timeout=2)
            brightness_throughput.measure(ctx, probe, node, yardstick, publisher, replies, yardstick_replies, burst,
                                          frozenset(earlier))
            if _node_died(ctx, node):
                crashed = True
                ctx.items.pop()  # the throughput item: the crash is its cause
                return _consequences(ctx, "the node process ended (see above)", 3)
    finally:
        for process in (node, remapped, yardstick):
            process.stop(timeout=2)
        if not crashed:  # a crash's output is in its item already
            ctx.note(f"node output (last lines):\n{node.log_tail(4)}")


def _replies(probe, topic: str) -> list:
    """The list that the UInt8 values arriving on `topic` (sensor-data QoS) are appended to."""
    from rclpy.qos import qos_profile_sensor_data
    from std_msgs.msg import UInt8

    replies: list[int] = []
    probe.node.create_subscription(UInt8, topic, lambda m: replies.append(m.data), qos_profile_sensor_data)
    return replies


def _frames_and_replies(probe, image_topic: str, brightness_topic: str):
    """The probe's side of a brightness node: a sensor-data Image publisher on image_topic, and the
    list that the UInt8 values arriving on brightness_topic are appended to."""
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import Image

    publisher = probe.node.create_publisher(Image, image_topic, qos_profile_sensor_data)
    return publisher, _replies(probe, brightness_topic)


def _remapped(ctx, probe, remapped, image) -> None:
    """The node started with remapped node and topic names answers on the remapped topics."""
    from course_lib.imaging import images

    label = "remapped names"
    publisher, replies = _frames_and_replies(probe, REMAPPED_IMAGE, REMAPPED_BRIGHTNESS)
    if not ctx.wait_for_node(probe, remapped, REMAPPED_NODE_NAME, 10.0) or not remapped.running():
        ctx.item(False, f"{label}: started with --ros-args -r __node:={REMAPPED_NODE_NAME}, no node of that name "
                        "appeared: call rclpy.init(args=args) and pass args from main(args=None)")
        return
    expected = ctx.expected("average_brightness", image)
    msg = images.image_to_msg(image, "bgr8")
    gave_up = ctx.no_answer_coming(remapped, 4.0)
    probe.resend_until(publisher, msg, lambda: expected in replies or len(replies) >= WRONG_ANSWERS or gave_up(),
                       scaled(4.0))
    if expected in replies:
        ctx.item(True, f"{label}: {REMAPPED_IMAGE} -> {REMAPPED_BRIGHTNESS} works")
        return
    if replies:
        ctx.item(False, f"{label}: the remapped node answers on {REMAPPED_BRIGHTNESS}, but with "
                        f"{sorted(set(replies))[:5]} for a frame of brightness {expected}")
        return
    topics = {name for name, _types in probe.node.get_topic_names_and_types()}
    strays = sorted(t for t in topics if t.endswith(("/image", "/brightness")) and t not in
                    ("/image", "/brightness", REMAPPED_IMAGE, REMAPPED_BRIGHTNESS))
    ctx.item(False, f"{label}: with /image:={REMAPPED_IMAGE} and /brightness:={REMAPPED_BRIGHTNESS}, no answer on "
                    f"{REMAPPED_BRIGHTNESS}" + (f"; topics seen: {strays}" if strays else "") +
             ": pass the topic names to create_subscription/create_publisher as the contract gives them, and "
             "init with args")
