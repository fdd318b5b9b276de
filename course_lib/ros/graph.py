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
``rqt_graph``                   ``rqt_graph.draw_graph()``
==============================  ==========================================

Another process's nodes become visible only after discovery (up to a few seconds), so the first
query after the tool node starts waits, briefly and boundedly, for the graph to settle
(:mod:`course_lib.ros.discovery`); pass ``wait_for=[...]`` to wait for particular names. Messages are
printed and filled by :mod:`course_lib.ros.message_yaml`, rates computed by :mod:`course_lib.ros.rates`,
the answers of ``topic_info`` and ``node_info`` are records of :mod:`course_lib.ros.graph_info`.
"""

from __future__ import annotations

import contextlib
import time

from course_lib.ros import graph_info, node_names, session
from course_lib.ros.discovery import _graph_node
from course_lib.ros.message_yaml import message_class
from course_lib.ros.rates import RateStatistics, rate_statistics

# --- helpers ------------------------------------------------------------------------------

def _wait_until(condition, timeout: float) -> bool:
    return session.wait_for(condition, timeout=timeout, poll=0.05)


def _unsubscribe(node, subscription, topic: str, timeout: float = 10.0) -> None:
    """Destroy a tool-node subscription and wait until the graph no longer shows it.

    The executor may hold the subscription in its current wait set, which defers the
    destruction until the session's thread next runs (a moment, or seconds on a busy machine);
    waiting keeps a following topic_info() from showing it. The timeout is only a backstop.
    """
    node.destroy_subscription(subscription)
    _wait_until(lambda: not any(info.node_name == node.get_name()
                                for info in node.get_subscriptions_info_by_topic(topic)),
                timeout)


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
                   if include_hidden or not node_names.is_hidden(name))
    return pairs if types else [name for name, _ in pairs]


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


def matching_qos(node, topic: str, depth: int = 10):
    """A subscription QoS every current publisher can serve, chosen as ``ros2 topic echo`` and
    rosbag2's recorder (Rosbag2QoS::adapt_request_to_offers) choose it: reliable only if every
    publisher is, transient local only if every publisher is, the history ``depth`` given."""
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
                                      matching_qos(node, name) if qos is None else qos, raw=raw)
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
        The ``count`` first messages received. ``print(message_yaml.format_messages(msgs))`` shows
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
    with subscription(name, keep, cls, qos=matching_qos(node, name, depth=max(10, count))):
        arrived = _wait_until(lambda: len(received) >= count,
                              max(0.0, deadline - time.monotonic()))
    if not arrived:
        raise EchoTimeout(f"Received {len(received)} of {count} messages on {name} within "
                          f"{timeout} s: is anyone publishing? graph.topic_info({name!r}) "
                          "shows the publishers and their QoS", list(received))
    return received[:count]


# --- ros2 topic hz ----------------------------------------------------------------------

def topic_hz(topic: str, window: int = 10000, duration: float = 2.0, timeout: float = 5.0,
             msg_type=None) -> RateStatistics:
    """Measure how often a topic is published, like ``ros2 topic hz``.

    The measurement starts at the first message and lasts ``duration`` seconds (shorter under
    test or grading, see run_limits.time_limit). Messages are not deserialized, so this works
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


#: What a notebook prints the answers of topic_info() and node_info() with, like the CLI:
#: ``print(graph.format_topic_info(graph.topic_info("/t")))``.
format_topic_info = graph_info.format_topic_info
format_node_info = graph_info.format_node_info


# --- ros2 topic info -v -----------------------------------------------------------------

_UNKNOWN_NODE = "_NODE_NAME_UNKNOWN_"


def topic_info(topic: str, verbose: bool = True, timeout: float = 2.0) -> graph_info.TopicInfo:
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
    return graph_info.TopicInfo(
        name=name, types=list(found[0]), publisher_count=len(publishers),
        subscription_count=len(subscriptions),
        publishers=[graph_info.endpoint_of(p) for p in publishers] if verbose else [],
        subscriptions=[graph_info.endpoint_of(s) for s in subscriptions] if verbose else [])


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


# --- ros2 node info ---------------------------------------------------------------------

def node_info(name: str, include_hidden: bool = False, timeout: float = 2.0) -> graph_info.NodeInfo:
    """The topics, services and actions of a node, like ``ros2 node info``.

    Args:
        name: the node's full name, e.g. "/talker" ("talker" is read as "/talker").
        include_hidden: also find a hidden node, and list hidden names (a part starting with
            "_"), like ``ros2 node info --include-hidden``.
        timeout: seconds to wait for the node to appear in the graph.

    Raises:
        ValueError: the node is not in the graph (the message lists the nodes there are).
    """
    from rclpy.action import get_action_client_names_and_types_by_node, get_action_server_names_and_types_by_node

    full = name if name.startswith("/") else "/" + name
    nodes = node_list(all=include_hidden, wait_for=[full], timeout=timeout)
    if full not in nodes:
        raise ValueError(f"Unable to find node '{full}'; the nodes are {node_list()}")
    namespace, _, base = full.rpartition("/")
    namespace = namespace or "/"
    node = _graph_node()

    def shown(pairs):
        return [(topic, list(kinds)) for topic, kinds in pairs if include_hidden or not node_names.is_hidden(topic)]

    return graph_info.NodeInfo(
        name=full,
        subscribers=shown(node.get_subscriber_names_and_types_by_node(base, namespace)),
        publishers=shown(node.get_publisher_names_and_types_by_node(base, namespace)),
        service_servers=shown(node.get_service_names_and_types_by_node(base, namespace)),
        service_clients=shown(node.get_client_names_and_types_by_node(base, namespace)),
        action_servers=shown(get_action_server_names_and_types_by_node(node, base, namespace)),
        action_clients=shown(get_action_client_names_and_types_by_node(node, base, namespace)))
