"""The TF tree as view_frames draws it: tf2's frames YAML -> Graphviz text (``frames.gv``, upstream's
layout) -> a picture (``frames.pdf`` or a figure in the notebook), without Graphviz's ``dot``.

    data = yaml.safe_load(buffer.all_frames_as_yaml())
    Path("frames.gv").write_text(dot_text(data, 12.5))
    figure = draw(read_gv("frames.gv"))          # what the notebook shows

Plain Python and matplotlib, no ROS; tested in tests/course_lib/robot/test_tf2_tools.py.
"""

from __future__ import annotations

import re
from pathlib import Path

#: The label lines upstream writes on each edge, and the frame's YAML key each shows.
EDGE_LABELS = (("Broadcaster", "broadcaster"), ("Average rate", "rate"), ("Buffer length", "buffer_length"),
               ("Most recent transform", "most_recent_transform"), ("Oldest transform", "oldest_transform"))
_EDGE = re.compile(r'^"(?P<parent>[^"]*)" -> "(?P<child>[^"]*)"\[label=" (?P<label>.*)"\];$', re.MULTILINE)
_RECORDED = re.compile(r'"Recorded at time: (?P<time>[^"]*)"')


def dot_text(data: dict, recorded_time: float) -> str:
    """The Graphviz digraph of tf2_tools' view_frames for `data` (frame -> its YAML entry)."""
    if not data:
        return 'digraph G { "No tf data received" }'
    lines, root = ["digraph G {"], None
    for child, entry in data.items():
        label = "".join(f"{words}: {entry[key]}\\n" for words, key in EDGE_LABELS)
        lines.append(f'"{entry["parent"]}" -> "{child}"[label=" {label}"];')
        if entry["parent"] not in data:
            root = entry["parent"]
    lines += ["edge [style=invis];",
              ' subgraph cluster_legend { style=bold; color=black; label ="view_frames Result";',
              f'"Recorded at time: {recorded_time}"[ shape=plaintext ] ;',
              f'}}->"{root}";', "}"]
    return "\n".join(lines)


def read_gv(path: str | Path) -> dict:
    """The frames of a view_frames ``.gv`` file: {"edges": [(parent, child, label lines)], "recorded": str}."""
    text = Path(path).read_text()
    edges = [(m["parent"], m["child"], [line for line in m["label"].split("\\n") if line])
             for m in _EDGE.finditer(text)]
    recorded = _RECORDED.search(text)
    return {"edges": edges, "recorded": recorded["time"] if recorded else ""}


def layout(edges: list[tuple[str, str, list]]) -> dict[str, tuple[float, int]]:
    """(x, depth) of every frame: roots on top, each parent centred over its children."""
    children: dict[str, list[str]] = {}
    for parent, child, _ in edges:
        children.setdefault(parent, []).append(child)
    roots = sorted({p for p, _, _ in edges} - {c for _, c, _ in edges})
    places: dict[str, tuple[float, int]] = {}
    next_x = [0.0]

    def place(frame: str, depth: int) -> float:
        below = [c for c in sorted(children.get(frame, [])) if c not in places]
        if below:
            xs = [place(c, depth + 1) for c in below]
            x = (xs[0] + xs[-1]) / 2
        else:
            x, next_x[0] = next_x[0], next_x[0] + 1
        places[frame] = (x, depth)
        return x

    for root in roots:
        place(root, 0)
    return places


def draw(graph: dict, title: str = "view_frames Result"):
    """A matplotlib Figure of the tree of read_gv's `graph`: each frame an ellipse, each transform an
    arrow from parent to child labelled as upstream labels it."""
    import matplotlib.pyplot as plt
    from matplotlib.patches import Ellipse

    places = layout(graph["edges"])
    width = max((x for x, _ in places.values()), default=0) + 1
    depth = max((d for _, d in places.values()), default=0) + 1
    figure, axes = plt.subplots(figsize=(max(4.0, 3.2 * width), 0.6 + 2.0 * depth))
    for parent, child, label in graph["edges"]:
        (x0, d0), (x1, d1) = places[parent], places[child]
        axes.annotate("", xy=(x1, -d1 + 0.2), xytext=(x0, -d0 - 0.2),
                      arrowprops={"arrowstyle": "-|>", "color": "black"})
        axes.text((x0 + x1) / 2 + 0.05, -(d0 + d1) / 2, "\n".join(label), fontsize=6, va="center")
    for frame, (x, d) in places.items():
        axes.add_patch(Ellipse((x, -d), 0.7, 0.36, facecolor="white", edgecolor="black"))
        axes.text(x, -d, frame, ha="center", va="center", fontsize=9)
    if not places:
        axes.text(0.5, 0.5, "No tf data received", ha="center", va="center", transform=axes.transAxes)
    axes.set_xlim(-0.6, width - 0.4)
    axes.set_ylim(-depth + 0.4, 0.5)
    axes.set_axis_off()
    recorded = f"\nRecorded at time: {graph['recorded']}" if graph.get("recorded") else ""
    axes.set_title(title + recorded, fontsize=9)
    figure.tight_layout()
    return figure


def show(path: str | Path):
    """The picture of a view_frames ``.gv`` file, for the notebook (``frame_graph.show("frames.gv")``)."""
    import matplotlib.pyplot as plt

    figure = draw(read_gv(path))
    plt.close(figure)  # shown once, as the cell's value, not again by the inline backend
    return figure
