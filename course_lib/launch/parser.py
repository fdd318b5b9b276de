"""Turn the entities of an XML or YAML launch file into actions, one parse function per tag.

Both formats go through the same functions (as in ros2/launch, where each action parses a
front-end-neutral Entity). Every attribute and nested tag a function does not read is an error
naming the file, the line and what the tag supports; nothing is silently ignored.
"""

from __future__ import annotations

import shlex
from pathlib import Path

from course_lib.launch import entities, parameters, substitutions
from course_lib.launch.actions import (
    DeclareArgument,
    Group,
    IncludeLaunchDescription,
    PushRosNamespace,
    SetEnvironmentVariable,
    SetLaunchConfiguration,
    reads_launch_files,
)
from course_lib.launch.entities import Entity, did_you_mean
from course_lib.launch.executables import ExecuteProcess, Node

#: Tags of the full ROS 2 launch that this one does not run.
NOT_SUPPORTED = ("timer", "log", "shutdown", "append_env", "unset_env", "reset", "reset_env",
                 "node_container", "load_composable_node", "set_parameter", "set_parameters_from_file",
                 "set_remap", "set_use_sim_time", "ros_timer", "set_ros_log_dir", "lifecycle_node")

_CONDITION = "if, unless"

#: The attributes and nested tags the full ROS 2 launch (Jazzy's launch and launch_ros parse
#: methods) reads on each tag this one runs: one outside these is "Unexpected" there too.
_ACTION = {"if", "unless"}
_EXECUTE = {"cmd", "cwd", "name", "launch-prefix", "output", "sigterm_timeout", "sigkill_timeout", "respawn",
            "respawn_delay", "respawn_max_retries", "shell", "emulate_tty", "on_exit", "env"}
KNOWN = {
    "launch": {"version"},
    "arg": _ACTION | {"name", "default", "description", "choice"},
    "let": _ACTION | {"name", "value"},
    "set_env": _ACTION | {"name", "value"},
    "push_ros_namespace": _ACTION | {"namespace"},
    "push-ros-namespace": _ACTION | {"namespace"},
    "group": _ACTION | {"scoped", "forwarding", "keep"},
    "include": _ACTION | {"file", "arg"},
    "executable": _ACTION | _EXECUTE,
    "node": _ACTION | _EXECUTE | {"pkg", "exec", "namespace", "exec_name", "args", "ros_args", "param", "remap"},
    "param": {"name", "value", "from", "allow_substs", "value-sep", "type", "param"},
    "remap": {"from", "to"},
    "env": {"name", "value"},
    "include/arg": {"name", "value"},
    "arg/choice": {"value"},
    "group/keep": {"name", "value"},
}


@reads_launch_files
def load_description(path) -> list:
    """The actions of a launch file (XML or YAML); what ``<include>`` reads (actions.load_description).

    Raises:
        LaunchFileError: the file cannot be read, or uses what is not supported (with its line).
    """
    root = entities.load(Path(path))
    if root.kind != "launch":
        raise root.error(f"the root tag must be <launch>, not <{root.kind}>")
    actions = [parse_action(child) for child in root.children()]
    root.check_all_read("its tags as children", KNOWN["launch"])
    return actions


def parse_action(entity: Entity):
    """The action of one tag (``<node>``, ``<arg>``, ...)."""
    parse = _ACTIONS.get(entity.kind)
    if parse is None and entity.kind not in NOT_SUPPORTED:  # launch's frontend/expose.py's words
        raise entity.error(f"Unrecognized entity of the type: {entity.kind}{did_you_mean(entity.kind, _ACTIONS)}")
    if parse is None:
        raise entity.error(f"<{entity.kind}> is not supported here (a full ROS 2 install has it); supported tags: "
                           f"{', '.join(_SUPPORTED_TAGS)}")
    action, supported = parse(entity)
    entity.check_all_read(supported, KNOWN.get(entity.kind, frozenset()))
    return action


