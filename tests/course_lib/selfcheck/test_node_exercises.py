"""Tests for course_lib.selfcheck.node_exercises: the exercises of lessons 01 (a publisher) and 01b
(the MsgTutorial subscriber), run in the notebook's session."""

import re

import pytest
from rclpy.node import Node
from std_msgs.msg import Header

from course_lib import selfcheck
from course_lib.ros import discovery, session


def _announcer(period=0.5, topic="announcements", text="Announcement {}", msg_type=None, timer=True, depth=10,
               publish=True):
    """A publisher node class for the lesson 01 exercise, right by default, wrong as asked."""
    from std_msgs.msg import String

    class Announcer(Node):
        def __init__(self):
            super().__init__("announcer")
            self.count = 0
            self.publisher = self.create_publisher(msg_type or String, topic, depth)
            if timer:
                self.create_timer(period, self.announce)

        def announce(self):
            if publish:
                self.publisher.publish(String(data=text.format(self.count)))
            self.count += 1

    return Announcer


class AnnouncerStub(Node):
    def __init__(self):
        super().__init__("announcer")
        self.count = 0
        # TODO: a publisher and a timer


@pytest.fixture
def exercise_session(domain_id, monkeypatch):
    monkeypatch.setattr(discovery, "SETTLE_SECONDS", 0)
    session.start(domain_id=domain_id)
    yield
    session.stop()


def test_publisher_exercise_passes_a_correct_node(exercise_session):
    verdict = selfcheck.publisher_exercise(_announcer())
    assert verdict, verdict
    assert session.nodes() == []  # the check removes the node it ran


@pytest.mark.parametrize("answer, named", [
    (None, "Not done yet"),
    (AnnouncerStub, "Not done yet: the node has no publisher"),
    (_announcer(topic="announcement"), "not on /announcements"),
    (_announcer(timer=False), "Not done yet: the node has no timer"),
    (_announcer(publish=False), "but no message arrived on /announcements after"),
    (_announcer(text="Announcement"), "'Announcement 0', then"),
    (_announcer(period=0.1), "every 0.1 s; the exercise asks for every 0.5 s"),
    (_announcer(depth=1), "queue depth 1; the exercise asks for 10"),
])
def test_publisher_exercise_names_what_is_wrong(exercise_session, answer, named):
    verdict = selfcheck.publisher_exercise(answer)
    assert not verdict and named in str(verdict), verdict


#: A call written out with its arguments, as in "self.create_publisher(String, 'announcements', 10)".
CALL_WITH_ARGUMENTS = re.compile(r"\w+\([^()]*,[^()]*\)")


@pytest.mark.parametrize("stub, named", [
    (AnnouncerStub, "no publisher"),
    (_announcer(timer=False), "no timer"),
])
def test_publisher_exercise_stub_hints_say_what_to_do_without_the_line_to_write(exercise_session, stub, named):
    text = str(selfcheck.publisher_exercise(stub))
    assert "Not done yet" in text and named in text and not CALL_WITH_ARGUMENTS.search(text), text


@pytest.mark.parametrize("period", [2.0, 5.0])
def test_publisher_exercise_judges_the_timer_period_the_node_has(exercise_session, period):
    """A slow timer fails by its period, read from the node's timer (not from how many messages came
    in a moment): a 2 s timer does not pass as "every 0.5 s", a 5 s one is not "no timer"."""
    verdict = selfcheck.publisher_exercise(_announcer(period=period))
    assert not verdict and f"every {period:g} s; the exercise asks for every 0.5 s" in str(verdict), verdict
    assert "create a timer" not in str(verdict)


def _tutorial_listener(keep, topic="ros_tutorial_msg", msg_type=Header, depth=100):
    class TutorialListener(Node):
        def __init__(self):
            super().__init__("tutorial_listener")
            self.received = []
            self.create_subscription(msg_type, topic, self.on_message, depth)

        def on_message(self, msg):
            self.received.append(keep(msg))

    return TutorialListener


def _stamp(msg):
    return msg.stamp.sec + msg.stamp.nanosec * 1e-9


class ListenerStub(Node):
    def __init__(self):
        super().__init__("tutorial_listener")
        self.received = []


@pytest.mark.parametrize("answer, named", [
    (_tutorial_listener(lambda msg: (_stamp(msg), int(msg.frame_id))), None),
    (None, "Not done yet"),
    (ListenerStub, "Not done yet: the node has no subscription"),
    (_tutorial_listener(lambda msg: (msg.stamp.sec, int(msg.frame_id))), "lost its nanoseconds"),
    (_tutorial_listener(lambda msg: (int(msg.frame_id), _stamp(msg))), "(stamp, data), not (data, stamp)"),
    (_tutorial_listener(lambda msg: (_stamp(msg), int(msg.frame_id)), topic="chatter"), "not to /ros_tutorial_msg"),
    (_tutorial_listener(lambda msg: (_stamp(msg), 0)), "has none of them"),
    (_tutorial_listener(lambda msg: (_stamp(msg), int(msg.frame_id)), depth=10),
     "queue depth 10; the exercise asks for 100"),
])
def test_subscriber_exercise(exercise_session, answer, named):
    """Header stands in for MsgTutorial (its counter in frame_id), as in lesson 01b without a build."""
    verdict = selfcheck.subscriber_exercise(answer, Header)
    if named is None:
        assert verdict, verdict
    else:
        assert not verdict and named in str(verdict), verdict


def test_subscriber_exercise_stub_hint_says_what_to_do_without_the_line_to_write(exercise_session):
    text = str(selfcheck.subscriber_exercise(ListenerStub, Header))
    assert "Not done yet" in text and not CALL_WITH_ARGUMENTS.search(text), text


def test_subscriber_exercise_with_a_data_field(exercise_session):
    """With a message that has a data field (as MsgTutorial has), data is the counter."""
    from builtin_interfaces.msg import Time  # noqa: F401 (Header's stamp type)
    from std_msgs.msg import Int32

    wrong_type = _tutorial_listener(lambda msg: (_stamp(msg), msg.data), msg_type=Int32)
    assert "sends std_msgs/msg/Header" in str(selfcheck.subscriber_exercise(wrong_type, Header))


