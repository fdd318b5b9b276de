"""Look at the running ROS graph from a notebook, the way the ``ros2`` command line does.

These functions give the answers of the ``ros2`` command line from Python, through rclpy's
graph API and the session's hidden tool node (on the pip install, the course's own ``ros2``
command, :mod:`course_lib.ros2cli`, prints them):

==============================  ==========================================
``ros2 node list``              ``graph.node_list()``
``ros2 topic list -t``          ``graph.topic_list(types=True)``
``ros2 topic echo --once /t``   ``graph.topic_echo("/t")``
(the first 5 messages)          ``graph.topic_echo("/t", count=5)``
``ros2 topic hz /t``            ``graph.topic_hz("/t")``
``ros2 topic info -v /t``       ``print(graph.format_topic_info(graph.topic_info("/t")))``
``ros2 node info /talker``      ``print(graph.format_node_info(graph.node_info("/talker")))``
``rqt_graph``                   ``graph.draw_graph()``
==============================  ==========================================

Another process's nodes become visible only after discovery (up to a few seconds), so the first
query after the tool node starts waits, briefly and boundedly, for the graph to settle; pass
``wait_for=[...]`` to wait for particular names.
"""

from __future__ import annotations

import array
import contextlib
import dataclasses
import functools
import importlib
import math
import time

import numpy as np

from course_lib import session

#: Topics every rclpy node has; draw_graph() leaves them out unless asked.
DEFAULT_HIDDEN_TOPICS = ("/rosout", "/parameter_events")

#: Seconds a newly started tool node waits for discovery before its first answer. Fast DDS
#: took about 2 s to show another process's node on the course machines; lower it for a
#: quicker first answer when only this kernel's nodes matter.
SETTLE_SECONDS = 2.5
# After SETTLE_SECONDS the graph must also have stayed the same for _SETTLE_QUIET s (things
# found late bring more with them), but the wait never lasts longer than _SETTLE_MAX s.
_SETTLE_POLL = 0.05
_SETTLE_QUIET = 0.3
_SETTLE_MAX = 5.0
_settled_node = None


# --- the tool node and the settling wait -------------------------------------------------

def _graph_node():
    """The session's tool node, after a bounded wait for discovery on its first use."""
    node = session.tool_node()
    if _settled_node is not node:
        wait_for_discovery()
    return node


def wait_for_discovery(minimum: float | None = None, quiet: float = _SETTLE_QUIET,
                       complete_within: float = 0.0) -> None:
    """Wait until discovery has shown the graph to the tool node; later queries do not wait.

    The functions of this module call it on the tool node's first use, with the defaults;
    the ``ros2`` command calls it first with its own (--spin-time, or no wait at all for a
    verb that waits for the name it is given).

    Args:
        minimum: seconds after the tool node's creation to wait at least (default
            SETTLE_SECONDS).
        quiet: then wait until the graph has not changed for this long.
        complete_within: also wait, up to this many seconds after the tool node's creation,
            while the graph shows fewer nodes of other processes than there are other DDS
            participants on this machine in this domain (each ROS process has one, holding its
            nodes). On a busy machine some of them take seconds to be discovered.

    The wait never lasts longer than 5 s after the tool node's creation.
    """
    global _settled_node
    node = session.tool_node()
    minimum = SETTLE_SECONDS if minimum is None else minimum
    others_here = _participants_here(node.context.get_domain_id()) - 1 if complete_within else 0
    ours = 1 + len(session.nodes())  # the nodes of this process share its participant
    last = _snapshot(node)
    quiet_since = time.monotonic()
    while True:
        now = time.monotonic()
        age = now - node.created_at
        missing = age < complete_within and len(last[0]) - ours < others_here
        if age >= _SETTLE_MAX or (age >= minimum and now - quiet_since >= quiet and not missing):
            break
        time.sleep(_SETTLE_POLL)
        current = _snapshot(node)
        if current != last:
            last, quiet_since = current, time.monotonic()
    _settled_node = node


def _participants_here(domain_id: int) -> int:
    """How many DDS participants run on this machine in a domain.

    Each binds the UDP port 7400 + 250 * domain + 10 + 2 * (its participant id) for discovery
    traffic (the RTPS standard port mapping), so /proc/net/udp tells. 0 when it cannot.
    """
    first = 7410 + 250 * domain_id
    ports = set()
    for table in ("/proc/net/udp", "/proc/net/udp6"):
        try:
            with open(table) as handle:
                rows = handle.read().splitlines()[1:]
        except OSError:
            continue
        for row in rows:
            port = int(row.split()[1].rsplit(":", 1)[1], 16)
            if first <= port < first + 240 and (port - first) % 2 == 0:
                ports.add(port)
    return len(ports)


def _snapshot(node):
    return (sorted(node.get_fully_qualified_node_names()),
            sorted((name, tuple(types)) for name, types in node.get_topic_names_and_types()))


