"""Does a brightness node keep up with 1920x1080 frames at 30 Hz? Judged on processor time.

The node check (:mod:`course_lib.checks.brightness`) sends bursts of the same frames to the
student's node and to the grader's yardstick node (:func:`yardstick_main`: one numpy sum per frame,
the work any brightness node does) and compares the processor time each used per frame it answered
(:func:`throughput_verdict`), which the machine's load does not change, never answers per second.
"""

from __future__ import annotations

import time

import numpy as np

from course_lib.checks.context import scaled
from course_lib.checks.student_processes import student_env

#: Frames of the throughput test: bursts of 1920x1080 BGR at 30 Hz, this many seconds each (30 frames:
#: a verdict needs THROUGHPUT_MIN_ANSWERS of them, and longer bursts cost every grading more time).
THROUGHPUT_SECONDS = 1.0
THROUGHPUT_RATE = 30.0
#: The throughput verdict is on processor time, which the machine's load does not change: the
#: student's node process may use at most this many times the processor time per frame answered
#: right that the grader's yardstick node uses per frame it answered, measured the same way
#: (course_lib.supervision.process_tree.cpu_seconds) over the same bursts. Both get the very same frames; the
#: yardstick does what any brightness node does (receives the frame, one numpy sum over its 6
#: million bytes: about 10 ms here). Measured against it, idle and beside 4-8 busy processes on 2
#: cores: the reference 0.9-1.1 times; np.mean or a float copy 1.2-2.5; a node that answers every
#: other frame 1.7 (it pays for receiving the frames it ignores); Python's sum() over msg.data 6.6;
#: .tolist() 14-17; a per-byte Python loop 90-100. Three times the yardstick is also where a node
#: stops keeping up with 30 Hz on one core (33 ms per frame). Frames that a busy machine's
#: transport drops cost neither node anything, so they change nothing.
THROUGHPUT_CPU_RATIO = 3.0
#: Right answers (and yardstick answers) needed before per-frame costs are compared.
THROUGHPUT_MIN_ANSWERS = 10
#: A node with fewer right answers than that fails once it has used this much processor time on
#: the bursts and more than the allowed cost of one more frame than it answered right: it spends
#: the time and does not answer (a slow computation), which no amount of load explains.
THROUGHPUT_MIN_EVIDENCE_CPU = 0.5
#: Bursts at most, until the counts above are reached (a busy machine may deliver few frames; a
#: backstop, not a verdict: a node undecided after them, cheap and with few answers, is not failed).
THROUGHPUT_BURSTS = 5
YARDSTICK_NODE_NAME = "brightness_yardstick"
YARDSTICK_ANSWERS = "/grader/yardstick_answers"


