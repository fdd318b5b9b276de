"""The course's ros2 daemon itself: ``python -m course_lib.ros2cli.daemon_server`` (started by
:func:`course_lib.ros2cli.daemon.start`; see :mod:`.daemon` for why and how it is reached).

It holds the session's tool node, whose graph DDS keeps current, and answers the graph verbs'
questions with the very functions a daemon-less verb calls (course_lib.ros.graph and the verbs'
own listings), so both give the same answer. Before each answer it waits, briefly, for what a
process on this machine has announced but the graph does not show yet (a node started a moment
ago, a new publisher): an answer does not depend on how long discovery took, also on a loaded
machine (:func:`course_lib.ros.discovery.processes_not_shown`). A node that ended leaves the
graph as soon as DDS says so: at once when its process ends, after the lease (20 s) when it was
killed, as with ros2cli's daemon.
"""

from __future__ import annotations

import argparse
import dataclasses
import fcntl
import json
import os
import signal
import socket
import sys
import time

from course_lib.ros2cli import daemon
from course_lib.ros2cli.common import QUIET_SECONDS

#: Seconds between two looks at what the daemon lives for (its owner, its domain's reservation).
LIFELINE_POLL = 0.25
#: Seconds after it was first seen (or announced something new) up to which a process on this
#: machine whose nodes the graph does not show in full yet holds up an answer: Fast DDS shows them
#: within 0.2-1 s on an idle machine (course_lib.ros.discovery.COMPLETE_SECONDS); grows with the load.
PATIENCE_SECONDS = 3.0


class Stop(Exception):
    """A signal, or ``ros2 daemon stop``, ends the daemon."""


def _stop_on_signal(_number, _frame):
    raise Stop


# --- what it answers ------------------------------------------------------------------------

def _nodes(all: bool = False):  # noqa: A002 - ros2 node list's option
    from course_lib.ros import graph

    return graph.node_list(all=all)


def _topics(include_hidden: bool = False):
    from course_lib.ros import graph

    return graph.topic_list(types=True, include_hidden=include_hidden)


def _services(include_hidden: bool = False):
    from course_lib.ros2cli.service import service_pairs

    return service_pairs(include_hidden)


def _actions():
    from course_lib.ros2cli.action import action_pairs

    return action_pairs()


def _topic_shown(name: str) -> bool:
    """Whether the graph shows the topic ``name`` (relative names resolved; hidden ones too)."""
    from course_lib.ros import graph, session

    return session.tool_node().resolve_topic_name(name) in graph.topic_list(include_hidden=True)


def _topic_info(name: str, verbose: bool = False):
    from course_lib.ros import graph
    from course_lib.ros2cli.common import DISCOVERY_BACKSTOP

    if not _topic_shown(name):
        return None
    return dataclasses.asdict(graph.topic_info(name, verbose=verbose, timeout=DISCOVERY_BACKSTOP))


def _node_info(name: str, include_hidden: bool = False):
    """{"count": how many nodes have the name, "info": the first one's}; None: no such node."""
    from course_lib.ros import graph

    count = graph.node_list(all=include_hidden).count(name)
    if not count:
        return None
    return {"count": count, "info": dataclasses.asdict(graph.node_info(name, include_hidden=include_hidden,
                                                                       timeout=0.0))}


def _action_ends(action_name: str):
    from course_lib.ros2cli.action import action_ends

    return action_ends(action_name)


#: The questions a graph verb may ask: the name of each, and what answers it.
QUERIES = {"nodes": _nodes, "topics": _topics, "services": _services, "actions": _actions,
           "topic_shown": _topic_shown, "topic_info": _topic_info, "node_info": _node_info,
           "action_ends": _action_ends}


class Graph:
    """The tool node's graph, with the wait that makes an answer complete."""

    def __init__(self, patience: float):
        from course_lib.ros import announcements, session

        self.node = session.tool_node()
        self.heard = announcements.Announcements(self.node)
        self.patience = patience
        self.first_seen: dict[tuple, float] = {}  # (process id, what it announced) -> when

    def pending(self) -> list[int]:
        """The processes here whose announced nodes and endpoints the graph does not show yet, and
        which have not been waited for longer than the patience since they announced them."""
        from course_lib.ros import discovery

        now = time.monotonic()
        missing = [(pid, announced) for pid, announced in discovery.processes_not_shown(self.node, self.heard).items()]
        for key in missing:
            self.first_seen.setdefault(key, now)
        return [pid for pid, announced in missing if now - self.first_seen[(pid, announced)] < self.patience]

    def answer(self, request: dict):
        from course_lib.ros import session

        query = request.pop("query", None)
        if query == "status":
            return {"pid": os.getpid()}
        if query not in QUERIES:
            raise ValueError(f"the course's ros2 daemon does not know the question {query!r}")
        session.wait_for(lambda: not self.pending(), timeout=self.patience, poll=0.02)
        return QUERIES[query](**request)

    def close(self) -> None:
        self.heard.close()


# --- what it lives for ----------------------------------------------------------------------

