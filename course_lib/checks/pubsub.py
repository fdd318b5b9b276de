"""Checks of the pubsub assignment: a counter publisher and a subscriber that records what it hears.

The contract (also in the notebook and in assignments/README.md). Until the course's own
MsgTutorial message exists, the message is the stock ``std_msgs/msg/Header``: ``stamp`` is the
time of publishing and ``frame_id`` holds the counter as decimal text.

- ``CounterPublisher()``: node ``counter_publisher``; publishes on ``ros_tutorial_msg`` with a
  queue depth of 100, at 10 Hz (a 0.1 s timer); counter 0, 1, 2, ... (one more per message);
  each stamp later than the one before.
- ``CounterSubscriber()``: node ``counter_subscriber``; subscribes ``ros_tutorial_msg`` with a
  queue depth of 100; appends ``(stamp, counter)`` to ``self.received`` and logs
  ``I heard: <counter>`` for each message.
- ``main_publisher(args=None)`` and ``main_subscriber(args=None)`` run one node each until Ctrl-C.
"""

from __future__ import annotations

import re
import time

from course_lib.checks import runner
from course_lib.checks.context import Context, StudentError, clip
from course_lib.checks.registry import check

ASSIGNMENT = "pubsub"
TOPIC = "/ros_tutorial_msg"
RATE_HZ = 10.0
#: Relative tolerance of the measured rate (from the message stamps).
RATE_TOLERANCE = 0.15
QUEUE_DEPTH = 100
HEARD = re.compile(r"I heard: (-?\d+)")


def selfcheck(name: str):
    """Run check `name` with the self-check seed and print what is right and wrong."""
    return runner.selfcheck(ASSIGNMENT, name)


def grade(name: str):
    """Run check `name` with a fresh seed (grading)."""
    return runner.grade(ASSIGNMENT, name)


def _stamp_seconds(stamp) -> float:
    return stamp.sec + stamp.nanosec * 1e-9


def _queue_depth(ctx, class_name: str, kind: str) -> None:
    """One item: the node's endpoint on the topic keeps the last QUEUE_DEPTH messages. A running
    node's depth is not visible to other processes (DDS discovery does not carry it), so the
    class is constructed in a student process of its own and asked."""
    try:
        found = [e for e in ctx.endpoints(class_name)[kind] if e["topic"] == TOPIC]
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


def _wait_node(ctx, probe, proc, name: str) -> bool:
    found = probe.spin_until(lambda: name in {n for n, _ in probe.node.get_node_names_and_namespaces()}
                             or not proc.running(), 25.0)
    if not proc.running():
        ctx.item(False, f"the process ended ({proc.describe_exit()}) before node {name} appeared:\n"
                        f"{clip(proc.log_tail(6))}")
        return False
    if not found:
        names = sorted(n for n, _ in probe.node.get_node_names_and_namespaces() if not n.startswith("autograder"))
        ctx.item(False, f"no node named {name} within 25 s (nodes seen: {names}): pass '{name}' to super().__init__()")
        return False
    return ctx.precondition(True, f"node {name} runs")


