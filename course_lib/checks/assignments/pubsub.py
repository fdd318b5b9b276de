"""The pubsub assignment: its spec, its notebook's words and its checks (the MsgTutorial publisher
and subscriber, as ROS 2 packages).

The contract is the notebook's introduction (PUBSUB_INTRO). The checks start the executables as
``ros2 run pubsub topic_publisher`` would (the grader builds the workspace first); the checker's own
node uses the reference MsgTutorial.
"""

from __future__ import annotations

import re
from itertools import pairwise

from course_lib import waiting
from course_lib.checks import packages
from course_lib.checks.context import Context, StudentError, scaled
from course_lib.checks.registry import check
from course_lib.checks.spec import Assignment, NotebookText

# --- the notebook's words (markdown) and the spec ----------------------------------------

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

#: The spec: what assignments/build.py, the grader and the checks below read about it.
SPEC = Assignment("pubsub", "01b", {"tutorial_interfaces": (), "pubsub": ("topic_publisher", "topic_subscriber")},
       NotebookText(intro=PUBSUB_INTRO, plain_ros=(
           "In plain ROS 2: `ros2 pkg create --build-type ament_cmake tutorial_interfaces` and "
           "`ros2 pkg create --build-type ament_python --dependencies rclpy tutorial_interfaces "
           "--node-name topic_publisher pubsub`, then the edits of Lesson 01b."),
           checks={"publisher": ("the publisher",), "subscriber": ("the subscriber",),
                   "together": ("both together",)}))
selfcheck, grade = SPEC.selfcheck, SPEC.grade  # what the notebook calls: checks.selfcheck("...")

INTERFACES, PACKAGE = SPEC.packages
PUBLISHER, SUBSCRIBER = SPEC.executables(PACKAGE)
MESSAGE_FIELDS = [("builtin_interfaces/Time", "stamp"), ("int32", "data")]
TOPIC = "/ros_tutorial_msg"
RATE_HZ = 10.0
#: Relative tolerance of the measured rate (from the message stamps).
RATE_TOLERANCE = 0.15
QUEUE_DEPTH = 100
#: Messages whose stamps measure the publisher's rate: the wait ends when they arrived, or when
#: the stamps of fewer span RATE_SPAN seconds (a slower publisher), whatever the machine's load.
RATE_MESSAGES = 16
RATE_SPAN = (RATE_MESSAGES - 1) / RATE_HZ
#: A subscriber's log line: the stamp (seconds, and nanoseconds when shown) and the data.
HEARD = re.compile(r"I heard:.*?stamp\D{0,4}(\d+)(?:\.(\d+))?.*?data\D{0,4}(-?\d+)")


def _stamp_seconds(stamp) -> float:
    return stamp.sec + stamp.nanosec * 1e-9


def _stamp_span(messages) -> float:
    """Seconds between the stamps of the first and the last of `messages`."""
    return _stamp_seconds(messages[-1].stamp) - _stamp_seconds(messages[0].stamp) if len(messages) > 1 else 0.0


def _queue_depth(ctx, module: str, class_name: str, kind: str) -> None:
    """One item: the node's endpoint on the topic keeps the last QUEUE_DEPTH messages. A running
    node's depth is not visible to other processes (DDS discovery does not carry it), so the
    class is constructed in a student process of its own and asked."""
    try:
        found = [e for e in packages.endpoints(ctx, module, class_name)[kind] if e["topic"] == TOPIC]
    except StudentError as error:
        ctx.item(False, f"queue depth: {error}")
        return
    if not found:
        ctx.item(False, f"queue depth: {class_name}() has no {kind[:-1]} on {TOPIC}")
        return
    depth, history = found[0]["depth"], found[0]["history"]
    ok = depth == QUEUE_DEPTH and history == "KEEP_LAST"
    ctx.item(ok, f"{kind[:-1]} queue depth {depth} ({history})" + ("" if ok else
             f"; the contract asks for a queue depth of {QUEUE_DEPTH}: pass {QUEUE_DEPTH} as the QoS argument"))


def _start(ctx, executable: str, tag: str = ""):
    """``ros2 run pubsub <executable>`` (raises StudentError when the workspace did not build)."""
    return packages.run(ctx, PACKAGE, executable, tag=tag)


