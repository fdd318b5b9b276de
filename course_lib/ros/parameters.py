"""A running node's parameters, through the node's own parameter services: ``ros2 param``.

Every rclpy node offers services (``/talker/get_parameters``, ``/talker/set_parameters``, ...)
that other processes call to read and change its parameters while it runs. A change goes
through the node's on-set-parameters callbacks, which may accept or reject it::

    from course_lib import parameters
    parameters.names("/talker")                  # ros2 param list /talker
    parameters.get("/talker", "rate")            # ros2 param get /talker rate
    parameters.set("/talker", "rate", 10.0)      # ros2 param set /talker rate 10.0
    print(parameters.dump("/talker"))            # ros2 param dump /talker (YAML for --params-file)
    parameters.load("/talker", "talker.yaml")    # ros2 param load /talker talker.yaml

The calls go out from the session's hidden tool node, so a notebook needs no node of its own.
"""

from __future__ import annotations

import yaml
from rcl_interfaces.msg import ParameterType

from course_lib.ros import session
from course_lib.ros.run_limits import answer_limit

#: Seconds to wait for a node's parameter services (ros2 param waits as long).
SERVICE_TIMEOUT = 5.0

#: Parameter types as ``ros2 param list --param-type`` names them.
TYPE_NAMES = {ParameterType.PARAMETER_BOOL: "boolean", ParameterType.PARAMETER_INTEGER: "integer",
              ParameterType.PARAMETER_DOUBLE: "double", ParameterType.PARAMETER_STRING: "string",
              ParameterType.PARAMETER_BYTE_ARRAY: "byte array",
              ParameterType.PARAMETER_BOOL_ARRAY: "boolean array",
              ParameterType.PARAMETER_INTEGER_ARRAY: "integer array",
              ParameterType.PARAMETER_DOUBLE_ARRAY: "double array",
              ParameterType.PARAMETER_STRING_ARRAY: "string array",
              ParameterType.PARAMETER_NOT_SET: "not set"}


def _full_name(node_name: str) -> str:
    return node_name if node_name.startswith("/") else "/" + node_name


_clients: dict = {}  # (tool node, node name) -> AsyncParameterClient, for the current session


def _client(node_name: str, timeout: float):
    from rclpy.parameter_client import AsyncParameterClient

    tool = session.tool_node()
    for key in [key for key in _clients if key[0] is not tool]:  # from a session that stopped
        del _clients[key]
    client = _clients.get((tool, _full_name(node_name)))
    if client is None:
        client = _clients[tool, _full_name(node_name)] = AsyncParameterClient(tool, _full_name(node_name))
    # rclpy's wait_for_services polls every 0.25 s; matching takes a few ms on one machine.
    if not session.wait_for(client.services_are_ready, timeout=timeout, poll=0.005):
        raise TimeoutError(f"Wait for service timed out waiting for parameter services for node "
                           f"{_full_name(node_name)}: is it running (graph.node_list() or "
                           "`ros2 node list`), and was it made with start_parameter_services on?")
    return client


def _result(future, node_name: str, timeout: float):
    timeout = answer_limit(timeout)  # the node's answer, once its services were found
    if not session.wait_for(future.done, timeout=timeout, poll=0.005):
        raise TimeoutError(f"Node {_full_name(node_name)} did not answer its parameter service "
                           f"within {timeout} s: is its executor busy (a callback that never returns)?")
    if future.exception() is not None:
        raise RuntimeError(f"Exception while calling service of node {_full_name(node_name)}: "
                           f"{future.exception()}")
    return future.result()


def names(node_name: str, prefixes=(), timeout: float = SERVICE_TIMEOUT) -> list[str]:
    """The names of a node's parameters, sorted, like ``ros2 param list NODE``.

    Args:
        node_name: the node's full name, e.g. "/talker".
        prefixes: only names that start with one of these (``--param-prefixes``).
        timeout: seconds to wait for the node's parameter services and for its answer.

    Raises:
        TimeoutError: the node offers no parameter services (not running, or not reachable).
    """
    client = _client(node_name, timeout)
    return sorted(_result(client.list_parameters(prefixes=list(prefixes)), node_name, timeout).result.names)