class Lifelines:
    """Whatever the daemon ends with: its owner process, its domain's reservation, idleness."""

    def __init__(self, owner: int | None, idle: float):
        from course_lib.supervision import process_tree

        self.owner = owner
        self.owner_started = process_tree.stat_fields(owner)[19] if owner and process_tree.running(owner) else None
        if owner and self.owner_started is None:
            raise Stop  # gone before the daemon came up
        self.reservation = _reservation_file()
        self.idle, self.last_request = idle, time.monotonic()
        self.checked = 0.0

    def cut(self) -> str | None:
        """Why the daemon should end now, or None."""
        from course_lib.ros import rosenv
        from course_lib.supervision import process_tree

        now = time.monotonic()
        if now - self.last_request > self.idle:
            return f"no request for {self.idle:.0f} s"
        if now - self.checked < LIFELINE_POLL:
            return None
        self.checked = now
        if self.owner_started is not None:
            try:
                alive = (process_tree.running(self.owner)
                         and process_tree.stat_fields(self.owner)[19] == self.owner_started)
            except (OSError, IndexError):
                alive = False
            if not alive:
                return f"its owner, process {self.owner}, has ended"
        if self.reservation is not None and rosenv.reservation_token(self.reservation[0]) != self.reservation[1]:
            return "the reservation of its ROS domain has ended"
        return None


def _reservation_file() -> tuple[int, str] | None:
    """This domain and the token of its reservation (rosenv.reserve_domain_id), if someone holds it:
    the daemon ends when that reservation does, even when the same id is reserved again at once."""
    from course_lib.ros import rosenv

    domain = int(os.environ.get("ROS_DOMAIN_ID", "0") or 0)
    if domain not in rosenv.RESERVABLE_DOMAIN_IDS:
        return None
    token = rosenv.reservation_token(domain)
    return (domain, token) if token else None


# --- serving --------------------------------------------------------------------------------

def _listen(path) -> socket.socket:
    """A listening socket at ``path``, made under another name and renamed: a client never finds
    a socket that does not listen yet."""
    making = path.with_name(f".{path.name}.{os.getpid()}")
    making.unlink(missing_ok=True)
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    listener.bind(str(making))
    listener.listen(64)
    os.replace(making, path)
    listener.settimeout(LIFELINE_POLL)
    return listener


def _serve_one(connection: socket.socket, graph: Graph) -> bool:
    """Answer one request; False when it asked the daemon to stop."""
    with connection:
        connection.settimeout(5.0)
        data = b""
        try:
            while not data.endswith(b"\n"):
                chunk = connection.recv(65536)
                if not chunk:
                    return True
                data += chunk
            request = json.loads(data)
            if request.get("query") == "stop":
                connection.sendall(json.dumps({"answer": {"pid": os.getpid()}}).encode() + b"\n")
                return False
            try:
                reply = {"answer": graph.answer(request)}
            except (ValueError, LookupError, TypeError, RuntimeError) as error:
                reply = {"error": str(error)}
            connection.sendall(json.dumps(reply).encode() + b"\n")
        except (OSError, ValueError):  # the client went away, or sent no JSON
            pass
    return True


def serve(spin_time: float, owner: int | None, idle: float) -> int:
    """Run the daemon of this process's ROS network until a lifeline is cut; 0 at once when
    another daemon of this network runs or is starting."""
    from course_lib.ros import discovery, rosenv, session

    path = daemon.address()
    lock = open(path.with_suffix(".lock"), "a+")
    try:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        return 0
    log = open(path.with_suffix(".log"), "w")
    os.dup2(log.fileno(), sys.stderr.fileno())
    for number in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
        signal.signal(number, _stop_on_signal)
    listener = graph = None
    try:
        lifelines = Lifelines(owner, idle)
        path.unlink(missing_ok=True)  # left by a daemon that was killed: nobody else holds the lock
        graph = Graph(PATIENCE_SECONDS * rosenv.load_factor(discovery.MAX_LOAD_FACTOR))
        # Listening only once the graph is as a daemon-less verb would see it, with all that the
        # processes here have announced (each answer waits for what they announce later).
        discovery.wait_for_discovery(minimum=spin_time, quiet=min(QUIET_SECONDS, spin_time), complete_within=0.0)
        session.wait_for(lambda: not graph.pending(), timeout=graph.patience, poll=0.02)
        listener = _listen(path)
        why = None
        while why is None:
            try:
                connection, _ = listener.accept()
            except TimeoutError:
                why = lifelines.cut()
                continue
            lifelines.last_request = time.monotonic()
            if not _serve_one(connection, graph):
                why = "ros2 daemon stop"
            else:
                why = lifelines.cut()
        print(f"The daemon ends: {why}", file=sys.stderr)
    except Stop:
        print("The daemon ends: a signal", file=sys.stderr)
    finally:
        if listener is not None:
            path.unlink(missing_ok=True)
            listener.close()
        if graph is not None:
            graph.close()
        session.stop()
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m course_lib.ros2cli.daemon_server",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--spin-time", type=float, default=0.5, help="seconds of discovery before the first answer")
    parser.add_argument("--owner", type=int, default=None, help="end when this process ends")
    parser.add_argument("--idle", type=float, default=daemon.IDLE_SECONDS, help="end after this long without a request")
    args = parser.parse_args(argv)
    return serve(args.spin_time, args.owner, args.idle)


if __name__ == "__main__":
    sys.exit(main())
