"""What the tags of a launch file do when the launch runs, in order, like ros2/launch's actions.

Running a description visits its actions one after the other in a LaunchContext: ``<arg>`` and
``<let>`` set launch configurations (the values ``$(var ...)`` reads), ``<set_env>`` changes
the environment of the nodes started after it, ``<group>`` (scoped by default) undoes both at
its end, ``<push_ros_namespace>`` prefixes the namespace of later nodes (it is a launch
configuration too, so a scoped group undoes it), ``<include>`` runs another launch file in the
same scope (as in ROS 2 Jazzy: what it sets stays set), and ``<node>`` becomes a ProcessToStart:
the command line launch_ros would run.
"""

from __future__ import annotations

import os
import re
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from course_lib.launch import parameters, substitutions
from course_lib.launch.entities import LaunchFileError

_NAME_TOKEN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*$")


class LaunchContext:
    """The state a launch file runs in.

    Attributes:
        configurations: launch configurations by name (arguments, ``<let>``, "ros_namespace").
        environment: the environment for the nodes (a copy; os.environ is never changed).
        initial_environment: the environment the launch started with (a group that does not
            forward starts from it).
        current_file: the launch file whose actions run now (``$(dirname)``).
        processes: the processes to start (ProcessToStart), in order.
        warnings: (logger, message) pairs the real tool logs as warnings.
    """

    def __init__(self, configurations: dict | None = None, environment: dict | None = None,
                 current_file: Path | None = None):
        self.configurations = dict(configurations or {})
        self.environment = dict(os.environ if environment is None else environment)
        self.initial_environment = dict(self.environment)
        self.current_file = current_file or Path.cwd() / "launch"
        self.processes: list[ProcessToStart] = []
        self.warnings: list[tuple[str, str]] = []
        self._scopes: list[tuple[dict, dict]] = []
        self._temp_dir: Path | None = None
        self._node_names: dict[str, int] = {}

    def push(self) -> None:
        self._scopes.append((dict(self.configurations), dict(self.environment)))

    def pop(self) -> None:
        self.configurations, self.environment = self._scopes.pop()

    def temp_dir(self) -> Path:
        """A folder for the parameter files of this launch (see remove_files)."""
        if self._temp_dir is None:
            self._temp_dir = Path(tempfile.mkdtemp(prefix="course_lib-launch-"))
        return self._temp_dir

    def remove_files(self) -> None:
        """Remove the parameter files written for the nodes (once they have read them)."""
        if self._temp_dir is not None:
            shutil.rmtree(self._temp_dir, ignore_errors=True)
            self._temp_dir = None


@dataclass
class ProcessToStart:
    """A process as the launch will start it (a node, or any other program).

    Attributes:
        command: the full command line (executable, arguments; a node's ``--ros-args ...``).
        environment: its complete environment.
        label: the process name the launch prints (``talker`` becomes ``[talker-1]``).
        output: "screen", "log" or "both".
        node_name, namespace: what the launch sets (None where the node's own code decides, and
            for a process that is no node).
        file, line: where its tag is.
        cwd: the folder it starts in (None: the launch's own).
    """

    command: list[str]
    environment: dict
    label: str
    output: str
    node_name: str | None
    namespace: str | None
    file: Path
    line: int
    cwd: str | None = None


# --- actions ----------------------------------------------------------------------------------

@dataclass
class Action:
    """A tag that does something when the launch runs; ``if``/``unless`` make it conditional."""

    file: Path
    line: int
    condition: tuple[str, list] | None = field(default=None, kw_only=True)

    def error(self, message: str) -> LaunchFileError:
        return LaunchFileError(message, self.file, self.line)

    def run(self, context: LaunchContext) -> None:
        if self.condition is None or self._condition_holds(context):
            self.execute(context)

    def _condition_holds(self, context: LaunchContext) -> bool:
        kind, parts = self.condition
        text = substitutions.perform(parts, context).strip().lower()
        if text not in ("true", "1", "false", "0"):
            raise self.error(f"{kind}=\"{substitutions.describe(parts)}\" is {text!r}; a condition must be "
                             "true, false, 1 or 0")
        return (text in ("true", "1")) == (kind == "if")

    def execute(self, context: LaunchContext) -> None:
        raise NotImplementedError


