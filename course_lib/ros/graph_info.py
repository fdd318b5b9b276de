"""What ``ros2 topic info -v`` and ``ros2 node info`` show, as records, and printed as the CLI prints them.

:func:`course_lib.ros.graph.topic_info` and :func:`course_lib.ros.graph.node_info` ask the graph and
return these records; ``format_topic_info`` and ``format_node_info`` give the CLI's text (the
course's ``ros2`` command prints it).
"""

from __future__ import annotations

import dataclasses
import math

from course_lib.ros import node_names


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
        return node_names.full_name(self.node_namespace, self.node_name)


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


def endpoint_of(info) -> Endpoint:
    """An Endpoint from rclpy's TopicEndpointInfo (get_publishers_info_by_topic and the like)."""
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