def values(node_name: str, parameter_names, timeout: float = SERVICE_TIMEOUT) -> list:
    """The values of named parameters as rcl_interfaces/msg/ParameterValue messages.

    Returns:
        One message per name, in order; an empty list when one of them is not declared
        (that is how the node answers).
    """
    client = _client(node_name, timeout)
    return list(_result(client.get_parameters(list(parameter_names)), node_name, timeout).values)


def types(node_name: str, parameter_names, timeout: float = SERVICE_TIMEOUT) -> dict[str, str]:
    """``{name: type name}`` of declared parameters, as ``ros2 param list --param-type`` shows."""
    client = _client(node_name, timeout)
    response = _result(client.describe_parameters(list(parameter_names)), node_name, timeout)
    return {descriptor.name: TYPE_NAMES.get(descriptor.type, "unknown") for descriptor in response.descriptors}


def get(node_name: str, name: str, timeout: float = SERVICE_TIMEOUT):
    """The value of one parameter as a Python value, like ``ros2 param get``.

    Raises:
        LookupError: the node has no such parameter; the message lists the ones it has.
    """
    from rclpy.parameter import parameter_value_to_python

    found = values(node_name, [name], timeout)
    if not found:
        raise LookupError(f"Node {_full_name(node_name)} has no parameter {name!r}; it has: "
                          f"{', '.join(names(node_name, timeout=timeout))}")
    return parameter_value_to_python(found[0])


def set_parameters(node_name: str, parameters, timeout: float = SERVICE_TIMEOUT) -> list:
    """Ask a node to set parameters (rcl_interfaces/msg/Parameter messages), one by one.

    Returns:
        One rcl_interfaces/msg/SetParametersResult per parameter: ``successful`` and, when
        the node's on-set-parameters callback rejected the value, its ``reason``.
    """
    client = _client(node_name, timeout)
    return list(_result(client.set_parameters(list(parameters)), node_name, timeout).results)


def set(node_name: str, name: str, value, timeout: float = SERVICE_TIMEOUT):  # noqa: A001
    """Set one parameter of a running node, like ``ros2 param set``.

    Args:
        node_name: the node's full name.
        name: the parameter's name.
        value: a Python value (bool, int, float, str, or a list of one of them). The type must
            fit the declared one: 10 for an integer, 10.0 for a double.

    Returns:
        The node's rcl_interfaces/msg/SetParametersResult (``.successful``, ``.reason``).
    """
    from rclpy.parameter import Parameter

    return set_parameters(node_name, [Parameter(name, value=value).to_parameter_msg()], timeout)[0]


def as_yaml_dict(node_name: str, timeout: float = SERVICE_TIMEOUT) -> dict:
    """All parameters of a node as the dict a ``--params-file`` YAML file holds.

    ``{"/talker": {"ros__parameters": {...}}}``; dotted names become nested dicts.
    """
    from rclpy.parameter import PARAMETER_SEPARATOR_STRING, parameter_value_to_python

    full = _full_name(node_name)
    listed = names(full, timeout=timeout)
    found = values(full, listed, timeout) if listed else []
    tree: dict = {}
    for name, value in zip(listed, found, strict=True):
        *groups, leaf = name.split(PARAMETER_SEPARATOR_STRING)
        branch = tree
        for group in groups:
            branch = branch.setdefault(group, {})
        branch[leaf] = parameter_value_to_python(value)
    return {full: {"ros__parameters": tree}}


def dump(node_name: str, timeout: float = SERVICE_TIMEOUT) -> str:
    """All parameters of a node as YAML, like ``ros2 param dump`` (readable by --params-file)."""
    return yaml.dump(as_yaml_dict(node_name, timeout), default_flow_style=False)


def load(node_name: str, path, use_wildcard: bool = True, timeout: float = SERVICE_TIMEOUT) -> list:
    """Set a node's parameters from a parameter YAML file, like ``ros2 param load``.

    Args:
        node_name: the node's full name.
        path: a YAML file in the ``--params-file`` format.
        use_wildcard: also apply the file's ``/**`` section.

    Returns:
        (name, SetParametersResult) pairs, in the order they were set.
    """
    from rclpy.parameter import parameter_dict_from_yaml_file

    parameters = list(parameter_dict_from_yaml_file(str(path), use_wildcard).values())
    results = set_parameters(node_name, parameters, timeout)
    return [(parameter.name, result) for parameter, result in zip(parameters, results, strict=True)]
