"""course_lib.ros.discovery: the wait for discovery ends once the graph has stopped changing, not
after a fixed time (the rule with a made-up clock and graph; then against a real process, where
the rule, not the backstop, ends a wait for a name that never shows)."""

import sys

from course_lib.ros import discovery, processes, session


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
