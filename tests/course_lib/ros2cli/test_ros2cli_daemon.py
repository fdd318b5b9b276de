"""The course's ros2 daemon (course_lib.ros2cli.daemon): started by the first graph verb, asked by
the later ones, one per ROS network, never stale, and never left running after what it serves."""

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from support.process import wait_until
from support.ros2cli import ROS2, ros2, ros2_together

from course_lib.ros import processes, rosenv
from course_lib.ros2cli import daemon

#: A node that spins until Ctrl-C: `python -c NODE name`.
NODE = ("import sys, rclpy\nfrom rclpy.node import Node\nrclpy.init()\nnode = Node(sys.argv[1])\n"
        "try:\n    rclpy.spin(node)\nexcept KeyboardInterrupt:\n    pass\n")


def daemon_pids(domain_id: int) -> list[int]:
    """The daemons of this user serving ``domain_id`` (read from /proc: their command line and
    environment)."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            command = (entry / "cmdline").read_bytes()
            environ = (entry / "environ").read_bytes().split(b"\0")
        except OSError:
            continue
        if b"course_lib.ros2cli.daemon_server" in command and f"ROS_DOMAIN_ID={domain_id}".encode() in environ:
            found.append(int(entry.name))
    return found


def gone(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] in ("Z", "X")
    except OSError:
        return True


@pytest.fixture
def domain():
    """A reserved ROS domain; yields the environment of a ros2 command in it. Its daemon ends with
    the reservation; the test checks that it did."""
    with rosenv.reserve_domain_id() as reservation:
        # A daemon of the id's last reservation ends once it sees this one's token (even in the
        # same worker, which gets the same id again at once): none adopts a new reservation.
        assert wait_until(lambda: not daemon_pids(reservation.domain_id)), "a daemon outlived its reservation"
        yield rosenv.ros_environment(domain_id=reservation.domain_id)
        domain_id = reservation.domain_id
    assert wait_until(lambda: not daemon_pids(domain_id)), "the daemon outlived its domain's reservation"


def test_daemon_verbs_say_upstreams_words(domain):
    """ros2cli/verb/daemon/{start,status,stop}.py: 'The daemon is not running', 'The daemon has
    been started', 'The daemon is already running', 'The daemon is running', 'The daemon has
    been stopped'."""
    words = [ros2("daemon", *verb, env=domain).stdout for verb in (
        ["status"], ["start"], ["start"], ["status"], ["stop"], ["stop"], ["status"])]
    assert words == ["The daemon is not running\n", "The daemon has been started\n",
                     "The daemon is already running\n", "The daemon is running\n", "The daemon has been stopped\n",
                     "The daemon is not running\n", "The daemon is not running\n"]
    assert "  start   Start the daemon if it isn't running" in ros2("daemon", "--help", env=domain).stdout


def test_the_first_graph_verb_starts_the_daemon_and_no_daemon_does_not(domain):
    """ros2cli's NodeStrategy: a graph verb spawns the daemon when none runs; --no-daemon neither
    spawns nor uses one ('Do not spawn nor use an already running daemon')."""
    domain_id = int(domain["ROS_DOMAIN_ID"])
    with processes.NodeProcess([sys.executable, "-c", NODE, "daemon_talker"], domain_id=domain_id) as node:
        node.wait_for_node("daemon_talker", timeout=60)
        direct = ros2("node", "list", "--no-daemon", env=domain)
        assert direct.stdout == "/daemon_talker\n" and not daemon_pids(domain_id)
        asked = ros2("node", "list", env=domain)
        assert asked.stdout == "/daemon_talker\n"
        assert len(daemon_pids(domain_id)) == 1
        assert ros2("daemon", "status", env=domain).stdout == "The daemon is running\n"
        # Every graph verb asks the same daemon, and gives the daemon-less answer (where the
        # daemon's hidden node, or the daemon-less command's own, does not count).
        verbs = (["topic", "list"], ["service", "list", "-t"], ["node", "info", "/daemon_talker"],
                 ["topic", "find", "rcl_interfaces/msg/Log"], ["topic", "type", "/rosout"])
        with_daemon = [ros2(*verb, env=domain).stdout for verb in verbs]
        # The daemon-less commands wait for discovery each (the daemon's answers come at once): together.
        without = ros2_together(*([*verb, "--no-daemon"] for verb in verbs), env=domain)
        for verb, asked, direct in zip(verbs, with_daemon, without, strict=True):
            assert direct.returncode == 0, direct.stderr
            assert asked and asked == direct.stdout, verb
        assert len(daemon_pids(domain_id)) == 1


