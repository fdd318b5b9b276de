"""``ros2 daemon start|stop|status``, and how the graph verbs ask the daemon.

Like ros2cli's daemon, the course's keeps one ROS node running in the background that holds the
graph, so that ``ros2 topic list`` and the other graph verbs answer at once instead of waiting
for discovery in a new process. The first graph verb starts it (:func:`graph_answer`); later
ones ask it; with ``--no-daemon``, or when no daemon answers, a verb discovers the graph itself.

One daemon per user and per ROS network: its address (:func:`address`) names the domain, the
discovery range and whatever else decides which participants it finds. ros2cli talks to its
daemon over XML-RPC on a localhost TCP port (11511 + the domain id); any local user can reach
such a port, and two users on one machine (the hub) would share it. The course's daemon listens
on a Unix socket in a folder only its user can open, which also keeps apart two network
namespaces sharing /tmp. Requests are one line of JSON each way: the client imports no rclpy.

The daemon (:mod:`.daemon_server`) ends on ``ros2 daemon stop``, on a signal (a student's
``kill``; the next graph verb starts a new one), after IDLE_SECONDS without a request (ros2cli's
``--timeout``), and with whatever it was started under (:func:`owner`): the notebook kernel that
ran ``!ros2``, else the Jupyter server of the terminal (``make lab``, the hub's server), else the
program named by OWNER_ENV (the test suite); and, in a domain reserved with
``rosenv.reserve_domain_id``, when the reservation ends.
"""

from __future__ import annotations

import hashlib
import json
import os
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from course_lib.ros2cli.common import DEFAULT_SPIN_TIME, Verb, run_group

#: Seconds without a request after which the daemon ends (ros2cli's daemon: --timeout, 2 hours).
IDLE_SECONDS = 2 * 60 * 60
#: An environment variable holding the id of a process the daemon ends with, when it was started
#: neither from a notebook kernel nor from a Jupyter terminal (the test suite sets it).
OWNER_ENV = "COURSE_LIB_ROS2_DAEMON_OWNER"
#: Seconds a graph verb waits at most for a new daemon to answer before it discovers the graph
#: itself (a backstop: the daemon answers in about a second, as soon as its discovery has settled).
START_BACKSTOP = 60.0
#: Seconds a request waits at most for the daemon's answer (a backstop: the daemon answers at
#: once, or after waiting a few seconds for the nodes of a process that has just started).
ANSWER_BACKSTOP = 60.0
#: Words in a process's command line that make it the daemon's owner: a notebook kernel first,
#: then a Jupyter server (make lab's, or the hub's single-user server).
KERNEL_WORDS = ("ipykernel_launcher", "ipykernel")
SERVER_WORDS = ("jupyter-lab", "jupyter-server", "jupyterhub-singleuser", "jupyter-notebook", "jupyterlab")


#: What graph_answer gives when the verb must discover the graph itself.
DIRECT = object()


class NotRunning(Exception):
    """No daemon answers at this address."""


def folder() -> Path:
    """This user's folder of daemon sockets: in XDG_RUNTIME_DIR where there is one, else in /tmp
    (mode 0700: no other user may connect)."""
    runtime = os.environ.get("XDG_RUNTIME_DIR", "")
    base = Path(runtime) if runtime and os.access(runtime, os.W_OK) else Path(tempfile.gettempdir())
    path = base / f"course_lib-ros2-daemon-{os.getuid()}"
    path.mkdir(mode=0o700, exist_ok=True)
    return path


def network_key(env=None) -> str:
    """What decides which DDS participants a daemon finds, as a short file name: the domain id
    and discovery range in words, the rest (static peers, rmw, Fast DDS profile, network
    namespace) as a digest."""
    env = os.environ if env is None else env
    domain = env.get("ROS_DOMAIN_ID", "").strip() or "0"
    scope = env.get("ROS_AUTOMATIC_DISCOVERY_RANGE", "").strip().upper()
    if not scope:
        scope = "LOCALHOST" if env.get("ROS_LOCALHOST_ONLY") == "1" else "SUBNET"  # Jazzy's default
    try:
        namespace = os.readlink("/proc/self/ns/net")
    except OSError:
        namespace = ""
    rest = [env.get(name, "") for name in ("ROS_STATIC_PEERS", "RMW_IMPLEMENTATION", "FASTRTPS_DEFAULT_PROFILES_FILE",
                                           "FASTDDS_BUILTIN_TRANSPORTS")] + [namespace]
    digest = hashlib.sha1("\0".join(rest).encode()).hexdigest()[:10]
    return f"domain{domain}-{scope.lower()}-{digest}"


def address(env=None) -> Path:
    """The socket of the daemon for the ROS network of ``env`` (default: this process's)."""
    return folder() / f"{network_key(env)}.sock"


# --- asking ---------------------------------------------------------------------------------

