"""The exercises of lessons 01 and 01b: a node class of the student's, run in the notebook's session
and judged by what it is (its timers, publishers and subscriptions) and what it does on a topic.
"""

from __future__ import annotations

from itertools import pairwise

from course_lib import progress
from course_lib.selfcheck.verdicts import Verdict, _not_done, _verdict


def _exercise_node(node_or_class, class_name: str, hint: str):
    """(node added to the session, None) or (None, a Verdict) for a student's Node class or instance."""
    from rclpy.node import Node

    from course_lib.ros import session

    if (result := _not_done(node_or_class, hint)) is not None:
        return None, result
    if isinstance(node_or_class, type) and issubclass(node_or_class, Node):
        try:
            node = node_or_class()
        except Exception as error:  # a check never raises on a wrong answer
            return None, _verdict(False, f"Creating {node_or_class.__name__}() raised {type(error).__name__}: {error}")
    elif isinstance(node_or_class, Node):
        node = node_or_class
    else:
        return None, _verdict(False, f"Pass the node class itself ({class_name}, without brackets), not a "
                                     f"{type(node_or_class).__name__}.")
    return session.add_node(node), None


def _message_type_name(cls) -> str:
    module = cls.__module__.split(".")
    return f"{module[0]}/{module[1]}/{cls.__name__}" if len(module) > 1 else cls.__name__


def _endpoint(endpoints: list, topic: str, msg_type, depth: int, call: str, none: str, elsewhere: str,
              wrong_type: str):
    """(the node's publisher or subscription on `topic`, None), or (None, a Verdict): `none` when the
    node has none at all, `elsewhere` (with {names} and {topic}) when they are on other topics,
    `wrong_type` (with {found}) when it carries another type than `msg_type`, and what was found
    and asked when its queue depth is not `depth`; `call` creates it (create_publisher)."""
    if not endpoints:
        return None, _verdict(False, none)
    mine = [e for e in endpoints if e.topic_name == topic]
    if not mine:
        return None, _verdict(False, elsewhere.format(names=", ".join(e.topic_name for e in endpoints), topic=topic))
    if mine[0].msg_type is not msg_type:
        return None, _verdict(False, wrong_type.format(found=_message_type_name(mine[0].msg_type)))
    what = "publisher" if call == "create_publisher" else "subscription"
    return mine[0], _depth_problem(mine[0], depth, what, call)


def _seconds(value: float) -> str:
    return f"{value:g} s"


def _depth_problem(endpoint, asked: int, what: str, call: str) -> Verdict | None:
    """A Verdict when a publisher's or subscription's queue is not the asked depth (found vs asked)."""
    from rclpy.qos import HistoryPolicy

    qos = endpoint.qos_profile
    if qos.history == HistoryPolicy.KEEP_ALL:
        return _verdict(False, f"The {what} keeps all messages (KEEP_ALL history); the exercise asks for a queue "
                               f"depth of {asked}: pass the depth as the last argument of {call}.")
    if qos.depth != asked:
        return _verdict(False, f"The {what} has queue depth {qos.depth}; the exercise asks for {asked}: pass "
                               f"{asked} as the last argument of {call}.")
    return None


