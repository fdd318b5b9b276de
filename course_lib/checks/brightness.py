"""Checks of the brightness assignment: ``average_brightness`` and ``BrightnessNode``.

The contract (also in the notebook and in assignments/README.md):

- ``average_brightness(image: np.ndarray) -> int``: the mean of all bytes of the image (every
  channel of every pixel), rounded down as the tutorial's integer division does
  (``sum // count``), returned as an int. Works for colour (H, W, 3) and grey (H, W) images.
- ``BrightnessNode()``: node name ``my_node``; subscribes ``/image`` (sensor_msgs/Image,
  sensor-data QoS) and publishes ``/brightness`` (std_msgs/UInt8, sensor-data QoS), one value
  per frame; accepts bgr8 and mono8 frames; keeps up with 1920x1080 frames at 30 Hz; its names
  can be remapped (``--ros-args -r __node:=... -r /image:=...``).
- ``main(args=None)`` in brightness_node.py runs the node until Ctrl-C.
"""

from __future__ import annotations

import time

import numpy as np

from course_lib.checks import harness
from course_lib.checks.harness import check

ASSIGNMENT = "brightness"


def selfcheck(name: str):
    """Run check `name` with the self-check seed and print what is right and wrong."""
    return harness.selfcheck(ASSIGNMENT, name)


def grade(name: str):
    """Run check `name` with a fresh seed (grading)."""
    return harness.grade(ASSIGNMENT, name)


def _test_images(rng: np.random.Generator) -> list[tuple[str, np.ndarray]]:
    """Generated images; one whose mean has a fraction above .5 tells floor from round."""
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
def values(ctx: harness.Context) -> None:
    """average_brightness returns the floor of the mean byte, as an int, for colour and grey images."""
    cases = _test_images(ctx.rng)
    outcomes = ctx.call("average_brightness", [((image,), {}) for _, image in cases])
    for (label, image), outcome in zip(cases, outcomes):
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
        if not isinstance(value, int):
            ctx.item(False, f"{label}: returned a {outcome.pytype}, not an int")
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

NODE_NAME = "my_node"
#: Frames of the throughput test: 1920x1080 BGR at 30 Hz for this many seconds.
THROUGHPUT_SECONDS = 2.0
THROUGHPUT_RATE = 30.0
#: Share of the frames the grader's yardstick node answers, in the same run and place, that the
#: student's node must answer for the points. Comparing side by side, instead of with the frames
#: sent, keeps the grade fair on a loaded grading machine (DDS then drops large best-effort frames
#: before any node sees them), while a per-byte Python loop (~80x slower) still falls far short.
#: The yardstick receives each frame and answers at once without computing anything (a numpy
#: mean of a 1080p frame takes ~2 ms of the 33 ms between frames, so the share stays fair).
THROUGHPUT_SHARE = 0.5
#: Below this many answers from the yardstick node, the machine was too busy to measure.
THROUGHPUT_MIN_REFERENCE = 6
YARDSTICK_NODE_NAME = "brightness_yardstick"


def _node_names(probe) -> set[str]:
    return {name for name, _ns in probe.node.get_node_names_and_namespaces()}


def _exchange(ctx, probe, publisher, replies: list, frames, encoding: str, label: str) -> bool:
    """Publish each frame until its brightness comes back; record one item for all frames."""
    from course_lib import images

    for image in frames:
        expected = ctx.expected("average_brightness", image)
        msg = images.image_to_msg(image, encoding)
        replies.clear()
        deadline = time.monotonic() + 4.0
        got = None
        while time.monotonic() < deadline:
            publisher.publish(msg)
            probe.spin_until(lambda: expected in replies, 0.3)
            if expected in replies:
                got = expected
                break
        if got is None:
            if replies:
                return ctx.item(False, f"{label}: for a frame of brightness {expected} the node published "
                                       f"{sorted(set(replies))[:5]}")
            return ctx.item(False, f"{label}: no value on /brightness within 4 s of publishing a {encoding} frame "
                                   f"on /image; see the node's output below")
    return ctx.item(True, f"{label}: the right brightness for {len(frames)} {encoding} frames")


