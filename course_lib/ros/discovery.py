"""Discovery: wait, briefly and boundedly, until the graph a new tool node sees has settled.

Another process's nodes become visible only after DDS discovery (up to a few seconds). The
first query of :mod:`course_lib.ros.graph` on the session's tool node waits here; ``ros2 ...
--spin-time`` is the plain ROS 2 equivalent.
"""

from __future__ import annotations

import contextlib
import os
import time

from course_lib import waiting
from course_lib.ros import announcements, rosenv, session
from course_lib.supervision import process_tree

#: Seconds a newly started tool node waits for discovery at least before its first answer
#: (then until every process here has shown its nodes, up to COMPLETE_SECONDS). Lower it to 0
#: for a quicker first answer when only this kernel's nodes matter.
SETTLE_SECONDS = 0.5
#: Seconds after its creation up to which a new tool node waits for the nodes of every other
#: ROS process on this machine: Fast DDS shows another process's nodes after 0.2-1 s on an idle
#: machine (course_lib/ros/fastdds_large_data.xml), after seconds on a busy one.
COMPLETE_SECONDS = 3.0
# After SETTLE_SECONDS the graph must also have stayed the same for _SETTLE_QUIET s (things
# found late bring more with them), but the wait never lasts longer than _SETTLE_MAX s.
_SETTLE_POLL = 0.05
_SETTLE_QUIET = 0.3
_SETTLE_MAX = 5.0
#: On a busy machine discovery between processes takes longer: COMPLETE_SECONDS and _SETTLE_MAX
#: grow with the load per core (rosenv.load_factor), up to this many times.
MAX_LOAD_FACTOR = 3.0
_settled_node = None


# --- the tool node and the settling wait -------------------------------------------------

def _graph_node():
    """The session's tool node, after a bounded wait for discovery on its first use."""
    node = session.tool_node()
    if _settled_node is not node:
        wait_for_discovery()
    return node


class Settling:
    """The rule that ends a wait for discovery, apart from the clock and the graph (so that a test
    can make both up): discovery has shown the graph once

    - at least ``minimum`` seconds have passed since the tool node's creation,
    - the graph has not changed for ``quiet`` seconds (things found late bring more with them),
    - and every other ROS process on this machine has shown all it announced (its nodes, with
      their endpoints), or ``complete_within`` seconds have passed since the tool node's creation
      (a process whose announcement has not come yet keeps the wait going).

    No fixed sleep: a wait ends as soon as the graph has stopped changing.
    """

    def __init__(self, created_at: float, now: float, graph, minimum: float, quiet: float, complete_within: float):
        self.created_at, self.minimum, self.quiet, self.complete_within = created_at, minimum, quiet, complete_within
        self.graph, self.since = graph, now
        self.complete = False
        self.changes = 0  # how often the graph changed while waiting

    def settled(self, now: float, graph, every_process_shown) -> bool:
        """Whether discovery has settled by ``now``, the graph looking like ``graph`` then.

        Args:
            every_process_shown: a function of no arguments, called only while it matters.
        """
        if graph != self.graph:  # a change restarts the quiet time
            self.graph, self.since = graph, now
            self.changes += 1
        age = now - self.created_at
        if not self.complete:  # once every process has shown its nodes, no need to count again
            self.complete = age >= self.complete_within or every_process_shown()
        return age >= self.minimum and now - self.since >= self.quiet and self.complete


