"""What every ROS process announces about its own nodes: rmw's graph messages on the DDS topic
``ros_discovery_info``.

Each ROS process's rmw publishes, after every node, publisher, subscription, service or client it
makes, one ``rmw_dds_common/msg/ParticipantEntitiesInfo``: its participant's GID and, for each of
its nodes, the name and the GIDs of the node's readers and writers (reliable, transient local,
the last one kept). rmw reads them itself to name the endpoints DDS discovery finds; rclpy does
not show them. :mod:`course_lib.ros.discovery` reads them to know when it has discovered
*everything* another process has, rather than guessing from the clock.

rclpy cannot subscribe to that topic: rcl makes every topic name absolute ("/ros_discovery_info"),
and rmw's topic has no slash. So :class:`Announcements` makes the subscription one level down, with
rmw's own C functions (``rmw_create_subscription``, ``rmw_take_serialized_message``) on the tool
node's rmw node, and reads each sample's CDR bytes itself (:func:`parse`): the message's Python
class would import numpy (its GIDs are arrays), which a ``ros2`` command otherwise does without. This is how
rmw itself subscribes (rmw_fastrtps_cpp, ``init_context_impl``): same topic, type and QoS, but
for the depth.

Only Fast DDS (rmw_fastrtps_cpp, the only rmw the ROS wheels hold) is supported.
"""

from __future__ import annotations

import ctypes
import struct
import typing

#: rmw's DDS topic of graph messages (no ROS name: no leading slash, no "rt/" prefix).
TOPIC = "ros_discovery_info"

#: How many messages not yet taken the reader keeps: those of every participant between two calls
#: of Announcements.latest.
DEPTH = 100

# enum values of rmw/types.h (rmw 7, Jazzy)
_KEEP_LAST, _RELIABLE, _TRANSIENT_LOCAL, _LIVELINESS_SYSTEM_DEFAULT = 1, 1, 1, 0


class _Time(ctypes.Structure):  # rmw_time_t
    _fields_ = [("sec", ctypes.c_uint64), ("nsec", ctypes.c_uint64)]


class _QoS(ctypes.Structure):  # rmw_qos_profile_t
    _fields_ = [("history", ctypes.c_int), ("depth", ctypes.c_size_t), ("reliability", ctypes.c_int),
                ("durability", ctypes.c_int), ("deadline", _Time), ("lifespan", _Time),
                ("liveliness", ctypes.c_int), ("liveliness_lease_duration", _Time),
                ("avoid_ros_namespace_conventions", ctypes.c_bool)]


class _SubscriptionOptions(ctypes.Structure):  # rmw_subscription_options_t
    _fields_ = [("rmw_specific_subscription_payload", ctypes.c_void_p), ("ignore_local_publications", ctypes.c_bool),
                ("require_unique_network_flow_endpoints", ctypes.c_int), ("content_filter_options", ctypes.c_void_p)]


class _Allocator(ctypes.Structure):  # rcutils_allocator_t
    _fields_ = [(name, ctypes.c_void_p) for name in ("allocate", "deallocate", "reallocate", "zero_allocate", "state")]


class _Bytes(ctypes.Structure):  # rcutils_uint8_array_t, alias rmw_serialized_message_t
    _fields_ = [("buffer", ctypes.POINTER(ctypes.c_uint8)), ("buffer_length", ctypes.c_size_t),
                ("buffer_capacity", ctypes.c_size_t), ("allocator", _Allocator)]


_functions = None


def _c_functions():
    """rcl's, rmw's and rcutils' functions, from the libraries rclpy has loaded (a library already
    loaded is found by its name)."""
    global _functions
    if _functions is None:
        rcl, rmw, rcutils = (ctypes.CDLL(name) for name in ("librcl.so", "librmw_fastrtps_cpp.so", "librcutils.so"))
        rcl.rcl_node_get_rmw_handle.restype = ctypes.c_void_p
        rcl.rcl_node_get_rmw_handle.argtypes = [ctypes.c_void_p]
        rmw.rmw_get_default_subscription_options.restype = _SubscriptionOptions
        rmw.rmw_create_subscription.restype = ctypes.c_void_p
        rmw.rmw_create_subscription.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_char_p,
                                                ctypes.POINTER(_QoS), ctypes.POINTER(_SubscriptionOptions)]
        rmw.rmw_destroy_subscription.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
        rmw.rmw_take_serialized_message.argtypes = [ctypes.c_void_p, ctypes.POINTER(_Bytes),
                                                    ctypes.POINTER(ctypes.c_bool), ctypes.c_void_p]
        rcutils.rcutils_get_default_allocator.restype = _Allocator
        rcutils.rcutils_uint8_array_init.argtypes = [ctypes.POINTER(_Bytes), ctypes.c_size_t,
                                                     ctypes.POINTER(_Allocator)]
        rcutils.rcutils_uint8_array_fini.argtypes = [ctypes.POINTER(_Bytes)]
        _functions = rcl, rmw, rcutils
    return _functions


