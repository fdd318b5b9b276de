"""course_lib.ros.discovery: the wait for discovery ends once the graph has stopped changing, not
after a fixed time (the rule with a made-up clock and graph; then against a real process, where
the rule, not the backstop, ends a wait for a name that never shows)."""

import os
import subprocess
import sys

from course_lib.ros import announcements, discovery, processes, session


def settling(minimum=0.5, quiet=0.2, complete_within=4.0):
    """A rule for a tool node made at t=0 that has seen graph "a" at t=0."""
    return discovery.Settling(created_at=0.0, now=0.0, graph="a", minimum=minimum, quiet=quiet,
                              complete_within=complete_within)


def everyone_shown():
    return True


def test_the_wait_ends_once_the_graph_has_stayed_the_same_for_the_quiet_time():
    """Changes at 0.3 and 0.6 s keep it going; 0.2 s after the last one it ends."""
    rule = settling()
    graphs = {0.1: "a", 0.3: "ab", 0.45: "ab", 0.6: "abc", 0.7: "abc", 0.79: "abc", 0.8: "abc"}
    ended = [now for now, graph in graphs.items() if rule.settled(now, graph, everyone_shown)]
    assert ended == [0.8] and rule.changes == 2


def test_a_quiet_graph_still_waits_for_the_minimum():
    """ros2cli spins --spin-time before it answers, however quiet the graph is."""
    rule = settling(minimum=0.5)
    assert not rule.settled(0.4, "a", everyone_shown)
    assert rule.settled(0.5, "a", everyone_shown)


def test_the_wait_goes_on_until_every_process_here_has_shown_its_nodes():
    """A quiet graph that does not yet show every ROS process on the machine is not settled,
    until complete_within has passed; once shown, the count is not asked again."""
    asked = []

    def shown_from_two_seconds(now):
        def shown():
            asked.append(now)
            return now >= 2.0
        return shown

    rule = settling(complete_within=4.0)
    assert [now for now in (1.0, 1.5, 2.0, 2.5) if rule.settled(now, "a", shown_from_two_seconds(now))] == [2.0, 2.5]
    assert asked == [1.0, 1.5, 2.0]
    never = settling(complete_within=4.0)
    assert not never.settled(3.9, "a", lambda: False)
    assert never.settled(4.0, "a", lambda: False)


def test_a_name_that_never_shows_ends_the_wait_when_the_graph_has_settled(domain_id, tmp_path):
    """With another process's node in the graph, waiting for a name nobody has ends by the rule
    (True) long before its backstop (which would return False), whatever the machine's speed."""
    script = tmp_path / "node.py"
    script.write_text("import rclpy, rclpy.node\nrclpy.init()\nnode = rclpy.node.Node('settled_talker')\n"
                      "try:\n    rclpy.spin(node)\nexcept KeyboardInterrupt:\n    pass\n")
    with processes.NodeProcess([sys.executable, str(script)], domain_id=domain_id) as other:
        other.wait_for_node("settled_talker", timeout=60)
        session.stop()
        session.start(domain_id=domain_id)
        try:
            node = session.tool_node()
            looked = []

            def never():
                looked.append(node.get_fully_qualified_node_names())
                return False

            assert discovery.wait_for_discovery(minimum=0.0, quiet=0.2, complete_within=60.0, until=never)
            assert "/settled_talker" in looked[-1]  # it had seen the other process
        finally:
            session.stop()


# --- which processes have shown all they announced ----------------------------------------

def _gid(pid: int, entity: int) -> bytes:
    """A Fast DDS GID: the process id's low 16 bits in bytes 4-5 of the participant's prefix."""
    return bytes(4) + (pid & 0xFFFF).to_bytes(2, "little") + bytes(6) + entity.to_bytes(4, "big")


def _announced(pid: int, node: str, readers=(), writers=()):
    """{participant GID: what it announced} for a process holding one node, as
    Announcements.latest() gives it: read (announcements.parse) from the message rmw would send."""
    from rclpy.serialization import serialize_message
    from rmw_dds_common.msg import Gid, NodeEntitiesInfo, ParticipantEntitiesInfo

    info = NodeEntitiesInfo(node_namespace="/", node_name=node,
                            reader_gid_seq=[Gid(data=list(_gid(pid, r))) for r in readers],
                            writer_gid_seq=[Gid(data=list(_gid(pid, w))) for w in writers])
    participant = _gid(pid, 0x1C1)
    message = ParticipantEntitiesInfo(gid=Gid(data=list(participant)), node_entities_info_seq=[info])
    return dict([announcements.parse(serialize_message(message))])