@dataclass
class DeclareArgument(Action):
    """``<arg name= default= description=>`` with optional ``<choice value=/>`` tags: a launch
    argument, set from ``name:=value``, whose value must be one of the choices when there are any.

    Attributes:
        description: as launch's DeclareLaunchArgument words it: the one given, or "no description
            given"; with choices, "One of: [...]", or the one given and ". Valid choices are: [...]".
    """

    name: str
    default: list | None
    description: str | None  # as given; __post_init__ makes it launch's
    choices: list[str] | None = None

    def __post_init__(self):
        given = self.description
        if self.choices is None:
            self.description = "no description given" if given is None else given
        elif given is None:
            self.description = f"One of: {self.choices}"
        else:
            self.description = f"{given if given.endswith('.') else given + '.'} Valid choices are: {self.choices}"

    def execute(self, context: LaunchContext) -> None:
        if self.name not in context.configurations:
            if self.default is None:
                raise self.error(f'Required launch argument "{self.name}" was not provided: pass '
                                 f'{self.name}:=VALUE')
            context.configurations[self.name] = substitutions.perform(self.default, context)
        value = context.configurations[self.name]
        if self.choices is not None and value not in self.choices:  # launch's words
            raise self.error(f'Argument "{self.name}" provided value "{value}" is not valid. Valid options '
                             f'are: {self.choices}')


@dataclass
class SetLaunchConfiguration(Action):
    """``<let name= value=/>``."""

    name: list
    value: list

    def execute(self, context: LaunchContext) -> None:
        context.configurations[substitutions.perform(self.name, context)] = substitutions.perform(self.value, context)


@dataclass
class SetEnvironmentVariable(Action):
    """``<set_env name= value=/>``: for the nodes started after it (within its scope)."""

    name: list
    value: list

    def execute(self, context: LaunchContext) -> None:
        context.environment[substitutions.perform(self.name, context)] = substitutions.perform(self.value, context)


@dataclass
class PushRosNamespace(Action):
    """``<push_ros_namespace namespace=/>``: later nodes' relative namespaces go below it."""

    namespace: list

    def execute(self, context: LaunchContext) -> None:
        pushed = substitutions.perform(self.namespace, context)
        namespace = absolute_namespace(prefix_namespace(context.configurations.get("ros_namespace"), pushed))
        problem = namespace_problem(namespace)
        if problem:
            raise self.error(f"the namespace '{namespace}' (pushing '{pushed}') is invalid: {problem}")
        context.configurations["ros_namespace"] = namespace


@dataclass
class Group(Action):
    """``<group scoped= forwarding=>`` with ``<keep name= value=/>`` tags, as launch's GroupAction.

    Scoped (the default), what its actions set ends with the group. Not forwarding (scoped only),
    the group starts from no launch configurations (so no pushed namespace either) and the
    environment the launch started with, except the kept configurations, whose values are
    performed before that. Forwarding, or not scoped, the kept ones are simply set.
    """

    actions: list
    scoped: bool = True
    forwarding: bool = True
    keep: list = field(default_factory=list)  # [(name parts, value parts)]

    def execute(self, context: LaunchContext) -> None:
        if self.scoped:
            context.push()
        if self.scoped and not self.forwarding:
            kept = {substitutions.perform(name, context): substitutions.perform(value, context)
                    for name, value in self.keep}
            context.configurations = kept
            context.environment = dict(context.initial_environment)
        else:
            for name, value in self.keep:
                context.configurations[substitutions.perform(name, context)] = substitutions.perform(value, context)
        for action in self.actions:
            action.run(context)
        if self.scoped:
            context.pop()


