"""What the tags of a launch file do when the launch runs, in order, like ros2/launch's actions.

Running a description visits its actions one after the other in a LaunchContext: ``<arg>`` and
``<let>`` set launch configurations (the values ``$(var ...)`` reads), ``<set_env>`` changes
the environment of the nodes started after it, ``<group>`` (scoped by default) undoes both at
its end, ``<push_ros_namespace>`` prefixes the namespace of later nodes (it is a launch
configuration too, so a scoped group undoes it), ``<include>`` runs another launch file in the
same scope (as in ROS 2 Jazzy: what it sets stays set). ``<node>`` and ``<executable>``
(executables.py) become the processes to start.
"""

from __future__ import annotations

import os
import re
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from course_lib.launch import substitutions
from course_lib.launch.entities import LaunchFileError

#: A name token of ROS names (node names, namespace parts).
NAME_TOKEN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*$")

#: The function that reads a launch file into its actions (``<include>`` runs another file). The
#: parser builds these actions, so this module does not import it: parser.py registers its
#: load_description here (reads_launch_files) when it is imported, which course_lib.launch does.
#: ros2/launch breaks the same cycle the other way round: actions register with the parser.
_loader = None


def reads_launch_files(load):
    """Register `load(path) -> [actions]`, the parser's reading of a launch file; return it."""
    global _loader
    _loader = load
    return load


def load_description(path: Path) -> list:
    """The actions of a launch file, read by the registered parser (see reads_launch_files)."""
    return _loader(path)


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
        self.processes: list = []  # executables.ProcessToStart
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
    bad = [token for token in tokens if not NAME_TOKEN.match(token)]
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
