"""``ros2 param list|get|set|dump|load``, through course_lib.ros.parameters (the node's services)."""

from __future__ import annotations

import re

from course_lib.ros2cli.common import Verb, add_discovery_arguments, run_group, say, wait_for_name, wait_for_whole_graph

#: ros2cli's default --timeout of the param verbs: seconds to wait for the node after --spin-time
#: (the wait goes on while discovery still changes the graph; see common.wait_for_name).
NODE_TIMEOUT = 1

#: Verbs of ros2cli's ``ros2 param`` that the course leaves out.
LEFT_OUT = ("delete", "describe")

#: How ``ros2 param get`` labels a value, by its type's name in course_lib.ros.parameters.TYPE_NAMES.
LABELS = {"boolean": "Boolean value is:", "integer": "Integer value is:", "double": "Double value is:",
          "string": "String value is:", "byte array": "Byte values are:",
          "boolean array": "Boolean values are:", "integer array": "Integer values are:",
          "double array": "Double values are:", "string array": "String values are:"}


def _absolute(node_name: str) -> str:
    return node_name if node_name.startswith("/") else "/" + node_name


def _node_arguments(parser, parameter: bool = False) -> None:
    add_discovery_arguments(parser)
    parser.add_argument("node_name", help="Name of the ROS node")
    parser.add_argument("--include-hidden-nodes", action="store_true", help="Consider hidden nodes as well")
    if parameter:
        parser.add_argument("parameter_name", help="Name of the parameter")


def _add_timeout(parser) -> None:
    parser.add_argument("--timeout", metavar="N", type=int, default=NODE_TIMEOUT,
                        help="Wait for N seconds until node becomes available (default %(default)s sec)")


def _find_node(args) -> str | None:
    """The node's full name once it is in the graph (waiting like ros2cli does), else None."""
    from course_lib.ros import graph

    name = _absolute(args.node_name)
    shown = wait_for_name(lambda: name in graph.node_list(all=args.include_hidden_nodes), args.spin_time,
                          args.timeout)
    return name if shown else None


# --- ros2 param list ---------------------------------------------------------------------

def _list_arguments(parser) -> None:
    add_discovery_arguments(parser)
    parser.add_argument("node_name", nargs="?", help="Name of the ROS node")
    parser.add_argument("--filter", help="Only parameters matching the regex expression will be showed")
    parser.add_argument("--include-hidden-nodes", action="store_true", help="Consider hidden nodes as well")
    parser.add_argument("--param-prefixes", nargs="+", default=[],
                        help="Only list parameters with the provided prefixes")
    parser.add_argument("--param-type", action="store_true", help="Print parameter types with parameter names")


def _list(args) -> str | None:
    from course_lib.ros import graph, parameters

    if args.node_name:
        args.timeout = 0  # ros2cli's param list looks once, after --spin-time
        node = _find_node(args)
        if node is None:
            return "Node not found"
        nodes = [node]
    else:
        wait_for_whole_graph(args.spin_time)
        nodes = graph.node_list(all=args.include_hidden_nodes)
    pattern = re.compile(args.filter) if args.filter else None
    for node in sorted(set(nodes)):
        try:
            names = parameters.names(node, prefixes=args.param_prefixes)
        except TimeoutError:
            print(f"Wait for service timed out waiting for parameter services for node {node}")
            continue
        if pattern is not None:
            names = [name for name in names if pattern.match(name)]
        if not args.node_name and names:
            print(f"{node}:")
        kinds = parameters.types(node, names) if args.param_type and names else {}
        for name in names:
            print(f"  {name} (type: {kinds[name]})" if args.param_type else f"  {name}")
    return None


# --- ros2 param get / set ----------------------------------------------------------------

def _get_arguments(parser) -> None:
    _node_arguments(parser, parameter=True)
    parser.add_argument("--hide-type", action="store_true", help="Hide the type information")
    _add_timeout(parser)


def _get(args) -> str | None:
    from rclpy.parameter import parameter_value_to_python

    from course_lib.ros import parameters

    node = _find_node(args)
    if node is None:
        return "Node not found"
    found = parameters.values(node, [args.parameter_name])
    if not found:
        return "Parameter not set"
    value = found[0]
    kind = parameters.TYPE_NAMES.get(value.type)
    if kind == "not set":
        print("Parameter not set.")
        return None
    if kind not in LABELS:
        return f"Unknown parameter type '{value.type}'"
    python = parameter_value_to_python(value)
    print(python if args.hide_type else f"{LABELS[kind]} {python}")
    return None


def _set_arguments(parser) -> None:
    _node_arguments(parser, parameter=True)
    parser.add_argument("value", help="Value of the parameter")
    _add_timeout(parser)


def _set(args) -> str | None:
    from rcl_interfaces.msg import Parameter
    from rclpy.parameter import get_parameter_value

    from course_lib.ros import parameters

    node = _find_node(args)
    if node is None:
        return "Node not found"
    # The value is read as YAML, as ros2cli reads it: 5 is an integer, 5.0 a double, true a bool.
    parameter = Parameter(name=args.parameter_name, value=get_parameter_value(string_value=args.value))
    result = parameters.set_parameters(node, [parameter])[0]
    if result.successful:
        say("Set parameter successful" + (f": {result.reason}" if result.reason else ""))
    else:  # ros2cli prints a rejection on stderr and still exits with 0
        say("Setting parameter failed" + (f": {result.reason}" if result.reason else ""), error=True)
    return None


# --- ros2 param dump / load --------------------------------------------------------------

def _dump_arguments(parser) -> None:
    _node_arguments(parser)
    _add_timeout(parser)


def _dump(args) -> str | None:
    from course_lib.ros import parameters

    node = _find_node(args)
    if node is None:
        return "Node not found"
    # ros2 param dump prints; `ros2 param dump /node > node.yaml` makes the --params-file.
    print(parameters.dump(node))
    return None


def _load_arguments(parser) -> None:
    _node_arguments(parser)
    parser.add_argument("parameter_file", help="Parameter file")
    parser.add_argument("--no-use-wildcard", action="store_true",
                        help="Do not load parameters in the '/**' namespace into the node")
    _add_timeout(parser)


def _load(args) -> str | None:
    from course_lib.ros import parameters

    node = _find_node(args)
    if node is None:
        return "Node not found"
    for name, result in parameters.load(node, args.parameter_file, use_wildcard=not args.no_use_wildcard):
        outcome = "successful" if result.successful else "failed"
        say(f"Set parameter {name} {outcome}" + (f": {result.reason}" if result.reason else ""),
            error=not result.successful)
    return None


VERBS = {
    "dump": Verb("Show all of the parameters of a node in a YAML file format", _dump_arguments, _dump),
    "get": Verb("Get parameter", _get_arguments, _get),
    "list": Verb("Output a list of available parameters", _list_arguments, _list),
    "load": Verb("Load parameter file for a node", _load_arguments, _load),
    "set": Verb("Set parameter", _set_arguments, _set),
}


def main(argv: list[str]):
    return run_group("ros2 param", "Various param related sub-commands", VERBS, argv, missing=LEFT_OUT)