@check(points=5, timeout=90)
def publisher(ctx: Context) -> None:
    """topic_publisher: MsgTutorial on ros_tutorial_msg at 10 Hz, data +1 per message, increasing stamps."""
    proc = _start(ctx, PUBLISHER)
    packages.use_interfaces(ctx)
    from tutorial_interfaces.msg import MsgTutorial

    packages.message_item(ctx, INTERFACES, "MsgTutorial", MESSAGE_FIELDS)
    packages.dependency_items(ctx, PACKAGE)
    _queue_depth(ctx, "pubsub.topic_publisher", "TopicPublisher", "publishers")
    try:
        with ctx.probe() as probe:
            messages = []
            probe.node.create_subscription(MsgTutorial, TOPIC, messages.append, 100)
            if not packages.wait_node(ctx, probe, proc, "topic_publisher"):
                return
            types = dict(probe.node.get_topic_names_and_types())
            if not probe.spin_until(lambda: len(messages) > 0 or not proc.running(), scaled(5.0)):
                types = dict(probe.node.get_topic_names_and_types())
                shown = {t: v for t, v in types.items() if not t.startswith(('/rosout', '/parameter'))}
                ctx.item(False, f"nothing arrived on {TOPIC} within {scaled(5):.0f} s (topics: {shown}); "
                                "publish tutorial_interfaces/msg/MsgTutorial on 'ros_tutorial_msg' from a 0.1 s timer")
                return
            # Enough stamps for the rate: RATE_MESSAGES, or RATE_SPAN seconds of a slower publisher's.
            probe.spin_until(lambda: len(messages) >= RATE_MESSAGES or not proc.running()
                             or _stamp_span(messages) >= RATE_SPAN, scaled(RATE_SPAN + 1.5))
    finally:
        proc.stop(timeout=2)
    types = types.get(TOPIC, [])
    wanted = ["tutorial_interfaces/msg/MsgTutorial"]
    ctx.item(types == wanted,
             f"{TOPIC} carries {types}" + ("" if types == wanted else f"; the contract says {wanted[0]}"))
    counters = [msg.data for msg in messages]
    steps = {b - a for a, b in pairwise(counters)}
    ctx.item(steps == {1}, f"data {counters[:4]}...{counters[-2:]}: " +
             ("one more per message" if steps == {1} else f"steps {sorted(steps)[:5]}; add one per message"))
    stamps = [_stamp_seconds(m.stamp) for m in messages]
    increasing = all(b > a for a, b in pairwise(stamps))
    ctx.item(increasing, "stamps increase" if increasing else
             "stamps do not increase: set msg.stamp = self.get_clock().now().to_msg() when publishing")
    if len(stamps) >= 3 and stamps[-1] > stamps[0]:
        rate = (len(stamps) - 1) / (stamps[-1] - stamps[0])
        ok = abs(rate - RATE_HZ) <= RATE_TOLERANCE * RATE_HZ
        ctx.item(ok, f"rate {rate:.2f} Hz from the stamps of {len(stamps)} messages" +
                 ("" if ok else f"; the contract asks for {RATE_HZ:g} Hz: create_timer(0.1, ...)"))
    else:
        ctx.item(False, f"only {len(stamps)} messages with increasing stamps: cannot measure a 10 Hz rate")


@check(points=3, timeout=90)
def subscriber(ctx: Context) -> None:
    """topic_subscriber: node topic_subscriber hears every MsgTutorial on ros_tutorial_msg and logs its stamp and data."""  # noqa: E501 (the check's description, one line: registry.check)
    proc = _start(ctx, SUBSCRIBER)
    packages.use_interfaces(ctx)
    from tutorial_interfaces.msg import MsgTutorial

    _queue_depth(ctx, "pubsub.topic_subscriber", "TopicSubscriber", "subscriptions")
    first = int(ctx.rng.integers(100, 10000))
    sent = [(int(ctx.rng.integers(10**6, 10**9)), first + i) for i in range(20)]  # (stamp sec, data)
    try:
        with ctx.probe() as probe:
            pub = probe.node.create_publisher(MsgTutorial, TOPIC, 100)
            if not packages.wait_node(ctx, probe, proc, "topic_subscriber"):
                return
            if not probe.spin_until(lambda: pub.get_subscription_count() > 0 or not proc.running(), scaled(5.0)):
                ctx.item(False, f"topic_subscriber does not subscribe {TOPIC}: "
                                "create_subscription(MsgTutorial, 'ros_tutorial_msg', self.callback, 100)")
                return
            probe.spin_for(0.3)
            for sec, data in sent:
                msg = MsgTutorial(data=data)
                msg.stamp.sec, msg.stamp.nanosec = sec, 250_000_000
                pub.publish(msg)
                probe.spin_for(0.05)
            probe.spin_until(lambda: sent[-1][1] in [d for _, d in _heard(proc.log)] or not proc.running(), scaled(3.0))
    finally:
        proc.stop(timeout=2)
    heard = _heard(proc.log)
    data = [d for _, d in heard]
    ok = data == [d for _, d in sent]
    ctx.item(ok, f"logged the data of all {len(sent)} messages in order" if ok else
             f"sent data {sent[0][1]}..{sent[-1][1]}, the log shows {data[:6]}{'...' if len(data) > 6 else ''}: "
             "log self.get_logger().info(f'I heard: stamp {msg.stamp.sec}.{msg.stamp.nanosec:09d} data {msg.data}') "
             "for every message", weight=2)
    stamps_ok = bool(heard) and [s for s, _ in heard] == [s for s, _ in sent][:len(heard)]
    ctx.item(stamps_ok, "logged the stamp of each message" if stamps_ok else
             "the log lines do not show each message's stamp (its sec): log every field, stamp and data")


def _heard(log: str) -> list[tuple[int, int]]:
    """(stamp sec, data) of each 'I heard: ...' line of a subscriber's log."""
    return [(int(sec), int(data)) for sec, _nanosec, data in HEARD.findall(log)]


@check(points=2, timeout=60)
def together(ctx: Context) -> None:
    """The subscriber receives what the publisher publishes: consecutive data, none lost."""
    pub = _start(ctx, PUBLISHER)
    sub = _start(ctx, SUBSCRIBER)
    try:
        waiting.spin_until(lambda: len(_heard(sub.log)) >= 15 or not (sub.running() and pub.running()), scaled(20.0),
                           poll=0.1)
    finally:
        sub.stop(timeout=2)
        pub.stop(timeout=2)
    heard = [d for _, d in _heard(sub.log)]
    steps = {b - a for a, b in pairwise(heard)}
    ok = len(heard) >= 15 and steps == {1}
    ctx.item(ok, f"the subscriber heard {len(heard)} messages, data {heard[:3]}...{heard[-2:]}" +
             ("" if ok else ": expected at least 15 consecutive values within 20 s"))
