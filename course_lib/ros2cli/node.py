"""``ros2 node list`` and ``ros2 node info NODE``, printed from course_lib.ros.graph."""

from __future__ import annotations

import sys

from course_lib.ros2cli.common import Verb, add_discovery_arguments, run_group, wait_for_whole_graph


def _list_arguments(parser) -> None:
    add_discovery_arguments(parser)
    parser.add_argument("-a", "--all", action="store_true", help="Display all nodes even hidden ones")
    parser.add_argument("-c", "--count-nodes", action="store_true",
                        help="Only display the number of nodes discovered")


def _list(args) -> None:
    from course_lib.ros2cli import daemon

    names = daemon.graph_answer(args, "nodes", all=args.all)
    if names is daemon.DIRECT:
        from course_lib.ros import graph

        wait_for_whole_graph(args.spin_time)
        names = graph.node_list(all=args.all)
    if args.count_nodes:
        print(len(names))
    elif names:
        if len(set(names)) < len(names):
            print("WARNING: Be aware that there are nodes in the graph that share an exact name, "
                  "which can have unintended side effects.", file=sys.stderr)
        print("\n".join(names))


def _info_arguments(parser) -> None:
    add_discovery_arguments(parser)
    parser.add_argument("node_name", help="Node name to request information")
    parser.add_argument("--include-hidden", action="store_true",
                        help="Display hidden topics, services, and actions as well")


def _info(args) -> str | None:
    from course_lib.ros import graph_info
    from course_lib.ros2cli import daemon

    # Like ros2cli: the name as given (a full name), among the nodes --include-hidden shows.
    answer = daemon.graph_answer(args, "node_info", name=args.node_name, include_hidden=args.include_hidden)
    if answer is None:
        count, info = 0, None
    elif answer is not daemon.DIRECT:
        count, info = answer["count"], daemon.node_info_of(answer["info"])
    else:
        from course_lib.ros import graph

        wait_for_whole_graph(args.spin_time)  # all the node's endpoints, not the first found
        count = graph.node_list(all=args.include_hidden).count(args.node_name)
        info = graph.node_info(args.node_name, include_hidden=args.include_hidden, timeout=0.0) if count else None
    if not count:
        return f"Unable to find node '{args.node_name}'"
    if count > 1:
        print(f'There are {count} nodes in the graph with the exact name "{info.name}". '
              "You are seeing information about only one of them.", file=sys.stderr)
    print(graph_info.format_node_info(info), end="")
    return None


VERBS = {
    "info": Verb("Output information about a node", _info_arguments, _info),
    "list": Verb("Output a list of available nodes", _list_arguments, _list),
}


def main(argv: list[str]):
    return run_group("ros2 node", "Various node related sub-commands", VERBS, argv)
