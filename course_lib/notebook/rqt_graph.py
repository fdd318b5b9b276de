"""A picture of the running ROS graph, rqt_graph's "Nodes/Topics" view drawn with matplotlib."""

from __future__ import annotations

import math

from course_lib.ros import node_names
from course_lib.ros.discovery import _graph_node
from course_lib.ros.graph import node_list

#: Topics every rclpy node has; draw_graph() leaves them out unless asked.
DEFAULT_HIDDEN_TOPICS = ("/rosout", "/parameter_events")

# --- rqt_graph --------------------------------------------------------------------------

def graph_edges(all: bool = False,  # noqa: A002
                hide_topics=DEFAULT_HIDDEN_TOPICS) -> list[tuple[str, str, str]]:
    """Who publishes and who subscribes to what, as (node, topic, "publishes"/"subscribes").

    Args:
        all: keep hidden nodes and topics (like the session's tool node).
        hide_topics: topics to leave out.

    Returns:
        Sorted, de-duplicated triples with fully-qualified names.
    """
    node = _graph_node()
    edges = set()
    for topic, _ in node.get_topic_names_and_types():
        if topic in hide_topics or (not all and node_names.is_hidden(topic)):
            continue
        for kind, infos in (("publishes", node.get_publishers_info_by_topic(topic)),
                            ("subscribes", node.get_subscriptions_info_by_topic(topic))):
            for info in infos:
                if all or not info.node_name.startswith("_"):
                    edges.add((node_names.full_name(info.node_namespace, info.node_name), topic, kind))
    return sorted(edges)


def layered_layout(edges) -> dict:
    """Columns and rows for a left-to-right drawing of a directed graph.

    Each vertex goes one column right of its furthest predecessor (cycles are broken where a
    depth-first walk in name order closes them); within a column, vertices sit near the mean
    row of their predecessors, ties broken by name. The layout depends only on ``edges``.

    Args:
        edges: (source, target) pairs of sortable vertices (names, or tuples of names).

    Returns:
        ``{vertex: (column, row)}``.
    """
    vertices = sorted({v for edge in edges for v in edge})
    successors = {v: sorted({t for s, t in edges if s == v}) for v in vertices}
    # Depth-first walk in name order; edges back to a vertex still on the stack close a cycle.
    on_stack, done, finish_order, forward = set(), set(), [], []
    for root in vertices:
        if root in done:
            continue
        stack = [(root, iter(successors[root]))]
        on_stack.add(root)
        while stack:
            vertex, children = stack[-1]
            child = next(children, None)
            if child is None:
                stack.pop()
                on_stack.discard(vertex)
                done.add(vertex)
                finish_order.append(vertex)
            elif child in on_stack:
                continue  # back edge: ignored for layering
            else:
                forward.append((vertex, child))
                if child not in done:
                    on_stack.add(child)
                    stack.append((child, iter(successors[child])))
    predecessors = {v: sorted({s for s, t in forward if t == v}) for v in vertices}
    column = {}
    for vertex in reversed(finish_order):  # a topological order of the acyclic part
        column[vertex] = max((column[p] + 1 for p in predecessors[vertex]), default=0)
    layout = {}
    for col in range(max(column.values(), default=-1) + 1):
        members = [v for v in vertices if column[v] == col]

        def centre(v):
            rows = [layout[p][1] for p in predecessors[v] if p in layout]
            return (sum(rows) / len(rows) if rows else math.inf, v)

        for row, vertex in enumerate(sorted(members, key=centre)):
            layout[vertex] = (col, row)
    return layout


def draw_graph(ax=None, all: bool = False,  # noqa: A002
               hide_topics=DEFAULT_HIDDEN_TOPICS):
    """Draw nodes (ellipses) and topics (boxes) with publisher -> topic -> subscriber arrows.

    Like rqt_graph's "Nodes/Topics" view, drawn with matplotlib in a fixed layered layout.

    Args:
        ax: a matplotlib Axes to draw into; None makes a new Figure (not through pyplot, so
            a notebook shows it once, as the cell's value).
        all: also draw hidden nodes and topics (the session's tool node).
        hide_topics: topics to leave out; by default /rosout and /parameter_events.

    Returns:
        The matplotlib Figure.
    """
    from matplotlib.figure import Figure

    # Vertices are ("node", name) or ("topic", name): a node and a topic may share a name.
    edges = []
    for node, topic, kind in graph_edges(all=all, hide_topics=hide_topics):
        pair = [("node", node), ("topic", topic)]
        edges.append(tuple(pair if kind == "publishes" else pair[::-1]))
    layout = layered_layout(edges)
    # Nodes without any shown connection still belong in the picture, in a column of their own.
    lonely = sorted({("node", name) for name in node_list(all=all)} - set(layout))
    spare_column = max((c for c, _ in layout.values()), default=-1) + 1
    for row, vertex in enumerate(lonely):
        layout[vertex] = (spare_column, row)
    columns = max((c for c, _ in layout.values()), default=0) + 1
    height = {col: sum(1 for c, _ in layout.values() if c == col) for col in range(columns)}
    rows = max(height.values(), default=1)
    if ax is None:
        figure = Figure(figsize=(max(4.0, 2.4 * columns), max(2.0, 0.9 * rows + 0.8)))
        ax = figure.add_subplot()
    figure = ax.figure
    ax.set_axis_off()
    ax.set_xlim(-0.6, columns - 0.4)
    ax.set_ylim(-0.6 - (rows - 1) / 2, 0.6 + (rows - 1) / 2)
    if not layout:
        ax.text(0, 0, "no nodes found", ha="center", va="center", color="gray")
        return figure
    labels = {}
    for vertex, (col, row) in sorted(layout.items()):
        kind, name = vertex
        style = (dict(boxstyle="square,pad=0.4", facecolor="#fff2cc", edgecolor="#b58900")
                 if kind == "topic" else
                 dict(boxstyle="ellipse,pad=0.3", facecolor="#dbe9f6", edgecolor="#1f4e79"))
        labels[vertex] = ax.text(col, (height[col] - 1) / 2 - row, name, ha="center",
                                 va="center", fontsize=9, bbox=style, zorder=2)
    for source, target in edges:
        ax.annotate("", xy=labels[target].get_position(), xytext=labels[source].get_position(),
                    arrowprops=dict(arrowstyle="-|>", color="#444444", shrinkA=0, shrinkB=0,
                                    mutation_scale=12,
                                    patchA=labels[source].get_bbox_patch(),
                                    patchB=labels[target].get_bbox_patch()),
                    # Above the labels: their boxes, which clip the arrow, are sized as they
                    # are drawn, so they must be drawn first.
                    zorder=3)
    return figure
