"""rqt_plot's paths: a topic followed by the path of a numeric field, read from each message.

``"/odom/pose/pose/position/x"`` names the topic ``/odom`` (the longest prefix that is a topic in
the graph) and the field ``pose.pose.position.x`` of its ``nav_msgs/Odometry``; ``"/scan/ranges[0]"``
an element of an array; a topic alone (``"/brightness"``) its only number. :mod:`course_lib.notebook.live`
plots what :func:`resolve_field_path` reads. A path that names no number gets an error that lists
the numeric fields there are.
"""

from __future__ import annotations

import re

from course_lib import waiting
from course_lib.ros import message_yaml

#: Field types a plot can draw (rosidl's names).
NUMBER_TYPES = {"boolean", "octet", "byte", "char", "float", "double", "int8", "uint8", "int16", "uint16",
                "int32", "uint32", "int64", "uint64"}

_STEP = re.compile(r"(\w+)(?:\[(\d+)\])?")


def resolve_field_path(tool, path: str, msg_type=None, timeout: float = 5.0):
    """Split an rqt_plot path into its topic and a numeric field of the topic's message.

    Args:
        tool: a node to look at the graph with.
        path: e.g. "/odom/pose/pose/position/x", "/scan/ranges[0]", "/brightness".
        msg_type: the message class or type name; None takes the topic and its type from the graph.
        timeout: seconds to wait for a topic of the path to appear in the graph.

    Returns:
        (the path as plotted, topic, message class, a function of a message that returns the number).

    Raises:
        ValueError: no numeric field at that path, with the fields there are.
        TimeoutError: no prefix of the path is a topic in the graph (and no msg_type given).
    """
    name = path.rstrip("/") if path.startswith("/") else "/" + path.rstrip("/")
    if msg_type is not None:
        cls = message_yaml.message_class(msg_type) if isinstance(msg_type, str) else msg_type
        problem = None
        for topic in _topic_prefixes(name):  # the longest topic whose rest is a field of msg_type
            try:
                return name, topic, cls, _field_reader(cls, name[len(topic):], topic)
            except ValueError as error:
                problem = error
        raise problem
    topics, found = {}, []

    def known():
        topics.clear()
        topics.update(tool.get_topic_names_and_types())
        found[:] = [t for t in _topic_prefixes(name) if t in topics][:1]
        return bool(found)

    if not waiting.spin_until(known, timeout):
        raise TimeoutError(f"No topic in the ROS graph begins {name}: is its publisher running, on the "
                           f"same ROS_DOMAIN_ID? graph.topic_list() shows the topics there are, or pass "
                           f"msg_type= to plot before it appears")
    topic = found[0]
    kinds = topics[topic]
    if len(kinds) != 1:
        raise ValueError(f"Topic {topic} carries several types {kinds}: pass msg_type= to choose one")
    cls = message_yaml.message_class(kinds[0])
    return name, topic, cls, _field_reader(cls, name[len(topic):], topic)


def _topic_prefixes(name: str) -> list[str]:
    """Where a path's topic may end, longest first: the whole path, then before each "/"."""
    return [name] + [name[:i] for i in range(len(name) - 1, 0, -1) if name[i] == "/"]


def _element_type(kind: str) -> tuple[str, bool]:
    """rosidl's field type as (element type, is an array): "sequence<float>" -> ("float", True)."""
    sequence = re.fullmatch(r"sequence<(.+?)(?:, ?\d+)?>", kind)
    if sequence:
        return sequence.group(1), True
    array = re.fullmatch(r"(.+)\[\d*\]", kind)
    if array:
        return array.group(1), True
    return kind, False


def _field_reader(cls, rest: str, topic: str):
    """A function of a message that reads the number at `rest` ("/pose/position/x"; "" for the only one)."""
    steps = [part for part in rest.split("/") if part]
    if not steps:
        numbers = [field for field, kind in cls.get_fields_and_field_types().items() if kind in NUMBER_TYPES]
        if len(numbers) != 1:
            raise ValueError(f"{topic} ({_type_name(cls)}) does not hold one number: plot one of its fields, "
                             f"e.g. {_field_examples(cls, topic)}")
        steps = numbers
    reads = []  # (field, index or None)
    current, where = cls, topic
    for number, step in enumerate(steps):
        if current is None:
            raise ValueError(f"{where} is a number: {'/'.join(steps[number:])} cannot follow it")
        fields = current.get_fields_and_field_types()
        match = _STEP.fullmatch(step)
        if match is None or match.group(1) not in fields:
            raise ValueError(f"{_type_name(current)} at {where} has no field {step!r}; its fields: "
                             f"{', '.join(fields) or 'none'} (numbers, e.g. {_field_examples(current, where)})")
        field, index = match.group(1), match.group(2)
        where = f"{where}/{step}"
        element, is_array = _element_type(fields[field])
        if is_array and index is None:
            raise ValueError(f"{where} is an array ({fields[field]}): plot one element, e.g. {where}[0]")
        if index is not None and not is_array:
            raise ValueError(f"{where} is a {fields[field]}, not an array: drop the [{index}]")
        reads.append((field, None if index is None else int(index)))
        if element in NUMBER_TYPES:
            current = None
        elif "/" in element:
            current = message_yaml.message_class(element)
        else:
            raise ValueError(f"{where} is a {element}, not a number")
    if current is not None:
        raise ValueError(f"{where} is a message ({_type_name(current)}), not a number: go on to one of its "
                         f"fields, e.g. {_field_examples(current, where)}")

    def read(msg):
        value = msg
        for field, index in reads:
            value = getattr(value, field)
            if index is not None:
                value = value[index]
        return value
    return read


def _type_name(cls) -> str:
    return f"{cls.__module__.split('.')[0]}/msg/{cls.__name__}"


def _field_examples(cls, topic: str, limit: int = 3) -> str:
    """Up to `limit` numeric field paths of a message, as plot() takes them."""
    found = []

    def walk(current, prefix, depth):
        for field, kind in current.get_fields_and_field_types().items():
            if len(found) >= limit or depth > 4:
                return
            if kind in NUMBER_TYPES:
                found.append(f"{prefix}/{field}")
            elif "/" in kind and not _element_type(kind)[1]:
                walk(message_yaml.message_class(kind), f"{prefix}/{field}", depth + 1)
    walk(cls, topic, 0)
    return ", ".join(found) or "(it has no numeric fields)"