def _qos_items(ctx, probe, prefix: str = "") -> None:
    from rclpy.qos import ReliabilityPolicy

    image_topic, brightness_topic = f"{prefix}/image", f"{prefix}/brightness"
    probe.spin_until(lambda: probe.node.get_subscriptions_info_by_topic(image_topic)
                     and probe.node.get_publishers_info_by_topic(brightness_topic), 3.0)
    subs = [i for i in probe.node.get_subscriptions_info_by_topic(image_topic) if i.node_name == NODE_NAME]
    pubs = [i for i in probe.node.get_publishers_info_by_topic(brightness_topic) if i.node_name == NODE_NAME]
    topics = {name: types for name, types in probe.node.get_topic_names_and_types()}
    if not subs:
        other = sorted(t for t in topics if "image" in t.lower() and t != image_topic)
        ctx.item(False, f"{NODE_NAME} does not subscribe {image_topic}" + (f" (topics seen: {other})" if other else "")
                 + ": create_subscription(Image, '/image', ..., qos_profile_sensor_data)")
    elif subs[0].qos_profile.reliability != ReliabilityPolicy.BEST_EFFORT:
        ctx.item(False, f"the subscription on {image_topic} is {subs[0].qos_profile.reliability.name.lower()}; "
                        "camera topics use the sensor-data QoS (best effort): pass qos_profile_sensor_data")
    else:
        ctx.item(True, f"subscribes {image_topic} with the sensor-data QoS")
    if not pubs:
        other = sorted(t for t in topics if "bright" in t.lower() and t != brightness_topic)
        ctx.item(False, f"{NODE_NAME} does not publish {brightness_topic}" + (f" (topics seen: {other})" if other else "")
                 + ": create_publisher(UInt8, '/brightness', qos_profile_sensor_data)")
    elif pubs[0].topic_type != "std_msgs/msg/UInt8":
        ctx.item(False, f"{brightness_topic} carries {pubs[0].topic_type}; the contract says std_msgs/msg/UInt8")
    elif pubs[0].qos_profile.reliability != ReliabilityPolicy.BEST_EFFORT:
        ctx.item(False, f"the publisher on {brightness_topic} is {pubs[0].qos_profile.reliability.name.lower()}; "
                        "use qos_profile_sensor_data (best effort), as the contract says")
    else:
        ctx.item(True, f"publishes std_msgs/UInt8 on {brightness_topic} with the sensor-data QoS")


def _node_died(ctx, node) -> bool:
    if node.running():
        return False
    ctx.item(False, f"the node process ended ({node.describe_exit()}). Its last output:\n{node.log_tail(6)}")
    return True