def ask(query: str, timeout: float = ANSWER_BACKSTOP, **params):
    """The daemon's answer to ``query`` (see daemon_server.QUERIES).

    Raises:
        NotRunning: no daemon listens (none started, or one that was killed left its socket).
        RuntimeError: the daemon could not answer (its words).
    """
    connection = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    connection.settimeout(timeout)
    try:
        connection.connect(str(address()))
        connection.sendall(json.dumps({"query": query, **params}).encode() + b"\n")
        reply = b""
        while not reply.endswith(b"\n"):
            chunk = connection.recv(65536)
            if not chunk:
                raise NotRunning("the daemon ended before it answered")
            reply += chunk
    except (FileNotFoundError, ConnectionRefusedError, ConnectionResetError, BrokenPipeError, TimeoutError) as error:
        raise NotRunning(str(error)) from None
    finally:
        connection.close()
    answer = json.loads(reply)
    if "error" in answer:
        raise RuntimeError(answer["error"])
    return answer["answer"]


def running_pid() -> int | None:
    """The process id of this network's daemon, if one answers."""
    try:
        return ask("status", timeout=5.0)["pid"]
    except NotRunning:
        return None


def owner() -> int | None:
    """The process the daemon should end with: the nearest notebook kernel among this process's
    ancestors, else the nearest Jupyter server, else the process OWNER_ENV names; None: none
    (a terminal outside Jupyter; the daemon then runs until stopped or idle, as ros2cli's)."""
    ancestors = []
    pid = os.getppid()
    while pid > 1 and len(ancestors) < 64:
        try:
            command = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            parent = int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            break
        ancestors.append((pid, command))
        pid = parent
    for words in (KERNEL_WORDS, SERVER_WORDS):
        for pid, command in ancestors:
            if any(word in command for word in words):
                return pid
    named = os.environ.get(OWNER_ENV, "")
    return int(named) if named.isdigit() else None


def start(spin_time: float = DEFAULT_SPIN_TIME, timeout: float = START_BACKSTOP) -> int | None:
    """Start this network's daemon unless one runs, and wait until it answers.

    Returns:
        its process id; None when none answered within ``timeout``.
    """
    pid = running_pid()
    if pid is not None:
        return pid
    keeper = owner()
    command = [sys.executable, "-m", "course_lib.ros2cli.daemon_server", "--spin-time", str(spin_time),
               "--idle", str(IDLE_SECONDS)] + (["--owner", str(keeper)] if keeper else [])
    # A session of its own: Ctrl-C in the terminal and the end of this command leave it running.
    subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                     start_new_session=True, close_fds=True)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:  # one that lost the race to another starter ends at once
        pid = running_pid()
        if pid is not None:
            return pid
        time.sleep(0.02)
    return None


def stop(timeout: float = 10.0) -> bool:
    """Stop this network's daemon; True if one ran (it has ended when this returns)."""
    try:
        pid = ask("stop", timeout=5.0)["pid"]
    except NotRunning:
        return False
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and Path(f"/proc/{pid}").exists():
        try:
            if Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] in ("Z", "X"):
                break
        except OSError:
            break
        time.sleep(0.02)
    return True


def graph_answer(args, query: str, **params):
    """For a graph verb: the daemon's answer to ``query``, starting the daemon if none runs.

    Returns:
        the answer; DIRECT when the verb must discover the graph itself (``--no-daemon``, or no
        daemon answered in time), as ros2cli's NodeStrategy falls back to a direct node.
    """
    if getattr(args, "no_daemon", False):
        return DIRECT
    for attempt in range(2):
        try:
            return ask(query, **params)
        except NotRunning:
            if attempt or start(getattr(args, "spin_time", DEFAULT_SPIN_TIME)) is None:
                return DIRECT
    return DIRECT


def topic_info_of(answer: dict):
    """A graph_info.TopicInfo from the daemon's answer to "topic_info"."""
    from course_lib.ros import graph_info

    def endpoint(fields: dict):
        return graph_info.Endpoint(**{**fields, "qos": graph_info.QosSummary(**fields["qos"])})

    return graph_info.TopicInfo(**{**answer, "publishers": [endpoint(e) for e in answer["publishers"]],
                                   "subscriptions": [endpoint(e) for e in answer["subscriptions"]]})


def node_info_of(answer: dict):
    """A graph_info.NodeInfo from the daemon's answer to "node_info"."""
    from course_lib.ros import graph_info

    return graph_info.NodeInfo(**{key: value if key == "name" else [(name, kinds) for name, kinds in value]
                                  for key, value in answer.items()})


# --- ros2 daemon start / stop / status ----------------------------------------------------------

def _start(_args) -> None:
    if running_pid() is not None:
        print("The daemon is already running")
        return None
    if start() is None:
        return "The daemon did not start: see the log in " + str(address().with_suffix(".log"))
    print("The daemon has been started")
    return None


def _stop(_args) -> None:
    print("The daemon has been stopped" if stop() else "The daemon is not running")


def _status(_args) -> None:
    print("The daemon is running" if running_pid() is not None else "The daemon is not running")


VERBS = {
    "start": Verb("Start the daemon if it isn't running", lambda parser: None, _start),
    "status": Verb("Output the status of the daemon", lambda parser: None, _status),
    "stop": Verb("Stop the daemon if it is running", lambda parser: None, _stop),
}


def main(argv: list[str]):
    return run_group("ros2 daemon", "Various daemon related sub-commands", VERBS, argv)