@progress.while_running("self-check: running your publisher")
def publisher_exercise(node_or_class, topic: str = "/announcements", prefix: str = "Announcement ",
                       period: float = 0.5, depth: int = 10) -> Verdict:
    """Exercise (lesson 01): a node that publishes std_msgs/String "Announcement N" (N = 0, 1, ...)
    on /announcements (queue depth 10) every 0.5 s. The period is read from the node's timers; then
    the check runs the node until it published three times and listens to it."""
    from std_msgs.msg import String

    from course_lib.checks.context import scaled
    from course_lib.ros import session

    hint = (f"Pass your node class; in __init__ create a publisher of String on {topic.lstrip('/')!r} and a "
            f"timer that calls a method every {_seconds(period)}; the method publishes '{prefix}0', '{prefix}1', ...")
    node, problem = _exercise_node(node_or_class, "Announcer", hint)
    if problem is not None:
        return problem
    tool = session.tool_node()
    heard: list[str] = []
    listener = None
    try:
        publisher, problem = _endpoint(
            [p for p in node.publishers if p.topic_name != "/parameter_events"], topic, String, depth,
            "create_publisher",
            "Not done yet: the node has no publisher. In __init__, create one with self.create_publisher, giving "
            "it the message type, the topic and the queue depth, as the talker of §2 does.",
            "The node publishes on {names}, not on {topic}: check the topic name you pass to create_publisher.",
            "The publisher sends {found}; the exercise asks for std_msgs/msg/String (from std_msgs.msg import "
            "String).")
        if problem is not None:
            return problem
        timers = list(node.timers)
        if not timers:
            return _verdict(False, "Not done yet: the node has no timer. In __init__, create one with "
                                   "self.create_timer, giving it the period in seconds and the method to call, as "
                                   "the talker of §2 does.")
        periods = [timer.timer_period_ns * 1e-9 for timer in timers]
        on_time = [timer for timer, p in zip(timers, periods, strict=True) if abs(p - period) < 1e-3]
        if not on_time:
            found = " and every ".join(_seconds(p) for p in sorted(set(periods)))
            return _verdict(False, f"The node's timer fires every {found}; the exercise asks for every "
                                   f"{_seconds(period)}: the first argument of create_timer is the period in seconds.")
        ticks = _count_calls(on_time[0])
        listener = tool.create_subscription(String, topic, lambda msg: heard.append(msg.data), depth)
        session.wait_for(lambda: publisher.get_subscription_count() > 0, timeout=scaled(5.0))
        ticks.clear()
        # Three messages, or a timer that fired four times without one (one tick's grace for delivery).
        session.wait_for(lambda: len(heard) >= 3 or (not heard and len(ticks) >= 4), timeout=scaled(6 * period + 2))
        if not heard:
            return _verdict(False, f"The node's timer fires every {_seconds(period)}, but no message arrived on "
                                   f"{topic} after {len(ticks)} of its calls: does the method the timer calls "
                                   "publish a String with the node's publisher?")
        numbers = [text[len(prefix):] for text in heard if text.startswith(prefix)]
        if len(numbers) != len(heard) or not all(n.isdigit() for n in numbers):
            return _verdict(False, f"The node sent {heard[0]!r}; the exercise asks for '{prefix}0', then "
                                   f"'{prefix}1', and so on: put the count into the text.")
        counts = [int(n) for n in numbers]
        if any(b != a + 1 for a, b in pairwise(counts)):
            return _verdict(False, f"The numbers go {counts}: count up by one per message, starting from 0.")
        return _verdict(True, f"The node's timer fires every {_seconds(period)} and it publishes {heard[0]!r}, "
                              f"{heard[1] if len(heard) > 1 else '...'!r} ... on {topic}. In a terminal: "
                              f"ros2 topic echo {topic}.")
    finally:
        if listener is not None:
            tool.destroy_subscription(listener)
        try:
            session.remove_node(node)
        except ValueError:  # the student's code removed it already
            pass


def _count_calls(timer) -> list:
    """A list that gets an entry each time `timer`'s callback has run (the executor reads
    timer.callback at every call)."""
    calls: list = []
    callback = timer.callback

    def counted(*args):
        try:
            return callback(*args)
        finally:
            calls.append(None)

    timer.callback = counted
    return calls