@check(points=7, timeout=90)
def node(ctx: harness.Context) -> None:
    """BrightnessNode: name my_node, /image -> /brightness with sensor-data QoS, bgr8 and mono8, 30 Hz at 1080p, remappable."""
    # Every input is drawn first: what is drawn must not depend on how the run goes (the
    # self-check's answers were recorded for exactly these inputs).
    colour = [ctx.rng.integers(0, 256, size=(480, 640, 3), dtype=np.uint8) // int(d) for d in (1, 2, 3)]
    grey = [ctx.rng.integers(0, 256, size=(240, 320), dtype=np.uint8) // int(d) for d in (1, 4)]
    remapped_image = ctx.rng.integers(0, 256, size=(120, 160, 3), dtype=np.uint8)
    burst = _burst_frames(ctx.rng)
    reference_answers = _reference_throughput(ctx, burst)
    node = ctx.start_node()
    try:
        with ctx.probe() as probe:
            publisher, replies = _frames_and_replies(probe, "/image", "/brightness")
            appeared = probe.spin_until(lambda: NODE_NAME in _node_names(probe) or not node.running(), 25.0)
            if _node_died(ctx, node):
                return
            if not appeared or NODE_NAME not in _node_names(probe):
                names = sorted(_node_names(probe) - {probe.node.get_name()})
                ctx.item(False, f"no node named {NODE_NAME} appeared within 25 s" +
                         (f"; nodes seen: {names}: pass '{NODE_NAME}' to super().__init__()" if names else ""))
                return
            ctx.precondition(True, f"a node named {NODE_NAME} runs")
            _qos_items(ctx, probe)
            _exchange(ctx, probe, publisher, replies, colour, "bgr8", "bgr8 frames")
            if _node_died(ctx, node):
                return
            _exchange(ctx, probe, publisher, replies, grey, "mono8", "mono8 frames")
            if _node_died(ctx, node):
                return
            _throughput(ctx, probe, publisher, replies, burst, reference_answers)
        if _node_died(ctx, node):
            return
    finally:
        node.stop(timeout=2)
        ctx.note(f"node output (last lines):\n{node.log_tail(4)}")
    _remapped(ctx, remapped_image)


def _burst_frames(rng) -> list:
    """The two 1920x1080 bgr8 Image messages the throughput test alternates."""
    from course_lib import images

    return [images.image_to_msg(rng.integers(0, 256, size=(1080, 1920, 3), dtype=np.uint8), "bgr8") for _ in range(2)]


def _burst(probe, publisher, replies: list, frames: list) -> int:
    """Send THROUGHPUT_SECONDS of `frames` at THROUGHPUT_RATE; return how many got an answer."""
    replies.clear()
    count = int(THROUGHPUT_SECONDS * THROUGHPUT_RATE)
    start = time.monotonic()
    for index in range(count):
        publisher.publish(frames[index % 2])
        probe.spin_until(lambda: False, max(0.0, start + (index + 1) / THROUGHPUT_RATE - time.monotonic()))
    probe.spin_until(lambda: len(replies) >= count, 2.0)
    return len(replies)


def _frames_and_replies(probe, image_topic: str, brightness_topic: str):
    """The probe's side of a brightness node: a sensor-data Image publisher on image_topic, and the
    list that the UInt8 values arriving on brightness_topic are appended to."""
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import Image
    from std_msgs.msg import UInt8

    replies: list[int] = []
    publisher = probe.node.create_publisher(Image, image_topic, qos_profile_sensor_data)
    probe.node.create_subscription(UInt8, brightness_topic, lambda m: replies.append(m.data), qos_profile_sensor_data)
    return publisher, replies


def _reference_throughput(ctx, frames: list) -> int:
    """How many throughput frames the yardstick node answers here and now."""
    from course_lib import processes

    yardstick = processes.python_node("course_lib.checks.brightness:yardstick_main", "--ros-args",
                                      "-r", "frames:=/image", "-r", "answers:=/brightness", name="brightness-yardstick",
                                      domain_id=ctx.domain_id, env=harness._student_env())
    try:
        with ctx.probe() as probe:
            publisher, replies = _frames_and_replies(probe, "/image", "/brightness")
            if not probe.spin_until(lambda: YARDSTICK_NODE_NAME in _node_names(probe), 25.0):
                return 0
            probe.wait_for_subscriber(publisher, 5.0)
            return _burst(probe, publisher, replies, frames)
    finally:
        yardstick.stop(timeout=2)


def yardstick_main(args=None) -> None:
    """The throughput yardstick: answers every Image on `frames` at once with a UInt8 0 on `answers`,
    computing nothing (what the transport allows here and now). The check remaps both topics."""
    import rclpy
    from rclpy.node import Node
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import Image
    from std_msgs.msg import UInt8

    class Yardstick(Node):
        def __init__(self):
            super().__init__(YARDSTICK_NODE_NAME)
            self.answers = self.create_publisher(UInt8, "answers", qos_profile_sensor_data)
            self.create_subscription(Image, "frames", lambda _frame: self.answers.publish(UInt8()),
                                     qos_profile_sensor_data)

    rclpy.init(args=args)
    try:
        rclpy.spin(Yardstick())
    except KeyboardInterrupt:
        pass
    finally:
        rclpy.try_shutdown()


def _throughput(ctx, probe, publisher, replies, frames: list, reference_answers: int) -> None:
    answered = _burst(probe, publisher, replies, frames)
    count = int(THROUGHPUT_SECONDS * THROUGHPUT_RATE)
    if reference_answers < THROUGHPUT_MIN_REFERENCE:
        ctx.item(True, f"throughput not measured: the grading machine was too busy (its yardstick node answered "
                       f"{reference_answers} of {count} 1920x1080 frames); not held against you", weight=2.0)
        return
    needed = THROUGHPUT_SHARE * reference_answers
    message = (f"answered {answered} of {count} 1920x1080 frames sent at {THROUGHPUT_RATE:g} Hz; the grader's "
               f"yardstick node answered {reference_answers} in the same place (needs {THROUGHPUT_SHARE:.0%} of that)")
    ctx.item(answered >= needed, message if answered >= needed else
             message + ": a Python loop over 6 million bytes per frame is too slow; let numpy do the sum "
                       "(image.sum() // image.size)", weight=2.0)


def _remapped(ctx, image) -> None:
    from course_lib import images

    node = ctx.start_node("--ros-args", "-r", "__node:=renamed_by_grader", "-r", "/image:=/grader/image",
                          "-r", "/brightness:=/grader/brightness")
    try:
        with ctx.probe() as probe:
            publisher, replies = _frames_and_replies(probe, "/grader/image", "/grader/brightness")
            if not probe.spin_until(lambda: "renamed_by_grader" in _node_names(probe) or not node.running(), 20.0) \
                    or not node.running():
                ctx.item(False, "with --ros-args -r __node:=renamed_by_grader no node of that name appeared: "
                                "call rclpy.init(args=args) and pass args from main(args=None)")
                return
            expected = ctx.expected("average_brightness", image)
            msg = images.image_to_msg(image, "bgr8")
            deadline = time.monotonic() + 4.0
            while time.monotonic() < deadline and expected not in replies:
                publisher.publish(msg)
                probe.spin_until(lambda: expected in replies, 0.3)
            ctx.item(expected in replies, "remapped to /grader/image -> /grader/brightness: " +
                     ("works" if expected in replies else "no answer; use the topic names through "
                      "create_subscription/create_publisher (no hard-coded extra namespaces), and init with args"))
    finally:
        node.stop(timeout=2)
