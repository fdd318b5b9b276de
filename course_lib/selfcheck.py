"""Instant self-checks for the lesson tasks (the graded assignments have their own checks).

Each check returns a Verdict, which a notebook shows as one line (✔ or ✘ and what to do) and
which is true only when the answer is right. A check never raises on a wrong answer, so "Run
All" goes on to the end of a lesson. A stub left as it is gets "not done yet" and a hint; a
wrong answer gets what is wrong.
"""

from __future__ import annotations

import dataclasses

PLACEHOLDERS = (None, ..., "...", "")


@dataclasses.dataclass(frozen=True)
class Verdict:
    ok: bool
    text: str

    def __bool__(self) -> bool:
        return self.ok

    def __str__(self) -> str:
        return ("✔ " if self.ok else "✘ ") + self.text

    def _repr_pretty_(self, printer, cycle):  # how IPython shows it as a cell's result
        printer.text(str(self))


def _verdict(ok: bool, text: str) -> Verdict:
    return Verdict(ok, text)


def _not_done(answer, hint: str) -> Verdict | None:
    if any(answer is p or (isinstance(answer, str) and answer == p) for p in PLACEHOLDERS):
        return _verdict(False, "Not done yet. " + hint)
    return None


def task1_node_name(answer, expected_node: str = "my_node") -> Verdict:
    """Task 1 (lesson 00): the name of the student's node as `ros2 node list` prints it."""
    from course_lib import graph

    hint = "Run graph.node_list() and copy your node's name, exactly as printed, into my_node_name."
    if (result := _not_done(answer, hint)) is not None:
        return result
    if not isinstance(answer, str):
        return _verdict(False, f"my_node_name should be a string like the list's entries, not {type(answer).__name__}.")
    names = graph.node_list()
    if answer in names and answer.rsplit("/", 1)[-1] == expected_node:
        return _verdict(True, f"{answer} is in the node list: your node is running and discoverable.")
    if "/" + answer in names:
        return _verdict(False, f"Almost: node list entries are fully qualified names, with the namespace. "
                               f"Write '/{answer}'.")
    if answer in names:
        return _verdict(False, f"{answer} is a node, but not yours: look for '{expected_node}'.")
    if not any(n.endswith("/" + expected_node) for n in names):
        return _verdict(False, f"{expected_node} is not in the node list at all: is it still running? "
                               "Run the cell that starts it (workspace.run) again, then graph.node_list().")
    return _verdict(False, f"{answer!r} is not in the node list {names}.")


def task2_echo(messages, topic: str = "/chatter", text_prefix: str = "Hello World") -> Verdict:
    """Task 2 (lesson 01): messages echoed from the talker's topic, like `ros2 topic echo --once`."""
    hint = f"Call graph.topic_echo({topic!r}) while the talker runs and store what it returns in echoed."
    if (result := _not_done(messages, hint)) is not None:
        return result
    if not isinstance(messages, (list, tuple)):
        messages = [messages]
    if not messages:
        return _verdict(False, f"Nothing was echoed: is the talker running and publishing on {topic}? "
                               "Check graph.topic_list() for the topic's name.")
    first = messages[0]
    data = getattr(first, "data", None)
    if not isinstance(data, str):
        return _verdict(False, f"Got a {type(first).__name__}, but {topic} carries std_msgs/msg/String: "
                               "did you echo the right topic?")
    if not data.startswith(text_prefix):
        return _verdict(False, f"Got {data!r}, which the talker did not send: echo {topic}, not another topic.")
    return _verdict(True, f"Echoed {len(messages)} message(s) from {topic}; the first says {data!r}.")