@progress.while_running("self-check: running your subscriber")
def subscriber_exercise(node_or_class, msg_type, topic: str = "/ros_tutorial_msg", depth: int = 100) -> Verdict:
    """Exercise (lesson 01b): a node subscribed to ros_tutorial_msg (MsgTutorial, depth 100) that
    appends (stamp in seconds, data) to self.received for every message. The check sends it three
    messages of its own, marked by negative data, and looks at what the node kept."""
    from rclpy.qos import QoSProfile

    from course_lib.ros import session

    hint = (f"Pass your node class; in __init__ set self.received = [] and subscribe to {topic.lstrip('/')!r}; "
            "the callback appends (stamp in seconds, data) for each message.")
    node, problem = _exercise_node(node_or_class, "TutorialListener", hint)
    if problem is not None:
        return problem
    fields = msg_type.get_fields_and_field_types()
    sent = []
    for i in range(3):
        msg = msg_type()
        msg.stamp.sec, msg.stamp.nanosec = 1000 + i, 250_000_000
        value = -1001 - i
        if "data" in fields:
            msg.data = value
        else:  # std_msgs/Header, the stand-in where MsgTutorial could not be built: counter in frame_id
            msg.frame_id = str(value)
        sent.append((msg, (1000.25 + i, value)))
    tool = session.tool_node()
    publisher = None
    try:
        _, problem = _endpoint(
            list(node.subscriptions), topic, msg_type, depth, "create_subscription",
            "Not done yet: the node has no subscription. In __init__, create one with self.create_subscription, "
            "giving it the message type, the topic, the method to call for each message and the queue depth, as "
            "topic_subscriber does.",
            "The node subscribes to {names}, not to {topic}: check the topic name.",
            "The subscription takes {found}; the publisher sends " + _message_type_name(msg_type) + ", so nothing "
            "would ever arrive.")
        if problem is not None:
            return problem
        if not isinstance(getattr(node, "received", None), list):
            return _verdict(False, "Keep what arrives in a list self.received, created empty in __init__ "
                                   "(self.received = []).")
        publisher = tool.create_publisher(msg_type, topic, QoSProfile(depth=depth))
        session.wait_for(lambda: publisher.get_subscription_count() > 0, timeout=3.0)
        for msg, _ in sent:
            publisher.publish(msg)
        expected = [pair for _, pair in sent]
        marks = {value for _, value in expected}

        def kept():
            return [entry for entry in list(node.received)
                    if isinstance(entry, (tuple, list)) and any(v in marks for v in entry if isinstance(v, int))]

        session.wait_for(lambda: len(kept()) >= 3, timeout=2.0)
        got = kept()
        if not got:
            shown = f": it holds {node.received[-1]!r}" if node.received else " and stays empty"
            return _verdict(False, f"The check sent three messages (data -1001, -1002, -1003), but self.received "
                                   f"has none of them{shown}. The callback should append (stamp in seconds, data) "
                                   "for every message.")
        first, want = got[0], expected[0]
        if len(first) != 2:
            return _verdict(False, f"For a message stamped {want[0]} with data {want[1]} the node kept {first!r}; "
                                   "keep a pair (stamp in seconds, data).")
        if first[0] == want[1]:
            return _verdict(False, f"The node kept {tuple(first)!r}: the pair goes (stamp, data), not (data, stamp).")
        if first[0] == int(want[0]):
            return _verdict(False, f"The node kept {tuple(first)!r}: the stamp lost its nanoseconds ({want[0]} was "
                                   "sent). Use msg.stamp.sec + msg.stamp.nanosec * 1e-9.")
        if len(got) < 3:
            return _verdict(False, f"Of three messages sent, {len(got)} reached self.received: append every one.")
        # The first three kept against the three sent (a node may keep more: strict=False).
        if not all(len(a) == 2 and abs(a[0] - b[0]) < 1e-6 and a[1] == b[1]
                   for a, b in zip(got, expected, strict=False)):
            return _verdict(False, f"For the messages {expected} (stamp, data) the node kept "
                                   f"{[tuple(e) for e in got]}.")
        return _verdict(True, f"The node kept {[tuple(e) for e in got]} for the three messages the check sent: "
                              "stamp and data, in order.")
    finally:
        if publisher is not None:
            tool.destroy_publisher(publisher)
        try:
            session.remove_node(node)
        except ValueError:
            pass