def _type_support() -> int:
    """The address of ParticipantEntitiesInfo's C type support, from rmw_dds_common's library
    (which rmw has loaded)."""
    library = ctypes.CDLL("librmw_dds_common__rosidl_typesupport_c.so")
    handle = library.rosidl_typesupport_c__get_message_type_support_handle__rmw_dds_common__msg__ParticipantEntitiesInfo
    handle.restype = ctypes.c_void_p
    return handle()


class Announced(typing.NamedTuple):
    """What one participant announced: its nodes (fully qualified names) and the GIDs (16 bytes
    each) of their readers and writers."""

    nodes: frozenset[str]
    gids: frozenset[bytes]


def parse(data: bytes) -> tuple[bytes, Announced]:
    """The participant's GID and what it announced, from one serialized ParticipantEntitiesInfo
    (CDR: a 4-byte encapsulation header, then each field aligned to its size from there: gid
    uint8[16]; node_entities_info_seq, a sequence of node_namespace and node_name strings and
    reader_gid_seq and writer_gid_seq, sequences of uint8[16]).

    Raises:
        ValueError: not a ParticipantEntitiesInfo in CDR (truncated, or another encoding).
    """
    if len(data) < 4 or data[0] != 0 or data[1] not in (0, 1):
        raise ValueError(f"not CDR: encapsulation header {bytes(data[:4])!r}")
    order, body, position = ("<" if data[1] == 1 else ">"), memoryview(data)[4:], 0

    def count() -> int:
        nonlocal position
        position = (position + 3) & ~3
        try:
            (value,) = struct.unpack_from(order + "I", body, position)
        except struct.error as error:
            raise ValueError(f"truncated at byte {position}") from error
        position += 4
        return value

    def octets(size: int) -> bytes:
        nonlocal position
        chunk = bytes(body[position:position + size])
        if len(chunk) != size:
            raise ValueError(f"truncated at byte {position}")
        position += size
        return chunk

    def text() -> str:
        return octets(count())[:-1].decode()  # the length counts the terminating NUL

    participant, nodes, gids = octets(16), set(), set()
    for _ in range(count()):
        namespace, name = text(), text()
        nodes.add(f"{namespace.rstrip('/')}/{name}")
        for _ in range(2):  # readers, then writers
            gids.update(octets(16) for _ in range(count()))
    return participant, Announced(frozenset(nodes), frozenset(gids))


class Announcements:
    """A reader of every participant's graph messages, on a node's participant; close it before the
    node is destroyed (``with Announcements(node) as heard:``).

    ``latest()`` gives what each participant announced last, of what has been heard so far.
    """

    def __init__(self, node):
        rcl, rmw, rcutils = _c_functions()
        self._rmw_node = rcl.rcl_node_get_rmw_handle(node.handle.pointer)
        if not self._rmw_node:
            raise RuntimeError(f"Node {node.get_name()} has no rmw node (destroyed?)")
        # Keeps the last DEPTH messages of all participants together (the type has no key, so one
        # instance): rmw's own reader keeps one, but handles each as it comes.
        qos = _QoS(history=_KEEP_LAST, depth=DEPTH, reliability=_RELIABLE, durability=_TRANSIENT_LOCAL,
                   liveliness=_LIVELINESS_SYSTEM_DEFAULT, avoid_ros_namespace_conventions=True)
        options = rmw.rmw_get_default_subscription_options()
        self._subscription = rmw.rmw_create_subscription(self._rmw_node, _type_support(),
                                                         TOPIC.encode(), ctypes.byref(qos), ctypes.byref(options))
        if not self._subscription:
            rcutils.rcutils_reset_error()  # rmw's error state, which rcl would report and clear
            raise RuntimeError(f"rmw could not subscribe to {TOPIC}")
        self._sample = _Bytes()
        allocator = rcutils.rcutils_get_default_allocator()
        if rcutils.rcutils_uint8_array_init(ctypes.byref(self._sample), 1024, ctypes.byref(allocator)):
            self.close()
            raise MemoryError("no memory for a graph message")
        self._latest: dict[bytes, Announced] = {}

    def latest(self) -> dict[bytes, Announced]:
        """{participant GID (16 bytes): what it announced last}, after taking every message that
        has come since the last call (one that cannot be read is left out)."""
        _, rmw, rcutils = _c_functions()
        taken = ctypes.c_bool(True)
        while self._subscription:
            taken.value = False
            if rmw.rmw_take_serialized_message(self._subscription, ctypes.byref(self._sample), ctypes.byref(taken),
                                               None):
                rcutils.rcutils_reset_error()
                break
            if not taken.value:
                break
            try:
                participant, announced = parse(ctypes.string_at(self._sample.buffer, self._sample.buffer_length))
            except ValueError:
                continue
            self._latest[participant] = announced
        return self._latest

    def close(self) -> None:
        """Destroy the subscription (once; later calls do nothing)."""
        _, rmw, rcutils = _c_functions()
        if self._subscription:
            rmw.rmw_destroy_subscription(self._rmw_node, self._subscription)
            self._subscription = None
            rcutils.rcutils_uint8_array_fini(ctypes.byref(self._sample))

    def __enter__(self) -> Announcements:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