def burst_images(rng) -> list:
    """The two 1920x1080 bgr8 images the throughput test alternates (their brightness differs, so
    that an answer says which frame it is for)."""
    image = rng.integers(0, 256, size=(1080, 1920, 3), dtype=np.uint8)
    return [image, image // 2]


def _burst(probe, publisher, replies: list, yardstick_replies: list, frames: list) -> None:
    """Send THROUGHPUT_SECONDS of `frames` (Image messages) at THROUGHPUT_RATE; wait until the
    answers stop coming (0.3 s without one, at most 2 s: frames still on their way cost processor
    time that the next burst's count makes up for)."""
    replies.clear()
    yardstick_replies.clear()
    count = int(THROUGHPUT_SECONDS * THROUGHPUT_RATE)
    start = time.monotonic()
    for index in range(count):
        publisher.publish(frames[index % 2])
        probe.spin_until(lambda: False, max(0.0, start + (index + 1) / THROUGHPUT_RATE - time.monotonic()))
    end = time.monotonic() + 2.0
    while time.monotonic() < end and _answer_comes(probe, (replies, yardstick_replies), 0.3):
        pass  # each answer gives the next one another 0.3 s


def _answer_comes(probe, answers: tuple, seconds: float) -> bool:
    """Spin `probe` until one of the lists `answers` grows, at most `seconds`; whether one did."""
    before = sum(map(len, answers))
    return probe.spin_until(lambda: sum(map(len, answers)) > before, seconds)


def start_yardstick(ctx):
    """Start the throughput yardstick on the check's /image, answering on YARDSTICK_ANSWERS."""
    from course_lib.ros import processes

    return ctx.track(processes.python_node("course_lib.checks.brightness_throughput:yardstick_main", "--ros-args",
                                 "-r", "frames:=/image", "-r", f"answers:={YARDSTICK_ANSWERS}",
                                 name="brightness-yardstick", domain_id=ctx.domain_id, env=student_env()))


def yardstick_main(args=None) -> None:
    """The throughput yardstick: answers every Image on `frames` with a UInt8 0 on `answers` after
    one numpy sum over the frame's bytes, the work any brightness node does per frame (so that on
    a busy machine it competes for the processor like a good student node). The check remaps both
    topics."""
    import rclpy
    from rclpy.node import Node
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import Image
    from std_msgs.msg import UInt8

    class Yardstick(Node):
        def __init__(self):
            super().__init__(YARDSTICK_NODE_NAME)
            self.answers = self.create_publisher(UInt8, "answers", qos_profile_sensor_data)
            self.create_subscription(Image, "frames", self.on_frame, qos_profile_sensor_data)

        def on_frame(self, frame: Image) -> None:
            np.frombuffer(frame.data, np.uint8).sum(dtype=np.uint64)  # the work of a good node; unused
            self.answers.publish(UInt8())

    rclpy.init(args=args)
    try:
        rclpy.spin(Yardstick())
    except KeyboardInterrupt:
        pass
    finally:
        rclpy.try_shutdown()


class CpuCost:
    """Processor time per frame of one node process over the bursts: ``add`` the processor time a
    burst cost and the frames it answered (right, for the student's node)."""

    def __init__(self):
        self.seconds, self.frames = 0.0, 0

    def add(self, seconds: float, frames: int) -> None:
        self.seconds += max(0.0, seconds)
        self.frames += frames

    def per_frame(self) -> float:
        return self.seconds / max(1, self.frames)


def throughput_verdict(student: CpuCost, yardstick: CpuCost) -> bool | None:
    """True (fast enough), False (too slow) or None (not yet decidable) from the processor time
    the two nodes used over the same bursts (see THROUGHPUT_CPU_RATIO and the constants below it)."""
    if yardstick.frames < THROUGHPUT_MIN_ANSWERS:
        return None
    allowed = THROUGHPUT_CPU_RATIO * yardstick.per_frame()
    if student.frames >= THROUGHPUT_MIN_ANSWERS:
        return student.per_frame() <= allowed
    if student.seconds >= THROUGHPUT_MIN_EVIDENCE_CPU and student.seconds > allowed * (student.frames + 1):
        return False
    return None


def measure(ctx, probe, node, yardstick, publisher, replies, yardstick_replies, images: list,
            earlier: frozenset = frozenset()) -> None:
    """Bursts to both the student's node and the yardstick, until their processor time per frame
    decides (throughput_verdict). `earlier`: the right answers to the frames the check sent before
    the bursts. A slow node may still be working through those frames during a burst; its answers
    to them are neither right nor wrong answers to the burst's frames."""
    from course_lib.imaging import images as image_msgs

    label = "throughput at 1920x1080, 30 Hz"
    expected = {ctx.expected("average_brightness", image) for image in images}
    # The yardstick started with the student's node: it has long been up, unless it could not start.
    if not probe.spin_until(lambda: (YARDSTICK_NODE_NAME in probe.node.get_node_names()
                                     and publisher.get_subscription_count() >= 2) or not yardstick.running(),
                            scaled(30.0)) \
            or not yardstick.running():
        ctx.item(True, f"{label}: not measured, the grader's yardstick node did not start "
                       f"({yardstick.describe_exit()}); not held against you", weight=2.0)
        return
    frames = [image_msgs.image_to_msg(i, "bgr8") for i in images]
    student, reference = CpuCost(), CpuCost()
    verdict, answered = None, 0
    for _ in range(THROUGHPUT_BURSTS):
        student_before, yardstick_before = node.cpu_seconds(), yardstick.cpu_seconds()
        _burst(probe, publisher, replies, yardstick_replies, frames)
        answered += sum(1 for value in replies if value in expected or value not in earlier)
        student.add(node.cpu_seconds() - student_before, sum(1 for value in replies if value in expected))
        reference.add(yardstick.cpu_seconds() - yardstick_before, len(yardstick_replies))
        verdict = throughput_verdict(student, reference)
        if verdict is not None or not node.running():
            break
    passed, words = throughput_item(verdict, student, reference, answered)
    ctx.item(passed, f"{label}: {words}", weight=2.0)


def throughput_item(verdict: bool | None, student: CpuCost, reference: CpuCost, answered: int) -> tuple[bool, str]:
    """The throughput check's item from its verdict (throughput_verdict): passed, and what it says.

    Args:
        answered: the student's node's answers in the bursts, right or wrong. A node that answered
            but never right is not called slow: its values are what to fix.
    """
    measured = (f"your node used {1000 * student.per_frame():.1f} ms of processor time per frame it answered right "
                f"({student.frames} frames, {student.seconds:.2f} s in all); the grader's yardstick node, which does "
                f"one numpy sum per frame, used {1000 * reference.per_frame():.1f} ms per frame ({reference.frames} "
                "frames) of the same bursts")
    if verdict is None:
        return True, f"not measured, too few frames arrived ({measured}); not held against you"
    if verdict:
        return True, f"{measured}: within {THROUGHPUT_CPU_RATIO:g} times the yardstick's cost per frame"
    if student.frames == 0 and answered:
        return False, (f"the node answered {answered} frames of the bursts, none with the right brightness, so "
                       "none counts towards its speed: fix the values it publishes first (the items above say what "
                       "it sent)")
    return False, (f"too slow: {measured}; at most {THROUGHPUT_CPU_RATIO:g} times the yardstick's "
                   "cost per frame is allowed. The node answers single frames right but cannot keep up with "
                   "30 Hz: it has 33 ms per frame of 6 million bytes, which whole-array numpy operations manage "
                   "and a Python loop over the bytes does not")