def _wait_until(condition, timeout: float) -> bool:
    return session.wait_for(condition, timeout=timeout, poll=0.05)


def _unsubscribe(node, subscription, topic: str, timeout: float = 1.0) -> None:
    """Destroy a tool-node subscription and wait until the graph no longer shows it.

    The executor may hold the subscription in its current wait set, which defers the
    destruction for a moment; waiting keeps a following topic_info() from showing it.
    """
    node.destroy_subscription(subscription)
    _wait_until(lambda: not any(info.node_name == node.get_name()
                                for info in node.get_subscriptions_info_by_topic(topic)),
                timeout)


def _full_name(namespace: str, name: str) -> str:
    return namespace.rstrip("/") + "/" + name


def _is_hidden(name: str) -> bool:
    # Like rclpy's topic_or_service_is_hidden: any token of the name that starts with "_".
    return any(token.startswith("_") for token in name.split("/") if token)


# --- ros2 node list / ros2 topic list ----------------------------------------------------

def node_list(all: bool = False, wait_for=(), timeout: float = 5.0) -> list[str]:  # noqa: A002
    """The running nodes, like ``ros2 node list``.

    Args:
        all: also list hidden nodes (names starting with "_"), like ``ros2 node list -a``.
        wait_for: full node names to wait for, e.g. ``["/talker"]``; useful right after
            starting another process.
        timeout: seconds to wait for the names in ``wait_for``; if they do not show up by
            then, the list is returned without them.

    Returns:
        Sorted fully-qualified names. A name listed twice means two nodes share it.
    """
    node = _graph_node()
    wanted = [name if name.startswith("/") else "/" + name for name in wait_for]

    def names():
        return node.get_fully_qualified_node_names()

    if wanted:
        _wait_until(lambda: set(wanted) <= set(names()), timeout)
    # Like ros2 node list: a node is hidden when its own name (not namespace) starts with "_".
    return sorted(name for name in names()
                  if all or not name.rsplit("/", 1)[-1].startswith("_"))


def topic_list(types: bool = False, include_hidden: bool = False, wait_for=(),
               timeout: float = 5.0):
    """The topics anyone publishes or subscribes to, like ``ros2 topic list``.

    Args:
        types: give ``(name, [type, ...])`` pairs instead of names, like ``ros2 topic list -t``.
        include_hidden: also list hidden topics (a name part starting with "_").
        wait_for: topic names to wait for.
        timeout: seconds to wait for the names in ``wait_for``.

    Returns:
        Sorted topic names, or sorted (name, types) pairs.
    """
    node = _graph_node()
    wanted = [node.resolve_topic_name(name) for name in wait_for]

    def current():
        return node.get_topic_names_and_types()

    if wanted:
        _wait_until(lambda: set(wanted) <= {name for name, _ in current()}, timeout)
    pairs = sorted((name, list(kinds)) for name, kinds in current()
                   if include_hidden or not _is_hidden(name))
    return pairs if types else [name for name, _ in pairs]


# --- message types ----------------------------------------------------------------------

def message_class(type_name: str):
    """The Python class of a message type name.

    Args:
        type_name: "std_msgs/msg/String" (the form the graph reports) or "std_msgs/String".

    Returns:
        The message class, e.g. ``std_msgs.msg.String``.

    Raises:
        ValueError: the name is malformed, or its package is not installed (the message says
            which pip package provides it).
    """
    parts = type_name.split("/")
    if len(parts) == 2:
        parts = [parts[0], "msg", parts[1]]
    if len(parts) != 3 or not all(parts):
        raise ValueError(f"Message type {type_name!r} is not of the form 'package/msg/Type', "
                         "e.g. 'std_msgs/msg/String'")
    package, kind, name = parts
    try:
        module = importlib.import_module(f"{package}.{kind}")
    except ModuleNotFoundError:
        raise ValueError(f"Cannot import the message type {type_name}: its package {package} is "
                         f"not installed; install ros-jazzy-{package.replace('_', '-')} "
                         "(pip) or build it in your colcon workspace and source it") from None
    try:
        return getattr(module, name)
    except AttributeError:
        raise ValueError(f"Package {package} has no {kind} type {name!r}; check the spelling "
                         f"(`ros2 topic list -t` or graph.topic_list(types=True) shows the types in use)") from None


def _topic_class(node, topic: str, msg_type, timeout: float | None):
    if msg_type is not None:
        return message_class(msg_type) if isinstance(msg_type, str) else msg_type
    found: list[list[str]] = []

    def known():
        found[:] = [kinds for name, kinds in node.get_topic_names_and_types() if name == topic]
        return bool(found)

    if not _wait_until(known, timeout):
        raise TimeoutError(f"Topic {topic} did not appear in the ROS graph: is its publisher "
                           "running, on the same ROS_DOMAIN_ID? graph.topic_list() shows the "
                           "topics there are, or pass msg_type= to subscribe anyway")
    kinds = found[0]
    if len(kinds) != 1:
        raise ValueError(f"Topic {topic} carries several types {kinds}: pass msg_type= "
                         "to choose one")
    return message_class(kinds[0])


