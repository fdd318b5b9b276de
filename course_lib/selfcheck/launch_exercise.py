"""The exercise of lesson 02b: a YAML launch file that starts the same nodes as the XML one,
compared without starting anything.
"""

from __future__ import annotations

from itertools import pairwise

from course_lib.selfcheck.verdicts import Verdict, _verdict

#: What ros2 launch (launch_ros) logs, and skips, for a <param from=...> that is no file.
_NOT_A_FILE = "Parameter file path is not a file: "


def _parameter_file(path, temp_dir) -> str:
    """A --params-file of a node as the launch file says it: ``$(find-pkg-share PKG)/...`` for a
    file in a package's share folder, else its path; the parameters themselves, as one line of YAML,
    for a file the launch wrote (a <param name= value=>)."""
    from pathlib import Path

    import yaml

    from course_lib.ros import ament

    path = Path(path)
    if path.is_relative_to(temp_dir):
        return "parameters " + yaml.safe_dump(yaml.safe_load(path.read_text()), default_flow_style=True).strip()
    for package, prefix in ament.packages().items():
        share = prefix / "share" / package
        if path.is_relative_to(share):
            return f"$(find-pkg-share {package})/{path.relative_to(share).as_posix()}"
    return str(path)


def _launch_nodes(path) -> tuple[list[dict], list[str]]:
    """What each node of a launch file would start with, without starting it; and the parameter
    files it names that are no files (ros2 launch warns and skips them)."""
    from pathlib import Path

    from course_lib.launch.actions import run_launch_file

    context = run_launch_file(path)
    try:
        nodes = []
        for node in context.processes:
            command = list(node.command)
            ros_args = command[command.index("--ros-args") + 1:] if "--ros-args" in command else []
            remaps, params = [], []
            for flag, value in pairwise(ros_args):
                if flag == "-r" and not value.startswith("__"):
                    remaps.append(value)
                elif flag == "--params-file":
                    params.append(_parameter_file(value, context.temp_dir()))
            nodes.append({"executable": "/".join(Path(command[0]).parts[-2:]), "output": node.output,
                          "name": node.node_name, "namespace": node.namespace, "remaps": sorted(remaps),
                          "parameter files": params})
        missing = [message[len(_NOT_A_FILE):] for _, message in context.warnings if message.startswith(_NOT_A_FILE)]
        return nodes, missing
    finally:
        context.remove_files()


def _listed(values) -> str:
    return ", ".join(map(str, values)) if values else "none"


def task_launch_yaml(yaml_file, xml_file) -> Verdict:
    """Lesson 02b: a YAML launch file starts the same nodes as the XML one (command lines, output)."""
    from course_lib.launch import LaunchFileError

    hint = ("Write the YAML file as a list under `launch:`, one `- node:` per <node> tag, with the keys pkg, "
            "exec, output, and lists `param:` and `remap:`.")
    try:
        wanted, _ = _launch_nodes(xml_file)
    except (LaunchFileError, LookupError, OSError) as error:
        return _verdict(False, f"The XML launch file does not run ({error}); build the workspace and call "
                               "workspace.use_workspace(WS) first.")
    try:
        given, missing = _launch_nodes(yaml_file)
    except (LaunchFileError, LookupError, OSError) as error:
        return _verdict(False, f"Your YAML launch file cannot run: {error}")
    if not given:
        return _verdict(False, "Not done yet: your launch file starts no node. " + hint)
    by_package = sorted({f for node in wanted for f in node["parameter files"] if f.startswith("$(find-pkg-share")})
    why = ("$(find-pkg-share) finds the installed file wherever ros2 launch runs; a relative path is relative to "
           "the folder it runs in, not to the launch file's")
    if missing:
        return _verdict(False, f"Your launch file names the parameter file {missing[0]}, which is no file (ros2 "
                               "launch warns and starts the node without it)."
                               + (f" The XML file names {by_package[0]}: {why}." if by_package else ""))
    if len(given) != len(wanted):
        return _verdict(False, f"Your launch file starts {len(given)} node(s); the XML file starts {len(wanted)}.")
    for index, (mine, theirs) in enumerate(zip(given, wanted, strict=True), start=1):
        if mine["executable"] != theirs["executable"]:
            return _verdict(False, f"Node {index} runs {mine['executable']}; the XML file's node {index} runs "
                                   f"{theirs['executable']} (pkg and exec, in the same order).")
        for key in ("output", "name", "namespace", "remaps", "parameter files"):
            if mine[key] != theirs[key]:
                if isinstance(mine[key], list):
                    said = f"{key} are {_listed(mine[key])}, the XML file gives {_listed(theirs[key])}"
                else:
                    said = f"{key} is {mine[key]!r}, the XML file gives {theirs[key]!r}"
                if key == "parameter files" and any(f in by_package for f in theirs[key]):
                    said += f": {why}"
                return _verdict(False, f"Node {index} ({theirs['executable']}): {said}.")
    return _verdict(True, f"Your YAML launch file starts the same {len(given)} nodes as the XML one.")
