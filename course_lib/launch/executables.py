"""What a launch file starts as processes: ``<executable>`` (any program) and ``<node>``.

Both end as a ProcessToStart, the way launch's ExecuteProcess prepares a process: the command
line with its substitutions performed and ``launch-prefix`` before it (the tag's own, else the
``launch-prefix`` launch configuration where ``launch-prefix-filter`` matches the program's
name), the process name the launch prints (the tag's name, else the first word's base name;
``[name-N]``), its output (screen, log or both), environment (with ``<env>``) and folder
(``cwd``). A node's command line is launch_ros's: the executable from the ament index, then
``--ros-args`` with its name, namespace, parameter files and remappings.
"""

from __future__ import annotations

import os
import re
import shlex
from dataclasses import dataclass, field
from pathlib import Path

from course_lib.launch import parameters, substitutions
from course_lib.launch.actions import (
    NAME_TOKEN,
    Action,
    LaunchContext,
    absolute_namespace,
    namespace_problem,
    prefix_namespace,
)

#: The outputs a process may have here (launch also has own_log and per-stream forms).
OUTPUTS = ("screen", "log", "both")


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


def process_to_start(action: Action, context: LaunchContext, command: list[str], *, label: list | None,
                     output: list | None, prefix: list | None, environment: list, cwd: list | None,
                     node_name: str | None = None, namespace: str | None = None) -> ProcessToStart:
    """The process of an <executable> or <node>, as launch's Executable.prepare makes it.

    Args:
        command: the program and its arguments, substitutions performed.
        label, output, prefix, cwd: the tag's parts (None where it does not give them).
        environment: its <env> tags, [(name parts, value parts)].

    Raises:
        LaunchFileError: an output this launch does not show.
    """
    def text(parts):
        return substitutions.perform(parts, context)

    if prefix is not None:
        command = shlex.split(text(prefix)) + command
    else:  # the launch configurations `ros2 launch --launch-prefix` sets, also settable as arguments
        prefix_filter = context.configurations.get("launch-prefix-filter", "")
        if re.match(prefix_filter, os.path.basename(command[0])) is not None:
            command = shlex.split(context.configurations.get("launch-prefix", "")) + command
    chosen = "log" if output is None else text(output)
    if chosen not in OUTPUTS:
        raise action.error(f"output=\"{chosen}\" is not supported here; use screen, log or both")
    variables = dict(context.environment)
    variables.update({text(key): text(value) for key, value in environment})
    return ProcessToStart(command, variables, os.path.basename(command[0]) if label is None else text(label),
                          chosen, node_name, namespace, action.file, action.line,
                          cwd=None if cwd is None else text(cwd))


@dataclass
class ExecuteProcess(Action):
    """``<executable cmd= cwd= name= output= launch-prefix=>`` with ``<env name= value=/>``: a
    program that is no node (launch's ExecuteProcess)."""

    command: list  # [parts] per command-line argument
    name: list | None = None
    cwd: list | None = None
    output: list | None = None
    prefix: list | None = None
    environment: list = field(default_factory=list)  # [(name parts, value parts)]

    def execute(self, context: LaunchContext) -> None:
        command = [substitutions.perform(argument, context) for argument in self.command]
        if not command or not command[0]:
            raise self.error("<executable> cmd is empty: give the program to run and its arguments")
        context.processes.append(process_to_start(self, context, command, label=self.name, output=self.output,
                                                  prefix=self.prefix, environment=self.environment, cwd=self.cwd))


@dataclass
class Node(Action):
    """``<node pkg= exec= name= namespace= output= args= ros_args= cwd= launch-prefix=>`` with
    param, remap, env: the command line launch_ros runs."""

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
    cwd: list | None = None
    prefix: list | None = None

    def execute(self, context: LaunchContext) -> None:
        from course_lib.ros import ament

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
            if not NAME_TOKEN.match(name):
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
        to_start = process_to_start(self, context, command, label=self.exec_name, output=self.output,
                                    prefix=self.prefix, environment=self.environment, cwd=self.cwd,
                                    node_name=name, namespace=namespace)
        if full_name is not None:
            count = context._node_names[full_name] = context._node_names.get(full_name, 0) + 1
            if count > 1:
                context.warnings.append((to_start.label, f"there are now at least {count} nodes with the name "
                                                         f"{full_name} created within this launch context"))
        context.processes.append(to_start)