@dataclass
class IncludeLaunchDescription(Action):
    """``<include file=...><arg name= value=/></include>``: another launch file, run here.

    Attributes:
        from_command_line: True for the file ``ros2 launch`` runs (its args are name:=value).
    """

    path: list
    arguments: list  # [(name parts, value parts)]
    from_command_line: bool = False

    def execute(self, context: LaunchContext) -> None:
        from course_lib.launch.parser import load_description  # the parser builds these actions

        path = Path(os.path.abspath(substitutions.perform(self.path, context)))
        actions = load_description(path)
        given = [substitutions.perform(name, context) for name, _ in self.arguments]
        for argument, passed_below, conditional in declared_arguments(actions, context, path):
            if argument.default is None and not conditional and argument.name not in given + passed_below:
                raise LaunchFileError(
                    f"Included launch description missing required argument '{argument.name}' "
                    f"(description: '{argument.description}'), given: "
                    f"[{', '.join(given)}]; " + (f"pass it as {argument.name}:=VALUE" if self.from_command_line
                                                 else f"add <arg name=\"{argument.name}\" value=\"...\"/> to the "
                                                 f"<include> at {self.file}:{self.line}"),
                    argument.file, argument.line)
        for name, value in self.arguments:
            context.configurations[substitutions.perform(name, context)] = substitutions.perform(value, context)
        including, context.current_file = context.current_file, path
        try:
            for action in actions:
                action.run(context)
        finally:
            context.current_file = including


@dataclass
class Node(Action):
    """``<node pkg= exec= name= namespace= output= args= ros_args=>`` with param, remap, env."""

    package: list | None
    executable: list
    name: list | None = None
    namespace: list | None = None
    exec_name: list | None = None
    output: list | None = None
    arguments: list = field(default_factory=list)  # [parts] per command-line argument
    ros_arguments: list | None = None
    parameters: list = field(default_factory=list)  # ParamGroup | ParamFile
    remappings: list = field(default_factory=list)  # [(from parts, to parts)]
    environment: list = field(default_factory=list)  # [(name parts, value parts)]

    def execute(self, context: LaunchContext) -> None:
        from course_lib import ament

        def text(parts):
            return substitutions.perform(parts, context)

        executable = text(self.executable)
        if self.package is not None:
            try:
                executable = str(ament.executable(text(self.package), executable))
            except LookupError as error:
                raise self.error(str(error)) from None
        command = [executable] + [text(argument) for argument in self.arguments]
        if self.ros_arguments is not None:
            command += ["--ros-args"] + [text(argument) for argument in self.ros_arguments]
        command.append("--ros-args")
        name = None if self.name is None else text(self.name)
        if name is not None:
            if not _NAME_TOKEN.match(name):
                raise self.error(f"the node name '{name}' is invalid: use letters, digits and underscores, "
                                 "not starting with a digit")
            command += ["-r", f"__node:={name}"]
        namespace = absolute_namespace(prefix_namespace(
            context.configurations.get("ros_namespace"), None if self.namespace is None else text(self.namespace)))
        if namespace is not None:
            problem = namespace_problem(namespace)
            if problem:
                raise self.error(f"the namespace '{namespace}' of this node is invalid: {problem}")
            command += ["-r", f"__ns:={namespace}"]
        full_name = f"{namespace.rstrip('/')}/{name}" if name is not None and namespace is not None else None
        for parameter in self.parameters:
            if isinstance(parameter, parameters.ParamFile):
                path = parameters.resolve_file(parameter, context, context.temp_dir())
                if path is None:
                    context.warnings.append(("launch_ros.actions.node", "Parameter file path is not a file: "
                                             f"{os.path.abspath(text(parameter.path))}"))
                    continue
            else:
                values = parameters.evaluate_group(parameter, context)
                path = parameters.write_params_file(values, full_name or "/**", context.temp_dir())
            command += ["--params-file", str(path)]
        for source, target in self.remappings:
            command += ["-r", f"{text(source)}:={text(target)}"]
        environment = dict(context.environment)
        environment.update({text(key): text(value) for key, value in self.environment})
        output = "log" if self.output is None else text(self.output)
        if output not in ("screen", "log", "both"):
            raise self.error(f"output=\"{output}\" is not supported here; use screen, log or both")
        label = os.path.basename(executable) if self.exec_name is None else text(self.exec_name)
        if full_name is not None:
            count = context._node_names[full_name] = context._node_names.get(full_name, 0) + 1
            if count > 1:
                context.warnings.append((label, f"there are now at least {count} nodes with the name {full_name} "
                                                "created within this launch context"))
        context.processes.append(ProcessToStart(command, environment, label, output, name, namespace, self.file, self.line))