@check(points=5, timeout=60)
def publisher(ctx: Context) -> None:
    """CounterPublisher: std_msgs/Header on ros_tutorial_msg at 10 Hz, counter +1 per message, increasing stamps."""
    from std_msgs.msg import Header

    _queue_depth(ctx, "CounterPublisher", "publishers")
    proc = ctx.start_node(entry="main_publisher")
    try:
        with ctx.probe() as probe:
            messages = []
            probe.node.create_subscription(Header, TOPIC, messages.append, 100)
            if not _wait_node(ctx, probe, proc, "counter_publisher"):
                return
            types = dict(probe.node.get_topic_names_and_types())
            if not probe.spin_until(lambda: len(messages) > 0, 5.0):
                types = dict(probe.node.get_topic_names_and_types())
                ctx.item(False, f"nothing arrived on {TOPIC} within 5 s (topics: "
                                f"{ {t: v for t, v in types.items() if not t.startswith('/rosout') and not t.startswith('/parameter')} }); "
                                "publish std_msgs/msg/Header on 'ros_tutorial_msg' from a 0.1 s timer")
                return
            probe.spin_for(3.0)
    finally:
        proc.stop(timeout=2)
    types = types.get(TOPIC, [])
    ctx.item(types == ["std_msgs/msg/Header"], f"{TOPIC} carries {types}" +
             ("" if types == ["std_msgs/msg/Header"] else "; the contract says std_msgs/msg/Header"))
    counters = []
    for msg in messages:
        try:
            counters.append(int(msg.frame_id))
        except ValueError:
            ctx.item(False, f"frame_id is {msg.frame_id!r}; it must hold the counter as text, str(self.count)")
            return
    steps = {b - a for a, b in zip(counters, counters[1:])}
    ctx.item(steps == {1}, f"counters {counters[:4]}...{counters[-2:]}: " +
             ("one more per message" if steps == {1} else f"steps {sorted(steps)[:5]}; add one per message"))
    stamps = [_stamp_seconds(m.stamp) for m in messages]
    increasing = all(b > a for a, b in zip(stamps, stamps[1:]))
    ctx.item(increasing, "stamps increase" if increasing else
             "stamps do not increase: set msg.stamp = self.get_clock().now().to_msg() when publishing")
    if len(stamps) >= 5 and stamps[-1] > stamps[0]:
        rate = (len(stamps) - 1) / (stamps[-1] - stamps[0])
        ok = abs(rate - RATE_HZ) <= RATE_TOLERANCE * RATE_HZ
        ctx.item(ok, f"rate {rate:.2f} Hz from the stamps of {len(stamps)} messages" +
                 ("" if ok else f"; the contract asks for {RATE_HZ:g} Hz: create_timer(0.1, ...)"))
    else:
        ctx.item(False, f"only {len(stamps)} messages with usable stamps in 3 s: cannot measure a 10 Hz rate")


@check(points=3, timeout=60)
def subscriber(ctx: Context) -> None:
    """CounterSubscriber: node counter_subscriber hears every message on ros_tutorial_msg and logs 'I heard: N'."""
    from std_msgs.msg import Header

    _queue_depth(ctx, "CounterSubscriber", "subscriptions")
    first = int(ctx.rng.integers(100, 10000))
    sent = list(range(first, first + 20))
    proc = ctx.start_node(entry="main_subscriber")
    try:
        with ctx.probe() as probe:
            pub = probe.node.create_publisher(Header, TOPIC, 100)
            if not _wait_node(ctx, probe, proc, "counter_subscriber"):
                return
            if not probe.spin_until(lambda: pub.get_subscription_count() > 0, 5.0):
                ctx.item(False, f"counter_subscriber does not subscribe {TOPIC}: "
                                "create_subscription(Header, 'ros_tutorial_msg', self.callback, 100)")
                return
            probe.spin_for(0.3)
            for counter in sent:
                msg = Header(frame_id=str(counter))
                msg.stamp = probe.node.get_clock().now().to_msg()
                pub.publish(msg)
                probe.spin_for(0.05)
            probe.spin_until(lambda: sent[-1] in _heard(proc.log), 3.0)
    finally:
        proc.stop(timeout=2)
    heard = _heard(proc.log)
    ok = heard == sent
    ctx.item(ok, f"logged 'I heard: N' for all {len(sent)} messages in order" if ok else
             f"sent counters {sent[0]}..{sent[-1]}, the log shows {heard[:6]}{'...' if len(heard) > 6 else ''}: "
             "log self.get_logger().info(f'I heard: {counter}') for every message", weight=2)


def _heard(log: str) -> list[int]:
    return [int(n) for n in HEARD.findall(log)]


@check(points=2, timeout=60)
def together(ctx: Context) -> None:
    """The subscriber receives what the publisher publishes: consecutive counters, none lost."""
    pub = ctx.start_node(entry="main_publisher")
    sub = ctx.start_node(entry="main_subscriber")
    try:
        deadline = time.monotonic() + 20.0
        while time.monotonic() < deadline and len(_heard(sub.log)) < 15 and sub.running() and pub.running():
            time.sleep(0.1)
    finally:
        sub.stop(timeout=2)
        pub.stop(timeout=2)
    heard = _heard(sub.log)
    steps = {b - a for a, b in zip(heard, heard[1:])}
    ok = len(heard) >= 15 and steps == {1}
    ctx.item(ok, f"the subscriber heard {len(heard)} messages, counters {heard[:3]}...{heard[-2:]}" +
             ("" if ok else ": expected at least 15 consecutive counters within 20 s"))