def _matching_qos(node, topic: str, depth: int = 10):
    """A subscription QoS every current publisher can serve, chosen as ``ros2 topic echo`` does."""
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    publishers = node.get_publishers_info_by_topic(topic)
    reliable = bool(publishers) and all(
        p.qos_profile.reliability == ReliabilityPolicy.RELIABLE for p in publishers)
    transient = bool(publishers) and all(
        p.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL for p in publishers)
    return QoSProfile(
        depth=depth,
        reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if transient else DurabilityPolicy.VOLATILE)


# --- ros2 topic echo --------------------------------------------------------------------

@contextlib.contextmanager
def subscription(topic: str, callback, msg_type=None, timeout: float | None = 5.0, qos=None,
                 raw: bool = False):
    """Call ``callback(msg)`` for each message on a topic while a ``with`` block runs.

    What ``ros2 topic echo`` and ``ros2 topic hz`` do between their start and Ctrl-C: the
    session's tool node subscribes, and unsubscribes when the block ends.

    Args:
        topic: the topic name; relative names are resolved like the CLI does.
        callback: called in the session's background thread with each message (the
            serialized bytes when ``raw``).
        msg_type: the message class or type name; None takes it from the graph.
        timeout: seconds to wait for the topic to appear when msg_type is None; None waits
            as long as session.wait_for allows (forever in a live session).
        qos: the subscription's QoS; None chooses one every current publisher can serve.
        raw: deliver serialized messages (no conversion cost, for rates of large messages).

    Yields:
        The resolved topic name.

    Raises:
        TimeoutError: the topic did not appear and no msg_type was given.
    """
    node = _graph_node()
    name = node.resolve_topic_name(topic)
    cls = _topic_class(node, name, msg_type, timeout)
    handle = node.create_subscription(cls, name, callback,
                                      _matching_qos(node, name) if qos is None else qos, raw=raw)
    try:
        yield name
    finally:
        _unsubscribe(node, handle, name)


class EchoTimeout(TimeoutError):
    """Fewer messages than asked for arrived in time; ``messages`` holds those that did."""

    def __init__(self, text: str, messages: list):
        super().__init__(text)
        self.messages = messages


def topic_echo(topic: str, count: int = 1, timeout: float = 5.0, msg_type=None) -> list:
    """Receive messages from a topic, like ``ros2 topic echo --once`` (or N of them).

    Args:
        topic: the topic name; relative names are resolved like the CLI does ("chatter" is
            "/chatter").
        count: how many messages to receive.
        timeout: seconds to wait for the topic to appear and the messages to arrive.
        msg_type: the message class or type name; None takes it from the graph.

    Returns:
        The ``count`` first messages received. ``print(graph.format_messages(msgs))`` shows
        them as ``ros2 topic echo`` would.

    Raises:
        EchoTimeout: fewer than ``count`` messages arrived within ``timeout`` (a TimeoutError;
            its ``messages`` attribute holds those that did).
        TimeoutError: the topic did not appear and no msg_type was given.
    """
    if count < 1:
        raise ValueError(f"count must be at least 1, got {count}")
    deadline = time.monotonic() + timeout
    received: list = []

    def keep(msg):
        if len(received) < count:
            received.append(msg)

    node = _graph_node()
    name = node.resolve_topic_name(topic)
    cls = _topic_class(node, name, msg_type, timeout)
    with subscription(name, keep, cls, qos=_matching_qos(node, name, depth=max(10, count))):
        arrived = _wait_until(lambda: len(received) >= count,
                              max(0.0, deadline - time.monotonic()))
    if not arrived:
        raise EchoTimeout(f"Received {len(received)} of {count} messages on {name} within "
                          f"{timeout} s: is anyone publishing? graph.topic_info({name!r}) "
                          "shows the publishers and their QoS", list(received))
    return received[:count]


def message_to_dict(msg, truncate_length: int | None = 128, no_arr: bool = False,
                    no_str: bool = False):
    """A message as plain dicts, lists and numbers (for printing, JSON or comparisons).

    Converts the way ``ros2 topic echo`` does before it prints YAML.

    Args:
        msg: a ROS message (nested messages and arrays are converted too).
        truncate_length: arrays and strings longer than this keep their first elements and
            end with "..." (ros2 topic echo's default is 128); None keeps everything.
        no_arr: show each array field as its type and length only (echo's ``--no-arr``).
        no_str: show each string field as its length only (echo's ``--no-str``).

    Returns:
        A dict in field order, or the plain value when ``msg`` is not a message.
    """
    if hasattr(msg, "get_fields_and_field_types"):
        return {field: _field_to_plain(getattr(msg, field), slot_type, truncate_length, no_arr, no_str)
                for field, slot_type in zip(msg.get_fields_and_field_types(), msg.SLOT_TYPES)}
    if isinstance(msg, (bytes, bytearray)):
        text = "".join(chr(byte) for byte in msg[:truncate_length])
        return text + "..." if truncate_length is not None and len(msg) > truncate_length else text
    if isinstance(msg, str):
        if no_str:
            return f"<string length: <{len(msg)}>>"
        cut = truncate_length is not None and len(msg) > truncate_length
        return msg[:truncate_length] + "..." if cut else msg
    if isinstance(msg, (np.ndarray, array.array)):
        msg = msg.tolist()
    if isinstance(msg, (list, tuple)):
        items = list(msg)
        cut = truncate_length is not None and len(items) > truncate_length
        items = [message_to_dict(item, truncate_length, no_arr, no_str)
                 for item in (items[:truncate_length] if cut else items)]
        return items + ["..."] if cut else items
    if isinstance(msg, np.generic):
        return msg.item()
    return msg