def wait_for_discovery(minimum: float | None = None, quiet: float = _SETTLE_QUIET,
                       complete_within: float | None = None, until=None) -> bool:
    """Wait until discovery has shown the graph to the tool node (the Settling rule); later
    queries do not wait.

    The functions of this module call it on the tool node's first use, with the defaults;
    the ``ros2`` command calls it first with its own (--spin-time; and for a verb that names a
    node or topic, ``until`` that name shows).

    Args:
        minimum: seconds after the tool node's creation to wait at least (default
            SETTLE_SECONDS).
        quiet: then wait until the graph has not changed for this long.
        complete_within: also wait, up to this many seconds after the tool node's creation,
            until every other DDS participant on this machine in this domain (each ROS process
            has one, holding its nodes) has shown all it announced (default COMPLETE_SECONDS; 0:
            not at all). On a busy machine some of them take seconds to be discovered.
        until: a function of no arguments that ends the wait early when it returns true.

    Returns:
        True when ``until`` or the rule ended the wait, False when the backstop did: 5 s after
        the tool node's creation (or ``minimum``, if later). On a machine loaded above one
        process per core, complete_within, quiet and the backstop grow with the load per core
        (at most MAX_LOAD_FACTOR times).
    """
    global _settled_node
    node = session.tool_node()
    _settled_node = node  # graph queries made by ``until`` must not start a wait of their own
    minimum = SETTLE_SECONDS if minimum is None else minimum
    busy = rosenv.load_factor(MAX_LOAD_FACTOR)
    complete_within = (COMPLETE_SECONDS if complete_within is None else complete_within) * busy
    here = _participants_here(node.context.get_domain_id()) if complete_within else []
    rule = Settling(node.created_at, time.monotonic(), _snapshot(node), minimum, quiet * busy,
                    complete_within if here else 0.0)
    backstop = max(_SETTLE_MAX * busy, minimum) - (time.monotonic() - node.created_at)
    with _announcements(node, here) as heard:
        def done():
            return (until is not None and until()) or rule.settled(
                time.monotonic(), _snapshot(node), lambda: _every_process_shown(node, heard, here))

        return waiting.spin_until(done, max(0.0, backstop), poll=_SETTLE_POLL)


def wait_for_every_process(timeout: float) -> bool:
    """Wait, up to `timeout` s from now, until the tool node has discovered all that every ROS
    process on this machine in its domain announced. True if it has; a process whose announcement
    has not come (its participant not discovered yet) keeps it waiting until the timeout."""
    node = session.tool_node()
    here = _participants_here(node.context.get_domain_id())
    with _announcements(node, here) as heard:
        return waiting.spin_until(lambda: _every_process_shown(node, heard, here), timeout, poll=_SETTLE_POLL)


def processes_not_shown(node, heard) -> dict:
    """The other ROS processes on this machine, in the node's domain, whose nodes and endpoints
    the graph does not show in full yet (a long-lived reader ``heard`` of their announcements,
    the ros2 daemon's, asks before each answer): {process id: what it announced last, None when
    nothing was heard from it yet}. Processes of another user cannot be told and are left out."""
    here = [pid for pid in _participants_here(node.context.get_domain_id())
            if pid is not None and pid != os.getpid() and process_tree.running(pid)]
    if not here:
        return {}
    latest = heard.latest()
    shown = _processes_shown(node, latest)
    announced = {_process_of(participant): what for participant, what in latest.items()}
    return {pid: announced.get(pid & 0xFFFF) for pid in here if pid & 0xFFFF not in shown}


def _announcements(node, here: list[int | None]):
    """A reader of what the processes of `here` announce, for the length of a wait; none when no
    other process is here."""
    if all(pid == os.getpid() for pid in here):
        return contextlib.nullcontext(None)
    return announcements.Announcements(node)


def _every_process_shown(node, heard, here: list[int | None]) -> bool:
    """True once every participant of `here` (a process id each, None: not known) whose process
    still runs is among those the graph shows all of (:func:`_processes_shown`).

    Participants are matched by their process, not counted: a listing started beside other
    `ros2` commands counted the quick ones that appeared after it looked, and answered before the
    slow process it was waiting for had shown its subscriptions ("Subscription count: 0").
    A process that has ended is not waited for, even while it is a zombie that its parent has not
    reaped yet (two `ros2` commands started together by one program that reaps them in turn).

    Args:
        heard: an Announcements reader (None: no other process is here).
    """
    shown = _processes_shown(node, heard.latest() if heard is not None else {})
    shown.add(os.getpid() & 0xFFFF)  # this process's own nodes are in its graph from their start
    known = {pid & 0xFFFF for pid in here if pid is not None and process_tree.running(pid)}
    unknown = sum(1 for pid in here if pid is None)  # another user's process: its sockets cannot be traced
    return known <= shown and len(shown - known) >= unknown


