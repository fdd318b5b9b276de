"""Destroying a node so that it leaves the ROS graph.

Jazzy's ``Node.destroy_node`` destroys the node's publishers, subscriptions, service clients and
servers, timers and guard conditions, but not its waitables: an ``ActionClient(node, ...)`` or
``ActionServer(node, ...)`` that nobody destroyed keeps a share of the rcl node, which then stays
in the graph (``ros2 node list``, another process's ``get_node_names_and_namespaces``) until the
process ends, however long ago its context was shut down. A check that later reserved the same
ROS domain in that process saw the left-over node as the student's.
"""

from __future__ import annotations

import sys


def destroy_node(node) -> None:
    """Destroy the action clients and servers made on ``node``, then the node. Safe on a node
    (or waitable) destroyed already."""
    action = sys.modules.get("rclpy.action")  # not imported: the process has no action client or server
    kinds = (action.ActionClient, action.ActionServer) if action is not None else ()
    for waitable in list(node.waitables):
        if isinstance(waitable, kinds):  # not the QoS event handlers: destroy_node's
            try:
                waitable.destroy()
            except Exception:  # destroyed already: nothing to free
                pass
    try:
        node.destroy_node()
    except Exception:  # already destroyed, or its context is gone: nothing left to free
        pass