def _field_to_plain(value, slot_type, truncate_length, no_arr, no_str):
    from rosidl_parser import definition

    if no_arr and isinstance(slot_type, definition.AbstractNestedType):
        element = slot_type.value_type
        element = ("string" if isinstance(element, definition.AbstractString) else
                   "/".join(element.namespaced_name()) if isinstance(element, definition.NamespacedType)
                   else getattr(element, "typename", "unknown"))
        if isinstance(slot_type, definition.Array):
            return f"<array type: {element}[{slot_type.size}]>"
        if isinstance(slot_type, definition.BoundedSequence):
            return f"<sequence type: {element}[{slot_type.maximum_size}], length: {len(value)}>"
        return f"<sequence type: {element}, length: {len(value)}>"
    return message_to_dict(value, truncate_length, no_arr, no_str)


def format_message(msg, truncate_length: int | None = 128, no_arr: bool = False,
                   no_str: bool = False) -> str:
    """One message as YAML, the way ``ros2 topic echo`` prints it (without the "---")."""
    import yaml

    return yaml.safe_dump(message_to_dict(msg, truncate_length, no_arr, no_str), sort_keys=False,
                          default_flow_style=False, allow_unicode=True, width=1 << 30)


def format_messages(messages, truncate_length: int | None = 128) -> str:
    """Messages as ``ros2 topic echo`` prints them: YAML, each followed by a "---" line."""
    return "".join(format_message(msg, truncate_length) + "---\n" for msg in messages)


def fill_message(msg, values) -> list:
    """Set a message's fields from plain values, the way ``ros2 topic pub`` reads its YAML.

    Args:
        msg: the message to fill; it is changed in place.
        values: ``{field: value}``; a nested message takes a dict, an array a list. As in
            ``ros2 topic pub``, ``header: auto`` (a std_msgs/Header) and ``stamp: now`` (a
            builtin_interfaces/Time) mean "the time of each publish".

    Returns:
        One setter per field marked auto/now: call each with a builtin_interfaces/Time
        (``node.get_clock().now().to_msg()``) before publishing.

    Raises:
        ValueError: a field the message does not have, or a value that does not fit its field
            (the message names the field and its type).
    """
    setters: list = []
    _fill(msg, values, setters, "")
    return setters


def _type_name(msg) -> str:
    module = type(msg).__module__.split(".")
    return f"{module[0]}/{module[1]}/{type(msg).__name__}"


def _fill(msg, values, setters: list, path: str) -> None:
    from rosidl_parser import definition

    fields = msg.get_fields_and_field_types()
    if not isinstance(values, dict):
        raise ValueError(f"{path.rstrip('.') or 'The message'} is a {_type_name(msg)} and needs a "
                         f"dictionary of its fields ({', '.join(fields)}), not {values!r}")
    slots = dict(zip(fields, msg.SLOT_TYPES))
    for field, value in values.items():
        where = path + str(field)
        if field not in fields:
            raise ValueError(f"{_type_name(msg)} has no field {field!r}"
                             f"{' (in ' + path.rstrip('.') + ')' if path else ''}; its fields are: "
                             f"{', '.join(fields)}")
        current = getattr(msg, field)
        slot = slots[field]
        if hasattr(current, "get_fields_and_field_types"):
            kind = _type_name(current)
            if value == "auto" and kind == "std_msgs/msg/Header":
                setters.append(functools.partial(setattr, current, "stamp"))
            elif value == "now" and kind == "builtin_interfaces/msg/Time":
                setters.append(functools.partial(setattr, msg, field))
            else:
                _fill(current, value, setters, where + ".")
            continue
        if isinstance(slot, definition.AbstractNestedType) and \
                isinstance(slot.value_type, definition.NamespacedType):
            element = getattr(importlib.import_module(".".join(slot.value_type.namespaces)),
                              slot.value_type.name)
            if not isinstance(value, list):
                raise ValueError(f"{where} ({fields[field]}) needs a list, not {value!r}")
            items = []
            for index, item in enumerate(value):
                items.append(element())
                _fill(items[-1], item, setters, f"{where}[{index}].")
            value = items
        elif isinstance(current, array.array):
            value = _converted(lambda: array.array(current.typecode, value), where, fields[field], value)
        elif isinstance(current, np.ndarray):
            value = _converted(lambda: np.array(value, dtype=current.dtype), where, fields[field], value)
        elif not isinstance(current, list) and type(value) is not type(current):
            value = _converted(lambda: type(current)(value), where, fields[field], value)
        _converted(lambda: setattr(msg, field, value), where, fields[field], value)