def _process_of(gid) -> int:
    """The process an endpoint or participant belongs to, as Fast DDS writes it into the GUID
    prefix of its participant: bytes 4 and 5 hold the low 16 bits of the process id."""
    return int.from_bytes(bytes(gid)[4:6], "little")


def _processes_shown(node, announced: dict) -> set[int]:
    """The processes (their ids' low 16 bits) whose participant the graph shows all of, as the
    participant announced it (`announced`: Announcements.latest()): every node
    listed by name, every reader and writer discovered.

    rmw learns endpoints and node names from two different messages, and DDS discovery announces
    a participant's writers and its readers apart, each in the order they were made. Judged by
    parts of it (its first reader and a named writer), a listener's process counted as shown
    while its subscriptions had not come, and `ros2 topic info` printed "Subscription count: 0".
    """
    if not announced:
        return set()
    listed = set(node.get_fully_qualified_node_names())
    discovered = _discovered_gids(node)
    shown = set()
    for participant, (nodes, gids) in announced.items():
        if nodes <= listed and gids <= discovered:
            shown.add(_process_of(participant))
    return shown


def _discovered_gids(node) -> set[bytes]:
    """The GIDs (16 bytes) of every reader and writer the graph shows, on every DDS topic (those of
    services and of rmw's own included)."""
    gids = set()
    for name, _ in node.get_topic_names_and_types(no_demangle=True):
        for info in (*node.get_publishers_info_by_topic(name, no_mangle=True),
                     *node.get_subscriptions_info_by_topic(name, no_mangle=True)):
            gids.add(bytes(info.endpoint_gid)[:16])
    return gids


def _participants_here(domain_id: int) -> list[int | None]:
    """The DDS participants that run on this machine in a domain: for each, its process's id, or
    None where the process cannot be told (another user's).

    Each binds two UDP ports (the RTPS standard port mapping): 7400 + 250 * domain + 10 +
    2 * (its participant id) for discovery traffic and the next one for data, so /proc/net/udp
    tells. Both must be bound, by one user: from domain 101 on, the range reaches the kernel's
    ephemeral ports (32768 and up), which any program's socket may get, and such a lone socket
    is no participant. Empty when it cannot tell.
    """
    first = 7410 + 250 * domain_id
    owners: dict[int, set[str]] = {}  # port -> the uids of the sockets bound to it
    inodes: dict[int, str] = {}  # discovery port -> the inode of a socket bound to it
    for table in ("/proc/net/udp", "/proc/net/udp6"):
        try:
            with open(table) as handle:
                rows = handle.read().splitlines()[1:]
        except OSError:
            continue
        for row in rows:
            fields = row.split()
            port = int(fields[1].rsplit(":", 1)[1], 16)
            if first <= port < first + 240:
                owners.setdefault(port, set()).add(fields[7])
                inodes.setdefault(port, fields[9])
    ports = [port for port in range(first, first + 240, 2) if owners.get(port, set()) & owners.get(port + 1, set())]
    processes = _socket_processes({inodes[port] for port in ports})
    return [processes.get(inodes[port]) for port in ports]


def _socket_processes(inodes: set[str]) -> dict[str, int]:
    """The id of the process that holds each of these sockets, where /proc shows it."""
    found: dict[str, int] = {}
    if not inodes:
        return found
    for entry in os.scandir("/proc"):
        if not entry.name.isdigit():
            continue
        try:
            descriptors = os.scandir(f"/proc/{entry.name}/fd")
        except OSError:
            continue  # gone, or another user's
        with descriptors:
            for descriptor in descriptors:
                try:
                    target = os.readlink(descriptor.path)
                except OSError:
                    continue
                if target.startswith("socket:[") and target[8:-1] in inodes:
                    found[target[8:-1]] = int(entry.name)
        if len(found) == len(inodes):
            break
    return found


def _snapshot(node):
    """What the graph shows: node names, topics with their types and how many publishers and
    subscriptions each has (a process announces its publishers and its subscriptions apart, so a
    topic can show with its publisher before its subscription)."""
    return (sorted(node.get_fully_qualified_node_names()),
            sorted((name, tuple(types), node.count_publishers(name), node.count_subscribers(name))
                   for name, types in node.get_topic_names_and_types()))
