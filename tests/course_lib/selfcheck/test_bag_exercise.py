"""Lesson 05's exercise check (course_lib.selfcheck.bag_exercise): a right read_topic passes, and
each typical mistake gets its own hint."""

from __future__ import annotations

import pytest

from course_lib import selfcheck


def read_topic(bag_path, topic, message_class, *, order=True, scale=1e-9, relative=True, only_topic=True,
               deserialize=True):
    """A right answer (all defaults), or one with a typical mistake."""
    from mcap.reader import make_reader
    from rclpy.serialization import deserialize_message

    from course_lib.ros import bag_files

    found = []
    for file in bag_files.storage_files(bag_path):
        with open(file, "rb") as stream:
            for _, channel, message in make_reader(stream).iter_messages(log_time_order=order):
                if channel.topic == topic or not only_topic:
                    data = deserialize_message(message.data, message_class) if deserialize else message.data
                    found.append((message.log_time, data))
    first = found[0][0] if relative else 0
    return [((t - first) * scale, m) for t, m in found]


def test_a_right_read_topic_passes():
    verdict = selfcheck.read_topic_exercise(read_topic)
    assert verdict, verdict


@pytest.mark.parametrize("mistake, said", [
    ({"order": False}, "not in the order of their times"),
    ({"scale": 1}, "in nanoseconds"),
    ({"relative": False}, "subtract the time of the topic's first message"),
    ({"only_topic": False}, "read only /brightness"),
    ({"deserialize": False}, "deserialize_message"),
])
def test_each_typical_mistake_is_named(mistake, said):
    verdict = selfcheck.read_topic_exercise(lambda *args: read_topic(*args, **mistake))
    assert not verdict and said in str(verdict), verdict


def test_a_stub_is_not_done_yet():
    def stub(bag_path, topic, message_class):
        raise NotImplementedError

    assert "Not done yet" in str(selfcheck.read_topic_exercise(stub))
    assert "Not done yet" in str(selfcheck.read_topic_exercise(None))