def _text(entity: Entity, name: str, *, required: bool = False) -> list | None:
    """An attribute parsed into text and substitutions (None when absent)."""
    value = entity.get(name, required=required)
    if value is None:
        return None
    if not isinstance(value, str):
        raise entity.error(f"<{entity.kind}> attribute '{name}' must be text; in YAML quote it: "
                           f"{name}: \"{value}\"", name)
    return substitutions.parse(value, entity.file, entity.line)


def _condition(entity: Entity) -> tuple[str, list] | None:
    if entity.has("if") and entity.has("unless"):
        raise entity.error(f"<{entity.kind}> has both if and unless; use one of them")
    for kind in ("if", "unless"):
        if entity.has(kind):
            return kind, _text(entity, kind)
    return None


def _where(entity: Entity) -> dict:
    return {"file": entity.file, "line": entity.line, "condition": _condition(entity)}


# --- one function per tag: (action, what the tag supports) ---------------------------------------

def _arg(entity: Entity):
    raw_name = entity.get("name", required=True)
    if not isinstance(raw_name, str):
        raise entity.error("<arg> name must be text", "name")
    description = entity.get("description")
    choices = None
    if entity.nested("choice"):
        choices = []
        for tag in entity.nested("choice"):
            value = tag.get("value", required=True)
            if not isinstance(value, str):  # launch_yaml's words
                raise tag.error(f"Attribute 'value' of Entity 'choice' expected to be of type '{str}', got "
                                f"'{type(value)}'", "value")
            choices.append(substitutions.unescape(value))
            tag.check_all_read("value", KNOWN["arg/choice"])
    return (DeclareArgument(name=substitutions.unescape(raw_name), default=_text(entity, "default"),
                            description=None if description is None else substitutions.unescape(str(description)),
                            choices=choices, **_where(entity)),
            f"name, default, description, {_CONDITION}, nested <choice value=>")


def _let(entity: Entity):
    return (SetLaunchConfiguration(name=_text(entity, "name", required=True),
                                   value=_text(entity, "value", required=True), **_where(entity)),
            f"name, value, {_CONDITION}")


def _set_env(entity: Entity):
    return (SetEnvironmentVariable(name=_text(entity, "name", required=True),
                                   value=_text(entity, "value", required=True), **_where(entity)),
            f"name, value, {_CONDITION}")


def _push_ros_namespace(entity: Entity):
    return (PushRosNamespace(namespace=_text(entity, "namespace", required=True), **_where(entity)),
            f"namespace, {_CONDITION}")


def _group(entity: Entity):
    scoped, forwarding = entity.get_bool("scoped"), entity.get_bool("forwarding")
    where = _where(entity)
    keep = _pairs(entity, "keep", "name", "value")
    actions = [parse_action(child) for child in entity.children() if child.kind != "keep"]
    return (Group(actions=actions, scoped=True if scoped is None else scoped,
                  forwarding=True if forwarding is None else forwarding, keep=keep, **where),
            f"scoped, forwarding, {_CONDITION}, nested <keep name= value=>, and tags inside it")


def _pairs(entity: Entity, kind: str, first: str, second: str) -> list[tuple[list, list]]:
    """The nested tags of one kind that hold two attributes (``<remap from= to=/>``), in order."""
    pairs = []
    for tag in entity.nested(kind):
        pairs.append((_text(tag, first, required=True), _text(tag, second, required=True)))
        tag.check_all_read(f"{first}, {second}", KNOWN.get(f"{entity.kind}/{kind}", KNOWN.get(kind, frozenset())))
    return pairs


def _include(entity: Entity):
    return (IncludeLaunchDescription(path=_text(entity, "file", required=True),
                                     arguments=_pairs(entity, "arg", "name", "value"), **_where(entity)),
            f"file, {_CONDITION}, nested <arg name= value=>")


def _process(entity: Entity) -> dict:
    """What <executable> and <node> share (launch's ExecuteProcess.parse)."""
    return {"cwd": _text(entity, "cwd"), "output": _text(entity, "output"), "prefix": _text(entity, "launch-prefix"),
            "environment": _pairs(entity, "env", "name", "value"), **_where(entity)}


_PROCESS = f"cwd, output, launch-prefix, {_CONDITION}, nested <env>"


