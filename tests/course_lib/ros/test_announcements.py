"""course_lib.ros.announcements: what a process's rmw announces about its nodes, read from the
DDS topic rclpy cannot subscribe to."""

import os

import pytest
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

        assert session.wait_for(lambda: mine() and "/announcer" in mine()[0].nodes, timeout=10)
        nodes, gids = mine()[0]
        assert {"/announcer", "/" + session.tool_node_name()} <= nodes
        publisher = tool.get_publishers_info_by_topic("/announced")[0]
        assert bytes(publisher.endpoint_gid)[:16] in gids
    heard.close()  # a second close does nothing
    assert session.wait_for(lambda: _graph_readers(tool) == before, timeout=10)



def test_parse_reads_the_message_as_rclpy_does():
    """parse() reads rmw's CDR bytes to what rclpy's deserialization of the message holds, in
    both byte orders; what is not such a message is refused."""
    from rclpy.serialization import deserialize_message, serialize_message
    from rmw_dds_common.msg import Gid, NodeEntitiesInfo, ParticipantEntitiesInfo

    gids = [Gid(data=list(range(n, n + 16))) for n in (1, 40, 90)]
    message = ParticipantEntitiesInfo(gid=Gid(data=[7] * 16), node_entities_info_seq=[
        NodeEntitiesInfo(node_namespace="/", node_name="talker", writer_gid_seq=gids[:2]),
        NodeEntitiesInfo(node_namespace="/robot", node_name="a", reader_gid_seq=gids[2:], writer_gid_seq=[])])
    data = serialize_message(message)
    read = deserialize_message(data, ParticipantEntitiesInfo)
    participant, announced = announcements.parse(data)
    assert participant == bytes(read.gid.data) == bytes([7] * 16)
    assert announced.nodes == {"/talker", "/robot/a"}
    assert announced.gids == {bytes(g.data) for info in read.node_entities_info_seq
                              for g in (*info.reader_gid_seq, *info.writer_gid_seq)} == {bytes(g.data) for g in gids}
    assert announcements.parse(bytes([0, 0, 0, 0]) + _big_endian(message)) == (participant, announced)
    for bad in (b"", data[:-3], b"\x00\x07\x00\x00" + data[4:]):
        with pytest.raises(ValueError):
            announcements.parse(bad)


def _big_endian(message) -> bytes:
    """The message's body in big-endian CDR (what a big-endian machine's rmw would send)."""
    import struct

    out = bytearray(bytes(message.gid.data))

    def count(value):
        out.extend(bytes(-len(out) % 4))
        out.extend(struct.pack(">I", value))

    count(len(message.node_entities_info_seq))
    for info in message.node_entities_info_seq:
        for text in (info.node_namespace, info.node_name):
            count(len(text) + 1)
            out.extend(text.encode() + b"\0")
        for seq in (info.reader_gid_seq, info.writer_gid_seq):
            count(len(seq))
            for gid in seq:
                out.extend(bytes(gid.data))
    return bytes(out)
