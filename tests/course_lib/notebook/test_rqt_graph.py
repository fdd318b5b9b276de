"""Tests for course_lib.notebook.rqt_graph: the picture of the ROS graph, rqt_graph's stand-in."""

import pytest
from rclpy.node import Node
from std_msgs.msg import String

from course_lib.notebook import rqt_graph
from course_lib.ros import discovery, session


@pytest.fixture
def local_session(domain_id, monkeypatch):
    """A session on a domain of its own, stopped afterwards; no discovery wait (all nodes are in this process)."""
    monkeypatch.setattr(discovery, "SETTLE_SECONDS", 0.0)
    session.stop()
    session.start(domain_id=domain_id)
    yield domain_id
    session.stop()


def test_layered_layout_is_layered_and_survives_cycles():
    """Sources sit left of what they feed; a cycle does not stop the layout or make it random."""
    edges = [("cam", "/image"), ("/image", "detector"), ("detector", "/markers"),
             ("/markers", "viewer"), ("viewer", "/image")]
    layout = rqt_graph.layered_layout(edges)
    assert rqt_graph.layered_layout(list(reversed(edges))) == layout
    assert layout["cam"][0] < layout["/image"][0] < layout["detector"][0] < layout["/markers"][0]
    assert len({position for position in layout.values()}) == len(layout)


def test_draw_graph_shows_nodes_and_topics_left_to_right(local_session):
    """draw_graph() draws talker -> /chatter -> listener, and leaves out /rosout and tool node."""
    from matplotlib.figure import Figure  # here, not at collection, where every test worker would pay it
    from matplotlib.text import Annotation

    session.add_node(Node("talker")).create_publisher(String, "chatter", 10)
    session.add_node(Node("listener")).create_subscription(String, "chatter", lambda msg: None, 10)
    figure = rqt_graph.draw_graph()
    assert isinstance(figure, Figure)
    texts = {t.get_text(): t for t in figure.axes[0].texts if not isinstance(t, Annotation)}
    assert set(texts) == {"/talker", "/chatter", "/listener"}
    x = {name: text.get_position()[0] for name, text in texts.items()}
    assert x["/talker"] < x["/chatter"] < x["/listener"]
    arrows = [t for t in figure.axes[0].texts if isinstance(t, Annotation)]
    assert len(arrows) == 2
    everything = {t.get_text() for t in rqt_graph.draw_graph(all=True, hide_topics=()).axes[0].texts}
    assert {"/rosout", "/parameter_events", "/" + session.tool_node_name()} <= everything