class _Graph:
    """What a tool node's graph shows, for the rule that tells when a process has shown all it
    announced: the nodes listed, and the endpoints discovered (GIDs)."""

    def __init__(self, nodes=(), endpoints=()):
        self.nodes, self.endpoints = list(nodes), list(endpoints)

    def get_fully_qualified_node_names(self):
        return self.nodes

    def get_topic_names_and_types(self, no_demangle=False):
        assert no_demangle, "the endpoints of services (rq/, rr/) count too"
        return [("rt/chatter", ["std_msgs::msg::dds_::String_"])]

    def get_publishers_info_by_topic(self, topic, no_mangle=False):
        import types

        return [types.SimpleNamespace(endpoint_gid=list(gid)) for gid in self.endpoints]

    def get_subscriptions_info_by_topic(self, topic, no_mangle=False):
        return []


class _Heard:
    """What an Announcements reader has heard."""

    def __init__(self, *announced):
        self.announced = {participant: message for one in announced for participant, message in one.items()}

    def latest(self):
        return self.announced


def test_a_process_counts_as_shown_once_all_it_announced_is_discovered():
    """DDS announces a process's writers and its readers apart, and rmw names its nodes in a
    message of its own: a process counts as shown only once its node is listed and every endpoint
    it announced is discovered. Judged by its first reader and a named writer, a listener's
    process counted while its subscriptions had not come ("Subscription count: 0")."""
    announced = _announced(101, "listener", readers=[5, 7, 0x13], writers=[3, 4])
    some = [_gid(101, e) for e in (3, 4, 5, 7)]
    assert discovery._processes_shown(_Graph(["/listener"], some), announced) == set()
    assert discovery._processes_shown(_Graph([], some + [_gid(101, 0x13)]), announced) == set()  # not named yet
    assert discovery._processes_shown(_Graph(["/listener"], some + [_gid(101, 0x13)]), announced) == {101}
    assert discovery._processes_shown(_Graph(["/listener"], some), {}) == set()  # nothing heard yet


def test_a_listing_waits_for_the_processes_it_found_not_for_as_many():
    """A listing started beside other `ros2` commands found this process, the talker's and its own;
    a quick `ros2` process that came after it looked and showed at once must not stand in for this
    slow process, whose subscriptions had not come ("Subscription count: 0" in a suite run)."""
    me, talker, newcomer = os.getpid(), os.getppid(), 1
    here = [me, talker]
    heard = _Heard(_announced(talker, "talker", readers=[5], writers=[3]),
                   _announced(newcomer, "newcomer", writers=[3]))
    graph_now = _Graph(["/talker", "/newcomer"], [_gid(talker, 3), _gid(newcomer, 3)])
    assert not discovery._every_process_shown(graph_now, heard, here)
    graph_now.endpoints.append(_gid(talker, 5))
    assert discovery._every_process_shown(graph_now, heard, here)
    # a process of another user (None: its sockets cannot be traced) needs one more shown
    assert discovery._every_process_shown(graph_now, heard, here + [None])
    assert not discovery._every_process_shown(graph_now, _Heard(_announced(talker, "talker", readers=[5], writers=[3])),
                                              here + [None])


def test_a_listing_stops_waiting_for_a_process_that_has_ended():
    """A `ros2` command beside it that ended before showing itself does not keep a listing waiting."""
    ended = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                           text=True, check=True)
    assert discovery._every_process_shown(_Graph(), _Heard(), [os.getpid(), int(ended.stdout)])


def test_a_listing_does_not_wait_for_a_zombie():
    """Two `ros2` commands started together by one program that reaps them in turn: the one that
    ended first stays a zombie until its parent waits for it. The other one waited for it until
    its backstop (12 s under load) in a suite run."""
    ended = subprocess.Popen([sys.executable, "-S", "-c", "pass"])
    try:
        os.waitid(os.P_PID, ended.pid, os.WEXITED | os.WNOWAIT)  # it has ended; not reaped yet
        assert os.path.exists(f"/proc/{ended.pid}")
        assert discovery._every_process_shown(_Graph(), _Heard(), [os.getpid(), ended.pid])
    finally:
        ended.wait(timeout=10)