def _converted(convert, where: str, field_type: str, value):
    try:
        return convert()
    except (AssertionError, TypeError, ValueError, OverflowError) as error:
        raise ValueError(f"{where} is a {field_type} and cannot take {value!r}"
                         f"{': ' + str(error) if str(error) else ''}") from None


# --- ros2 topic hz ----------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class RateStatistics:
    """The publishing rate of a topic, as ``ros2 topic hz`` reports it.

    Attributes:
        rate: average rate in Hz (1 / mean period).
        min_period, max_period: shortest and longest time between two messages, seconds.
        std_dev: standard deviation of the periods, seconds.
        samples: number of periods measured (what ros2 prints as "window").
    """

    rate: float
    min_period: float
    max_period: float
    std_dev: float
    samples: int

    def __str__(self) -> str:
        return (f"average rate: {self.rate:.3f}\n\tmin: {self.min_period:.3f}s "
                f"max: {self.max_period:.3f}s std dev: {self.std_dev:.5f}s "
                f"window: {self.samples}")


def rate_statistics(times, window: int | None = None) -> RateStatistics:
    """Rate statistics of arrival times.

    Args:
        times: arrival times in seconds, in order of arrival (1-D array-like).
        window: use only the last ``window`` periods; None uses all.

    Returns:
        The statistics of the periods between consecutive arrivals.

    Raises:
        ValueError: fewer than two times, or times that go backwards.
    """
    times = np.asarray(times, dtype=float)
    if times.ndim != 1 or times.size < 2:
        raise ValueError(f"Need at least two arrival times to measure a rate, got {times.size}: "
                         "measure for longer, or check that the topic is published")
    periods = np.diff(times)
    if np.any(periods < 0):
        raise ValueError("Arrival times must not decrease: pass them in order of arrival")
    if window is not None:
        periods = periods[-window:]
    mean = float(periods.mean())
    return RateStatistics(rate=1.0 / mean if mean > 0 else math.inf,
                          min_period=float(periods.min()), max_period=float(periods.max()),
                          std_dev=float(periods.std()), samples=int(periods.size))


def topic_hz(topic: str, window: int = 10000, duration: float = 2.0, timeout: float = 5.0,
             msg_type=None) -> RateStatistics:
    """Measure how often a topic is published, like ``ros2 topic hz``.

    The measurement starts at the first message and lasts ``duration`` seconds (shorter under
    test or grading, see session.time_limit). Messages are not deserialized, so this works
    for large images too.

    Args:
        topic: the topic name.
        window: use only the last ``window`` periods (ros2's ``--window``).
        duration: seconds to measure after the first message.
        timeout: seconds to wait for the topic and its first message.
        msg_type: the message class or type name; None takes it from the graph.

    Returns:
        The rate statistics; ``print()`` shows them like the CLI.

    Raises:
        TimeoutError: no message arrived within ``timeout``.
        ValueError: only one message arrived during the measurement.
    """
    deadline = time.monotonic() + timeout
    times: list[float] = []
    with subscription(topic, lambda _: times.append(time.monotonic()), msg_type, timeout,
                      raw=True) as name:
        if not _wait_until(lambda: bool(times), max(0.0, deadline - time.monotonic())):
            raise TimeoutError(f"No message on {name} within {timeout} s: is anyone "
                               f"publishing? graph.topic_info({name!r}) shows the publishers")
        session.spin_for(duration)
    return rate_statistics(list(times), window)


# --- ros2 topic info -v -----------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class QosSummary:
    """The QoS profile of one endpoint, with policy names as the CLI prints them.

    Durations are in seconds; math.inf means "Infinite". Discovery does not carry the history
    of another endpoint, so history is often "UNKNOWN" and depth 0 there.
    """

    reliability: str
    durability: str
    history: str
    depth: int
    deadline: float
    lifespan: float
    liveliness: str
    liveliness_lease_duration: float


@dataclasses.dataclass(frozen=True)
class Endpoint:
    """One publisher or subscription of a topic."""

    node_name: str
    node_namespace: str
    topic_type: str
    topic_type_hash: str
    endpoint_type: str  # "PUBLISHER" or "SUBSCRIPTION"
    gid: str
    qos: QosSummary

    @property
    def node(self) -> str:
        """The fully-qualified name of the endpoint's node."""
        return _full_name(self.node_namespace, self.node_name)


