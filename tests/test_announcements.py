"""course_lib.ros.announcements: what a process's rmw announces about its nodes, read from the
DDS topic rclpy cannot subscribe to."""

import os

from rclpy.node import Node
from std_msgs.msg import String

from course_lib.ros import announcements, discovery, session


def _graph_readers(tool) -> int:
    return len(tool.get_subscriptions_info_by_topic(announcements.TOPIC, no_mangle=True))


def test_a_process_announces_each_node_with_its_endpoints(session_domain):
    """This process's participant announces the node it holds, named, with the GID of its
    publisher (the one the graph shows); the reader is gone once closed."""
    tool = session.tool_node()
    node = Node("announcer")
    node.create_publisher(String, "announced", 10)
    session.add_node(node)
    before = _graph_readers(tool)  # rmw's own reader, one per participant
    with announcements.Announcements(tool) as heard:
        assert session.wait_for(lambda: _graph_readers(tool) == before + 1, timeout=10)

        def mine():
            return [message for participant, message in heard.latest().items()
                    if discovery._process_of(participant) == os.getpid() & 0xFFFF]

        assert session.wait_for(lambda: mine() and "/announcer" in announcements.endpoints_of(mine()[0])[0],
                                timeout=10)
        nodes, gids = announcements.endpoints_of(mine()[0])
        assert {"/announcer", "/" + session.TOOL_NODE_NAME} <= nodes
        publisher = tool.get_publishers_info_by_topic("/announced")[0]
        assert bytes(publisher.endpoint_gid)[:16] in gids
    heard.close()  # a second close does nothing
    assert session.wait_for(lambda: _graph_readers(tool) == before, timeout=10)
