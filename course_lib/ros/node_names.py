"""Node names as ROS 2 forms them: the full name a node will get, has, or shows in the graph.

The notebook session replaces a node by the name it *will* get (:func:`expected_name`, after the
``__node``/``__ns`` remaps of its arguments); the graph reports namespace and name apart
(:func:`full_name`); names with a token that starts with "_" are hidden (:func:`is_hidden`).
"""

from __future__ import annotations


def full_name(namespace: str, name: str) -> str:
    """"/ns/name" from a node's namespace and name, as the graph reports them."""
    return namespace.rstrip("/") + "/" + name


def is_hidden(name: str) -> bool:
    """A hidden node, topic or service name: ros2 lists it only with --all / --include-hidden."""
    # Like rclpy's topic_or_service_is_hidden: any token of the name that starts with "_".
    return any(token.startswith("_") for token in name.split("/") if token)


def expected_name(node_name: str, namespace: str | None = None, cli_args=None) -> str:
    """The fully-qualified name a node will get: "/ns/name", after ``__node``/``__ns`` remaps.

    Args:
        node_name: the name passed to Node().
        namespace: the namespace passed to Node(); None or "" is the root namespace.
        cli_args: the node's own arguments, e.g. ["--ros-args", "-r", "__ns:=/robot1"].
    """
    for arg in map(str, cli_args or ()):  # "-r __node:=x" or "-r talker:__node:=x"
        if "__node:=" in arg:
            node_name = arg.split("__node:=", 1)[1]
        elif "__ns:=" in arg:
            namespace = arg.split("__ns:=", 1)[1]
    return full_name("/" + (namespace or "").strip("/"), node_name)


def alive_name(node) -> str:
    """The fully-qualified name of a node that still exists; a clear error for a destroyed one."""
    from rclpy.exceptions import InvalidHandle

    try:
        return node.get_fully_qualified_name()
    except InvalidHandle:
        raise ValueError("This node was destroyed (by session.stop(), session.remove_node() or "
                         "destroy_node()): create it again") from None