@dataclasses.dataclass(frozen=True)
class TopicInfo:
    """What ``ros2 topic info -v`` shows about a topic."""

    name: str
    types: list[str]
    publisher_count: int
    subscription_count: int
    publishers: list[Endpoint]
    subscriptions: list[Endpoint]


def _seconds(duration) -> float:
    from rclpy.duration import Infinite

    return math.inf if duration == Infinite else duration.nanoseconds / 1e9


def _endpoint(info) -> Endpoint:
    qos = info.qos_profile
    return Endpoint(
        node_name=info.node_name, node_namespace=info.node_namespace,
        topic_type=info.topic_type, topic_type_hash=str(info.topic_type_hash),
        endpoint_type=info.endpoint_type.name,
        gid=".".join(f"{byte:02x}" for byte in info.endpoint_gid),
        qos=QosSummary(reliability=qos.reliability.name, durability=qos.durability.name,
                       history=qos.history.name, depth=int(qos.depth),
                       deadline=_seconds(qos.deadline), lifespan=_seconds(qos.lifespan),
                       liveliness=qos.liveliness.name,
                       liveliness_lease_duration=_seconds(qos.liveliness_lease_duration)))


_UNKNOWN_NODE = "_NODE_NAME_UNKNOWN_"


def topic_info(topic: str, verbose: bool = True, timeout: float = 2.0) -> TopicInfo:
    """The type and endpoints of a topic, like ``ros2 topic info [-v]``.

    Args:
        topic: the topic name.
        verbose: also collect each endpoint (node, GID, QoS); counts are always there.
        timeout: seconds to wait for the topic to appear in the graph, and again for the
            nodes of its endpoints to be known.

    Returns:
        A TopicInfo; ``print(graph.format_topic_info(info))`` shows it like the CLI.

    Raises:
        ValueError: the topic is unknown (the message lists the topics there are).
    """
    node = _graph_node()
    name = node.resolve_topic_name(topic)
    found: list[list[str]] = []

    def known():
        found[:] = [kinds for other, kinds in node.get_topic_names_and_types() if other == name]
        return bool(found)

    if not _wait_until(known, timeout):
        raise ValueError(f"Unknown topic {name!r}; the topics are {topic_list()}")
    endpoints: list = []

    def named():
        # DDS may report an endpoint before the ROS node it belongs to; its node name then
        # reads _NODE_NAME_UNKNOWN_ for a moment.
        endpoints[:] = [node.get_publishers_info_by_topic(name),
                        node.get_subscriptions_info_by_topic(name)]
        return not any(info.node_name == _UNKNOWN_NODE for infos in endpoints for info in infos)

    _wait_until(named, timeout)
    publishers, subscriptions = endpoints
    return TopicInfo(
        name=name, types=list(found[0]), publisher_count=len(publishers),
        subscription_count=len(subscriptions),
        publishers=[_endpoint(p) for p in publishers] if verbose else [],
        subscriptions=[_endpoint(s) for s in subscriptions] if verbose else [])


class NoPublisher(LookupError):
    """Nothing publishes on a topic that a cell is about to wait on."""


def wait_for_publisher(topic: str, timeout: float = 3.0, hint: str = "") -> int:
    """Wait until some node publishes on ``topic``; say plainly when none does.

    ``ros2 topic info TOPIC`` shows the same count. Call it before waiting for messages, so
    that "0 messages received" is not mistaken for a bug in the subscriber.

    Args:
        topic: the topic name.
        timeout: seconds to wait for a publisher to appear.
        hint: what to run to start the publisher, added to the error.

    Returns:
        How many publishers there are.

    Raises:
        NoPublisher: no publisher appeared within timeout seconds.
    """
    node = _graph_node()
    name = node.resolve_topic_name(topic)
    if _wait_until(lambda: node.count_publishers(name) > 0, timeout):
        return node.count_publishers(name)
    raise NoPublisher(f"No node publishes on {name} (ros2 topic info {name}: Publisher count: 0), so nothing "
                      f"can arrive there.{' ' + hint if hint else ''}")


def _format_duration(seconds: float) -> str:
    return "Infinite" if math.isinf(seconds) else f"{round(seconds * 1e9)} nanoseconds"


def format_endpoint(endpoint: Endpoint) -> str:
    """One endpoint as ``ros2 topic info -v`` prints it."""
    qos = endpoint.qos
    history = f"{qos.history} ({qos.depth})" if qos.history == "KEEP_LAST" else qos.history
    return "\n".join([
        f"Node name: {endpoint.node_name}",
        f"Node namespace: {endpoint.node_namespace}",
        f"Topic type: {endpoint.topic_type}",
        f"Topic type hash: {endpoint.topic_type_hash}",
        f"Endpoint type: {endpoint.endpoint_type}",
        f"GID: {endpoint.gid}",
        "QoS profile:",
        f"  Reliability: {qos.reliability}",
        f"  History (Depth): {history}",
        f"  Durability: {qos.durability}",
        f"  Lifespan: {_format_duration(qos.lifespan)}",
        f"  Deadline: {_format_duration(qos.deadline)}",
        f"  Liveliness: {qos.liveliness}",
        f"  Liveliness lease duration: {_format_duration(qos.liveliness_lease_duration)}",
    ])