def _executable(entity: Entity):
    executable = ExecuteProcess(command=split_command_line(_text(entity, "cmd", required=True)),
                                name=_text(entity, "name"), **_process(entity))
    return executable, f"cmd, name, {_PROCESS}"


def _node(entity: Entity):
    arguments = _text(entity, "args")
    ros_arguments = _text(entity, "ros_args")
    node = Node(package=_text(entity, "pkg"), executable=_text(entity, "exec", required=True),
                name=_text(entity, "name"), namespace=_text(entity, "namespace"),
                exec_name=_text(entity, "exec_name"),
                arguments=[] if arguments is None else split_command_line(arguments),
                ros_arguments=None if ros_arguments is None else split_command_line(ros_arguments),
                parameters=_parameters(entity.nested("param")),
                remappings=_pairs(entity, "remap", "from", "to"), **_process(entity))
    return node, f"pkg, exec, name, namespace, exec_name, args, ros_args, {_PROCESS}, nested <param>, <remap>"


_ACTIONS = {"arg": _arg, "let": _let, "set_env": _set_env, "push_ros_namespace": _push_ros_namespace,
            "push-ros-namespace": _push_ros_namespace, "group": _group, "include": _include, "node": _node,
            "executable": _executable}
_SUPPORTED_TAGS = ("node (with param, remap, env)", "executable (with env)", "arg (with choice)", "let",
                   "include (with arg)", "group (with keep)", "push_ros_namespace", "set_env")


# --- parameters -------------------------------------------------------------------------------

def _parameters(tags: list[Entity]) -> list:
    """ParamFile / ParamGroup per ``<param>`` tag of a node, in order (launch_ros's rules)."""
    result = []
    for tag in tags:
        source, name = tag.get("from"), tag.get("name")
        if source is not None and name is not None:
            raise tag.error("<param> has both name and from; use name= with value= (or nested <param> "
                            "tags), or from= a parameter file")
        if source is not None:
            allow = tag.get_bool("allow_substs")
            result.append(parameters.ParamFile(_text(tag, "from"), bool(allow), tag.file, tag.line))
            tag.check_all_read("from, allow_substs (or name with value or nested <param> tags)", KNOWN["param"])
        elif name is not None:
            if tag.has("allow_substs"):
                raise tag.error("<param> allow_substs goes with from=, not with name=", "allow_substs")
            result.append(parameters.ParamGroup([_parameter(tag)], tag.file, tag.line))
        else:
            raise tag.error("<param> needs name= (with value= or nested <param> tags) or from= a "
                            "parameter file")
    return result


def _parameter(tag: Entity):
    """(name parts, value or nested ParamGroup) of a ``<param name=...>``."""
    name = _text(tag, "name", required=True)
    nested = tag.nested("param")
    if tag.has("value") and nested:
        raise tag.error("<param> has both value= and nested <param> tags; use one")
    if tag.has("type") and nested:  # launch_ros's words
        raise tag.error("nested parameters and type attributes are mutually exclusive", "type")
    if tag.has("value"):
        value = parameters.value_of(tag)
    elif nested:
        value = parameters.ParamGroup([_parameter(inner) for inner in nested], tag.file, tag.line)
    else:
        raise tag.error("<param> needs value= or nested <param> tags")
    tag.check_all_read("name, value, value-sep, type, nested <param>", KNOWN["param"])
    return name, value


# --- command lines ----------------------------------------------------------------------------

def split_command_line(parts: list) -> list[list]:
    """Split ``args="..."`` into arguments like launch does: the text between substitutions is
    split as a shell would (quotes group words); a substitution joins the text it touches."""
    result, argument = [], []
    for part in parts:
        if not isinstance(part, str):
            argument.append(part)
            continue
        tokens = shlex.split(part)
        if not tokens:  # spaces only: they separate what is around them
            if argument:
                result.append(argument)
            argument = []
            continue
        if part[0].isspace() and argument:
            result.append(argument)
            argument = []
        argument.append(tokens[0])
        if len(tokens) > 1:
            result.append(argument)
            result.extend([token] for token in tokens[1:-1])
            argument = [tokens[-1]]
        if part[-1].isspace():
            result.append(argument)
            argument = []
    if argument:
        result.append(argument)
    return result


