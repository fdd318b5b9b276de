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
node's rmw node, and turns each sample into a message with ``rclpy.serialization``. This is how
rmw itself subscribes (rmw_fastrtps_cpp, ``init_context_impl``): same topic, type and QoS, but
for the depth.

Only Fast DDS (rmw_fastrtps_cpp, the only rmw the ROS wheels hold) is supported.
"""

from __future__ import annotations

import ctypes

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
        ctypes.pythonapi.PyCapsule_GetPointer.restype = ctypes.c_void_p
        ctypes.pythonapi.PyCapsule_GetPointer.argtypes = [ctypes.py_object, ctypes.c_char_p]
        ctypes.pythonapi.PyCapsule_GetName.restype = ctypes.c_char_p
        ctypes.pythonapi.PyCapsule_GetName.argtypes = [ctypes.py_object]
        _functions = rcl, rmw, rcutils
    return _functions


def _type_support(message_class) -> int:
    """The address of a message type's C type support (what rclpy hands rcl for it)."""
    from rclpy.type_support import check_for_type_support

    check_for_type_support(message_class)
    capsule = message_class._TYPE_SUPPORT
    return ctypes.pythonapi.PyCapsule_GetPointer(capsule, ctypes.pythonapi.PyCapsule_GetName(capsule))


class Announcements:
    """A reader of every participant's graph messages, on a node's participant; close it before the
    node is destroyed (``with Announcements(node) as heard:``).

    ``latest()`` gives the last message of each participant heard so far.
    """

    def __init__(self, node):
        from rmw_dds_common.msg import ParticipantEntitiesInfo

        rcl, rmw, rcutils = _c_functions()
        self._message_class = ParticipantEntitiesInfo
        self._rmw_node = rcl.rcl_node_get_rmw_handle(node.handle.pointer)
        if not self._rmw_node:
            raise RuntimeError(f"Node {node.get_name()} has no rmw node (destroyed?)")
        # Keeps the last DEPTH messages of all participants together (the type has no key, so one
        # instance): rmw's own reader keeps one, but handles each as it comes.
        qos = _QoS(history=_KEEP_LAST, depth=DEPTH, reliability=_RELIABLE, durability=_TRANSIENT_LOCAL,
                   liveliness=_LIVELINESS_SYSTEM_DEFAULT, avoid_ros_namespace_conventions=True)
        options = rmw.rmw_get_default_subscription_options()
        self._subscription = rmw.rmw_create_subscription(self._rmw_node, _type_support(ParticipantEntitiesInfo),
                                                         TOPIC.encode(), ctypes.byref(qos), ctypes.byref(options))
        if not self._subscription:
            rcutils.rcutils_reset_error()  # rmw's error state, which rcl would report and clear
            raise RuntimeError(f"rmw could not subscribe to {TOPIC}")
        self._sample = _Bytes()
        allocator = rcutils.rcutils_get_default_allocator()
        if rcutils.rcutils_uint8_array_init(ctypes.byref(self._sample), 1024, ctypes.byref(allocator)):
            self.close()
            raise MemoryError("no memory for a graph message")
        self._latest: dict[bytes, object] = {}

    def latest(self) -> dict[bytes, object]:
        """{participant GID (16 bytes): its last ParticipantEntitiesInfo}, after taking every
        message that has come since the last call."""
        from rclpy.serialization import deserialize_message

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
            message = deserialize_message(ctypes.string_at(self._sample.buffer, self._sample.buffer_length),
                                          self._message_class)
            self._latest[bytes(message.gid.data)] = message
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


def endpoints_of(message) -> tuple[set[str], set[bytes]]:
    """The nodes (their fully qualified names) and endpoint GIDs (16 bytes each) one
    ParticipantEntitiesInfo announces."""
    nodes, gids = set(), set()
    for info in message.node_entities_info_seq:
        namespace = info.node_namespace.rstrip("/")
        nodes.add(f"{namespace}/{info.node_name}")
        gids.update(bytes(gid.data) for gid in (*info.reader_gid_seq, *info.writer_gid_seq))
    return nodes, gids