def format_topic_info(info: TopicInfo, verbose: bool = True) -> str:
    """A TopicInfo as ``ros2 topic info`` prints it; ``verbose=True`` is ``-v``.

    Like the CLI, the verbose form separates its parts with blank lines and the short form
    does not.
    """
    kinds = info.types[0] if len(info.types) == 1 else str(info.types)
    parts = [f"Type: {kinds}", f"Publisher count: {info.publisher_count}"]
    if verbose:
        parts += [format_endpoint(endpoint) for endpoint in info.publishers]
    parts.append(f"Subscription count: {info.subscription_count}")
    if verbose:
        parts += [format_endpoint(endpoint) for endpoint in info.subscriptions]
    return ("\n\n" if verbose else "\n").join(parts) + "\n"


# --- ros2 node info ---------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class NodeInfo:
    """What ``ros2 node info`` shows about a node: each list holds (name, [types]) pairs."""

    name: str
    subscribers: list[tuple[str, list[str]]]
    publishers: list[tuple[str, list[str]]]
    service_servers: list[tuple[str, list[str]]]
    service_clients: list[tuple[str, list[str]]]
    action_servers: list[tuple[str, list[str]]]
    action_clients: list[tuple[str, list[str]]]


def node_info(name: str, include_hidden: bool = False, timeout: float = 2.0) -> NodeInfo:
    """The topics, services and actions of a node, like ``ros2 node info``.

    Args:
        name: the node's full name, e.g. "/talker" ("talker" is read as "/talker").
        include_hidden: also list hidden names (a part starting with "_").
        timeout: seconds to wait for the node to appear in the graph.

    Raises:
        ValueError: the node is not in the graph (the message lists the nodes there are).
    """
    from rclpy.action import (get_action_client_names_and_types_by_node,
                              get_action_server_names_and_types_by_node)

    full = name if name.startswith("/") else "/" + name
    nodes = node_list(all=True, wait_for=[full], timeout=timeout)
    if full not in nodes:
        raise ValueError(f"Unable to find node '{full}'; the nodes are {node_list()}")
    namespace, _, base = full.rpartition("/")
    namespace = namespace or "/"
    node = _graph_node()

    def shown(pairs):
        return [(topic, list(kinds)) for topic, kinds in pairs if include_hidden or not _is_hidden(topic)]

    return NodeInfo(
        name=full,
        subscribers=shown(node.get_subscriber_names_and_types_by_node(base, namespace)),
        publishers=shown(node.get_publisher_names_and_types_by_node(base, namespace)),
        service_servers=shown(node.get_service_names_and_types_by_node(base, namespace)),
        service_clients=shown(node.get_client_names_and_types_by_node(base, namespace)),
        action_servers=shown(get_action_server_names_and_types_by_node(node, base, namespace)),
        action_clients=shown(get_action_client_names_and_types_by_node(node, base, namespace)))


def format_node_info(info: NodeInfo) -> str:
    """A NodeInfo as ``ros2 node info`` prints it (an empty section leaves an empty line)."""
    lines = [info.name]
    for title, pairs in (("Subscribers", info.subscribers), ("Publishers", info.publishers),
                         ("Service Servers", info.service_servers),
                         ("Service Clients", info.service_clients),
                         ("Action Servers", info.action_servers),
                         ("Action Clients", info.action_clients)):
        lines.append(f"  {title}:")
        lines += [f"    {topic}: {', '.join(kinds)}" for topic, kinds in pairs] or [""]
    return "\n".join(lines) + "\n"


# --- rqt_graph --------------------------------------------------------------------------

def graph_edges(all: bool = False,  # noqa: A002
                hide_topics=DEFAULT_HIDDEN_TOPICS) -> list[tuple[str, str, str]]:
    """Who publishes and who subscribes to what, as (node, topic, "publishes"/"subscribes").

    Args:
        all: keep hidden nodes and topics (like the session's tool node).
        hide_topics: topics to leave out.

    Returns:
        Sorted, de-duplicated triples with fully-qualified names.
    """
    node = _graph_node()
    edges = set()
    for topic, _ in node.get_topic_names_and_types():
        if topic in hide_topics or (not all and _is_hidden(topic)):
            continue
        for kind, infos in (("publishes", node.get_publishers_info_by_topic(topic)),
                            ("subscribes", node.get_subscriptions_info_by_topic(topic))):
            for info in infos:
                if all or not info.node_name.startswith("_"):
                    edges.add((_full_name(info.node_namespace, info.node_name), topic, kind))
    return sorted(edges)


