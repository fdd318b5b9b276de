"""The self-check of lesson 05's exercise: ``read_topic(bag_path, topic, message_class)``, the
messages of one topic of a recorded bag with their times.

The check writes a small bag of its own (course_lib.bag_files, as ``ros2 bag record`` writes one):
known ``/brightness`` values at known times, ``/chatter`` strings between them, and one message
written after a later one (a bag's file is in the order messages were written; the times say
when they were received). It then asks the student's function for each topic.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from course_lib.selfcheck.verdicts import Verdict, _call, _not_a_function, _verdict

#: The check's bag: seconds after its start -> brightness, and the /chatter lines between.
BRIGHTNESS = {0.0: 120, 0.1: 121, 0.25: 119, 0.5: 200, 1.0: 3}
CHATTER = {0.05: "hello", 0.3: "world", 0.7: "again"}
#: Where the bag's clock starts (ns since the epoch): a bag's times are wall-clock times.
START_NS = 1_700_000_000_123_456_789


def write_check_bag(folder: Path) -> Path:
    """Write the check's bag (BRIGHTNESS and CHATTER) into folder/check_bag and return its path."""
    from rclpy.qos import qos_profile_sensor_data, qos_profile_system_default
    from rclpy.serialization import serialize_message
    from std_msgs.msg import String, UInt8

    from course_lib.ros import bag_files, bag_metadata

    path = Path(folder) / "check_bag"
    bag = bag_files.BagWriter(path)
    bag.add_topic("/brightness", "std_msgs/msg/UInt8", [bag_metadata.qos_to_dict(qos_profile_sensor_data)])
    bag.add_topic("/chatter", "std_msgs/msg/String", [bag_metadata.qos_to_dict(qos_profile_system_default)])
    messages = [(t, "/brightness", UInt8(data=v)) for t, v in BRIGHTNESS.items()]
    messages += [(t, "/chatter", String(data=text)) for t, text in CHATTER.items()]
    messages.sort(key=lambda entry: entry[0])
    messages.append(messages.pop(2))  # written late: its time, not its place in the file, orders it
    for seconds, topic, message in messages:
        stamp = START_NS + round(seconds * 1e9)
        bag.write(topic, serialize_message(message), log_time=stamp, publish_time=stamp)
    bag.close()
    return path


def read_topic_exercise(read_topic) -> Verdict:
    """Check ``read_topic(bag_path, topic, message_class)``: a list of (seconds since the topic's
    first message, message) in the order of their times, only that topic's messages."""
    from std_msgs.msg import String, UInt8

    hint = "Write read_topic(bag_path, topic, message_class) in the cell above and run it."
    if (result := _not_a_function(read_topic, "read_topic", hint)) is not None:
        return result
    with tempfile.TemporaryDirectory(prefix="read-topic-check-") as folder:
        bag = write_check_bag(Path(folder))
        for topic, message_class, expected in (("/brightness", UInt8, BRIGHTNESS), ("/chatter", String, CHATTER)):
            got, failed = _call(read_topic, str(bag), topic, message_class)
            if failed is not None:
                return failed
            problem = _series_problem(got, topic, message_class, expected)
            if problem:
                return _verdict(False, f"read_topic(bag, {topic!r}, {message_class.__name__}): {problem}")
    return _verdict(True, "read_topic returns each topic's messages with their seconds since the topic's first "
                          "message, in time order.")


def _series_problem(got, topic: str, message_class, expected: dict) -> str | None:
    """What is wrong with one answer of read_topic (None: nothing)."""
    times, values = list(expected), list(expected.values())
    if not isinstance(got, (list, tuple)) or not all(isinstance(p, (list, tuple)) and len(p) == 2 for p in got):
        return f"returned {type(got).__name__} {got!r:.80}; return a list of (seconds, message) pairs."
    if len(got) != len(values):
        return (f"returned {len(got)} pairs, but the bag holds {len(values)} messages on {topic} "
                f"(and {len(BRIGHTNESS) + len(CHATTER) - len(values)} on the other topic: read only {topic}).")
    if not all(isinstance(message, message_class) for _, message in got):
        kinds = sorted({type(message).__name__ for _, message in got})
        return (f"the messages are {', '.join(kinds)}, not {message_class.__name__}: deserialize each with "
                "rclpy.serialization.deserialize_message(data, message_class).")
    seconds = [float(t) for t, _ in got]
    if [m.data for _, m in got] != values:
        if sorted(m.data for _, m in got) == sorted(values):
            return "the messages are not in the order of their times (read with log_time_order=True, or sort)."
        return f"the values are {[m.data for _, m in got]}, expected {values}."
    if abs(seconds[0] - START_NS * 1e-9) < 1.0 or abs(seconds[0] - START_NS) < 1e9:
        return "the times are the bag's clock; subtract the time of the topic's first message."
    if abs(seconds[-1] - (times[-1] - times[0]) * 1e9) < 1.0:
        return "the times are in nanoseconds: divide by 1e9 for seconds."
    if any(abs(s - (t - times[0])) > 1e-6 for s, t in zip(seconds, times, strict=True)):
        return f"the times are {[round(s, 3) for s in seconds]}, expected {[t - times[0] for t in times]}."
    return None