def run_launch_file(path, arguments: dict | None = None, environment: dict | None = None) -> LaunchContext:
    """Run a launch file's actions, as ``ros2 launch`` does before its processes start.

    Args:
        path: the launch file.
        arguments: {name: value} as given on the command line (``name:=value``).
        environment: the environment to start from (os.environ when None; never changed).

    Returns:
        The context: ``nodes`` to start, ``configurations``, ``warnings``.

    Raises:
        LaunchFileError: the file cannot run as written (the message has its line).
    """
    path = Path(os.path.abspath(path))
    context = LaunchContext(environment=environment, current_file=path)
    given = [([name], [value]) for name, value in (arguments or {}).items()]
    try:
        IncludeLaunchDescription(path=[str(path)], arguments=given, file=path, line=0,
                                 from_command_line=True).run(context)
    except BaseException:
        context.remove_files()
        raise
    return context


# --- namespaces (launch_ros's rules) -----------------------------------------------------------

def prefix_namespace(base: str | None, namespace: str | None) -> str | None:
    """`namespace` below `base` unless it is absolute; None when both are None."""
    if base is None and namespace is None:
        return None
    if namespace is None:
        combined = base
    elif not base or namespace.startswith("/"):
        combined = namespace
    else:
        combined = ("" if base == "/" else base) + "/" + namespace
    return combined if combined == "/" else combined.rstrip("/")


def absolute_namespace(namespace: str | None) -> str | None:
    if namespace is None or namespace.startswith("/"):
        return namespace
    return "/" + namespace


def namespace_problem(namespace: str) -> str | None:
    """Why a (fully qualified) namespace is invalid, or None."""
    if namespace == "/":
        return None
    tokens = namespace[1:].split("/")
    bad = [token for token in tokens if not _NAME_TOKEN.match(token)]
    if bad:
        return (f"'{bad[0]}' is not a name: namespaces are names (letters, digits, underscores, "
                "not starting with a digit) separated by single '/'")
    return None


# --- reading a description without running it --------------------------------------------------

def declared_arguments(actions: list, context: LaunchContext | None, file: Path, passed: tuple = ()):
    """The ``<arg>`` declarations of a description, first of each name, as (DeclareArgument,
    names passed on by the includes in between, conditional). An argument is conditional when
    it or a tag around it has ``if``/``unless``. Includes are followed when their file can be
    found before the launch runs (launch does the same)."""
    found, seen = [], set()

    def visit(actions, current_file, passed, conditional):
        for action in actions:
            if isinstance(action, DeclareArgument):
                if action.name not in seen:
                    seen.add(action.name)
                    found.append((action, list(passed), conditional or action.condition is not None))
            elif isinstance(action, Group):
                visit(action.actions, current_file, passed, conditional or action.condition is not None)
            elif isinstance(action, IncludeLaunchDescription):
                from course_lib.launch.parser import load_description

                probe = LaunchContext(current_file=current_file,
                                      environment=None if context is None else context.environment)
                try:
                    path = Path(os.path.abspath(substitutions.perform(action.path, probe)))
                    names = [substitutions.perform(name, probe) for name, _ in action.arguments]
                    included = load_description(path)
                except LaunchFileError:
                    continue
                visit(included, path, (*passed, *names), conditional or action.condition is not None)

    visit(actions, file, passed, False)
    return found