def layered_layout(edges) -> dict:
    """Columns and rows for a left-to-right drawing of a directed graph.

    Each vertex goes one column right of its furthest predecessor (cycles are broken where a
    depth-first walk in name order closes them); within a column, vertices sit near the mean
    row of their predecessors, ties broken by name. The layout depends only on ``edges``.

    Args:
        edges: (source, target) pairs of sortable vertices (names, or tuples of names).

    Returns:
        ``{vertex: (column, row)}``.
    """
    vertices = sorted({v for edge in edges for v in edge})
    successors = {v: sorted({t for s, t in edges if s == v}) for v in vertices}
    # Depth-first walk in name order; edges back to a vertex still on the stack close a cycle.
    on_stack, done, finish_order, forward = set(), set(), [], []
    for root in vertices:
        if root in done:
            continue
        stack = [(root, iter(successors[root]))]
        on_stack.add(root)
        while stack:
            vertex, children = stack[-1]
            child = next(children, None)
            if child is None:
                stack.pop()
                on_stack.discard(vertex)
                done.add(vertex)
                finish_order.append(vertex)
            elif child in on_stack:
                continue  # back edge: ignored for layering
            else:
                forward.append((vertex, child))
                if child not in done:
                    on_stack.add(child)
                    stack.append((child, iter(successors[child])))
    predecessors = {v: sorted({s for s, t in forward if t == v}) for v in vertices}
    column = {}
    for vertex in reversed(finish_order):  # a topological order of the acyclic part
        column[vertex] = max((column[p] + 1 for p in predecessors[vertex]), default=0)
    layout = {}
    for col in range(max(column.values(), default=-1) + 1):
        members = [v for v in vertices if column[v] == col]

        def centre(v):
            rows = [layout[p][1] for p in predecessors[v] if p in layout]
            return (sum(rows) / len(rows) if rows else math.inf, v)

        for row, vertex in enumerate(sorted(members, key=centre)):
            layout[vertex] = (col, row)
    return layout


def draw_graph(ax=None, all: bool = False,  # noqa: A002
               hide_topics=DEFAULT_HIDDEN_TOPICS):
    """Draw nodes (ellipses) and topics (boxes) with publisher -> topic -> subscriber arrows.

    Like rqt_graph's "Nodes/Topics" view, drawn with matplotlib in a fixed layered layout.

    Args:
        ax: a matplotlib Axes to draw into; None makes a new Figure (not through pyplot, so
            a notebook shows it once, as the cell's value).
        all: also draw hidden nodes and topics (the session's tool node).
        hide_topics: topics to leave out; by default /rosout and /parameter_events.

    Returns:
        The matplotlib Figure.
    """
    from matplotlib.figure import Figure

    # Vertices are ("node", name) or ("topic", name): a node and a topic may share a name.
    edges = []
    for node, topic, kind in graph_edges(all=all, hide_topics=hide_topics):
        pair = [("node", node), ("topic", topic)]
        edges.append(tuple(pair if kind == "publishes" else pair[::-1]))
    layout = layered_layout(edges)
    # Nodes without any shown connection still belong in the picture, in a column of their own.
    lonely = sorted({("node", name) for name in node_list(all=all)} - set(layout))
    spare_column = max((c for c, _ in layout.values()), default=-1) + 1
    for row, vertex in enumerate(lonely):
        layout[vertex] = (spare_column, row)
    columns = max((c for c, _ in layout.values()), default=0) + 1
    height = {col: sum(1 for c, _ in layout.values() if c == col) for col in range(columns)}
    rows = max(height.values(), default=1)
    if ax is None:
        figure = Figure(figsize=(max(4.0, 2.4 * columns), max(2.0, 0.9 * rows + 0.8)))
        ax = figure.add_subplot()
    figure = ax.figure
    ax.set_axis_off()
    ax.set_xlim(-0.6, columns - 0.4)
    ax.set_ylim(-0.6 - (rows - 1) / 2, 0.6 + (rows - 1) / 2)
    if not layout:
        ax.text(0, 0, "no nodes found", ha="center", va="center", color="gray")
        return figure
    labels = {}
    for vertex, (col, row) in sorted(layout.items()):
        kind, name = vertex
        style = (dict(boxstyle="square,pad=0.4", facecolor="#fff2cc", edgecolor="#b58900")
                 if kind == "topic" else
                 dict(boxstyle="ellipse,pad=0.3", facecolor="#dbe9f6", edgecolor="#1f4e79"))
        labels[vertex] = ax.text(col, (height[col] - 1) / 2 - row, name, ha="center",
                                 va="center", fontsize=9, bbox=style, zorder=2)
    for source, target in edges:
        ax.annotate("", xy=labels[target].get_position(), xytext=labels[source].get_position(),
                    arrowprops=dict(arrowstyle="-|>", color="#444444", shrinkA=0, shrinkB=0,
                                    mutation_scale=12,
                                    patchA=labels[source].get_bbox_patch(),
                                    patchB=labels[target].get_bbox_patch()),
                    # Above the labels: their boxes, which clip the arrow, are sized as they
                    # are drawn, so they must be drawn first.
                    zorder=3)
    return figure