def test_a_killed_daemon_is_replaced_by_the_next_command(domain):
    """A student's `kill` (or kill -9) of the daemon: the next graph verb starts a new one."""
    domain_id = int(domain["ROS_DOMAIN_ID"])
    ros2("daemon", "start", env=domain)
    for number in (signal.SIGTERM, signal.SIGKILL):
        (first,) = daemon_pids(domain_id)
        os.kill(first, number)
        assert wait_until(lambda pid=first: gone(pid))
        assert ros2("topic", "list", env=domain).stdout == "/parameter_events\n/rosout\n"
        assert daemon_pids(domain_id) not in ([], [first])


def test_a_node_that_ended_leaves_the_daemons_answer(domain):
    """Never a stale graph: a node whose process ended is gone from `ros2 node list` as soon as
    DDS says so (the participant's goodbye), as with ros2cli's daemon."""
    domain_id = int(domain["ROS_DOMAIN_ID"])
    ros2("daemon", "start", env=domain)
    with processes.NodeProcess([sys.executable, "-c", NODE, "short_lived"], domain_id=domain_id) as node:
        node.wait_for_node("short_lived", timeout=60)
        # Started after the daemon: its answer waits for what the new process has announced.
        assert ros2("node", "list", env=domain).stdout == "/short_lived\n"
    assert wait_until(lambda: ros2("node", "list", env=domain).stdout == "")


def test_a_daemon_ends_with_the_notebook_kernel_that_started_it(domain):
    """Started by `!ros2 ...` in a notebook, the daemon belongs to the kernel (the nearest process
    called ipykernel among the command's ancestors) and ends when the kernel does."""
    domain_id = int(domain["ROS_DOMAIN_ID"])
    kernel = subprocess.Popen(["sh", "-c", f'"{ROS2}" daemon start >/dev/null && exec sleep 600', "ipykernel_launcher"],
                              env=domain)
    try:
        assert wait_until(lambda: daemon_pids(domain_id) and not Path(f"/proc/{kernel.pid}/cmdline").read_bytes()
                          .startswith(b"sh"))  # the daemon runs, and the shell has become `sleep`
        (started,) = daemon_pids(domain_id)
        kernel.kill()
        kernel.wait()
        assert wait_until(lambda: gone(started))
    finally:
        kernel.kill()
        kernel.wait()


def test_parallel_domains_get_daemons_of_their_own(domain):
    """One daemon per ROS network: two domains (two test workers) never share one."""
    with rosenv.reserve_domain_id() as other:
        other_env = rosenv.ros_environment(domain_id=other.domain_id)
        assert daemon.network_key(other_env) != daemon.network_key(domain)
        for env in (domain, other_env):
            assert ros2("daemon", "start", env=env).stdout == "The daemon has been started\n"
        ours, theirs = daemon_pids(int(domain["ROS_DOMAIN_ID"])), daemon_pids(other.domain_id)
        assert len(ours) == len(theirs) == 1 and ours != theirs
    assert wait_until(lambda: not daemon_pids(other.domain_id))


#: A notebook's session with its tool node, until Ctrl-C: prints the tool node's name once it runs.
#: SIGINT gets a handler of its own (a test run started with `&` by a script passes it on ignored,
#: and signal.pause() then slept through it until the test's 60 s ran out) and is blocked in every
#: thread and awaited by the main one (pause() sleeps on when a session thread takes the signal).
SESSION = ("import signal\nfrom course_lib.ros import session\n"
           "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
           "signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})\nsession.start()\n"
           "print(session.tool_node().get_name(), flush=True)\nsignal.sigwait({signal.SIGINT})\nsession.stop()\n")


def node_list_showing(names, args, env):
    """The first `ros2 node list ARGS` that lists all of ``names`` (asked again until one does)."""
    listed = []

    def shows_them():
        listed.append(ros2("node", "list", *args, env=env))
        return set(names) <= set(listed[-1].stdout.split())

    assert wait_until(shows_them)
    return listed[-1]


def test_every_process_has_a_tool_node_of_its_own_name(domain):
    """Two notebooks' sessions and the daemon each have a hidden tool node: `ros2 node list -a`
    lists three names (four with --no-daemon: the command's own) and does not warn that nodes
    share a name."""
    sessions = [subprocess.Popen([sys.executable, "-c", SESSION], env=domain, stdout=subprocess.PIPE, text=True)
                for _ in range(2)]
    try:
        names = ["/" + process.stdout.readline().strip() for process in sessions]
        assert len(set(names)) == 2 and all(name.startswith("/_course_tools_") for name in names), names
        for args, count in ((["-a"], 3), (["-a", "--no-daemon"], 4)):
            listed = node_list_showing(names, args, domain)
            tools = [name for name in listed.stdout.split() if name.startswith("/_course_tools")]
            assert len(tools) == len(set(tools)) == count, listed.stdout
            assert "share an exact name" not in listed.stderr
        assert ros2("node", "list", env=domain).stdout == ""
    finally:
        for process in sessions:
            process.send_signal(signal.SIGINT)
        for process in sessions:
            process.communicate(timeout=60)
