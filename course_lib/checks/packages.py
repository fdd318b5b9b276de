"""The student's ROS 2 packages as the checks use them: built, run like ``ros2 run``, declared.

An assignment's work is a colcon workspace beside the notebook (``ros2_ws/src/<package>/``,
written by the notebook's ``%%writefile`` cells). The checks

- call plain functions (``average_brightness``, ``crop_pictures``) from the package's source,
  without a build (course_lib.checks.context.Context.call, with the module its spec names:
  course_lib.checks.assignments);
- start executables as ``ros2 run <package> <executable>`` would: the console script colcon
  installed in ``ros2_ws/install/<package>/lib/<package>/``, in the environment of
  ``source ros2_ws/install/setup.bash`` (:func:`run`);
- read package.xml against the imports of the package's Python files (:func:`dependency_items`).

Who builds: in a self-check, the student, with the notebook's build cell (the check says so when
``install/`` is missing); at grading, the grader (autograder.builds.workspace_build, in its sandbox), which hands
the checks its report through contract.BUILD_REPORT_ENV. When that build failed, every check that
needs it fails with the build's own error lines.
"""

from __future__ import annotations

import functools
import json
import os
import xml.etree.ElementTree as ElementTree
from pathlib import Path

from course_lib import contract
from course_lib.checks.context import StudentError, clip, scaled
from course_lib.checks.student_processes import student_env as _student_env
from course_lib.ros import package_files

#: Python modules that belong to no ROS package (a <depend> on them is not needed here). Every
#: other top-level module whose name is a ROS package (installed, or in the workspace) must be
#: declared.
_NOT_ROS = {"course_lib", "numpy", "cv2"}


def require_build(ctx) -> Path:
    """The built workspace; raises StudentError with the reason when it is not built."""
    ws = ctx.workspace_dir()
    report = os.environ.get(contract.BUILD_REPORT_ENV)
    if report:
        data = json.loads(Path(report).read_text())
        if not data["ok"]:
            raise StudentError(f"your workspace did not build, so this cannot run. {data['reason']}")
        return Path(data["workspace"])
    if not (ws / "install" / "setup.bash").is_file():
        raise StudentError(f"{contract.WORKSPACE} is not built yet: run the notebook's build cell "
                                   f"(in a terminal: cd {contract.WORKSPACE} && colcon build --symlink-install)")
    return ws


def student_env(ctx, ws: Path) -> dict:
    """The environment of the student's processes: ``source ros2_ws/install/setup.bash`` on top of
    the course's, PYTHONPATH ending with course_lib's (student_processes.student_env)."""
    from course_lib.ros import workspace

    if getattr(ctx, "_workspace_env", None) is None:
        try:
            ctx._workspace_env = workspace.workspace_environment(ws, domain_id=ctx.domain_id)
        except (FileNotFoundError, RuntimeError) as error:
            raise StudentError(str(error)) from None
    env = dict(ctx._workspace_env)
    paths = [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]
    env.update(_student_env())
    env["PYTHONPATH"] = os.pathsep.join(paths + [env["PYTHONPATH"]])
    env[contract.BUILD_REPORT_ENV] = None
    return env


def run(ctx, package: str, executable: str, *ros_args: str, tag: str = ""):
    """Start ``ros2 run <package> <executable> [ros_args]`` in the check's ROS domain, as the
    student's uid with the student's limits; stopped at the end of the check.

    Returns:
        The started course_lib.ros.processes.NodeProcess.

    Raises:
        StudentError: the workspace is not built, or has no such package or executable
            (the message lists the executables there are: an entry point missing from setup.py).
    """
    from course_lib.ros import workspace

    ws = require_build(ctx)
    try:
        command = workspace.executable_command(ws, package, executable, ros_args=ros_args)
    except FileNotFoundError as error:
        raise StudentError(f"`ros2 run {package} {executable}` cannot start: {error}") from None
    # Named after the check too: a process started under a name stops the earlier one of that
    # name (course_lib.ros.processes), and the checks of a grading run at the same time.
    return ctx.students.start(command, name=f"student-{package}-{executable}{tag}-{ctx.spec.name}", cwd=ctx.workdir,
                              domain_id=ctx.domain_id, wall_seconds=ctx.remaining() + 5, env=student_env(ctx, ws))


def wait_node(ctx, probe, proc, name: str) -> bool:
    """A precondition item: node `name` of the student's process `proc` shows in `probe`'s graph
    (ctx.wait_for_node); else a failed item that says why (the process ended, with its log, or
    no node of that name, with the names seen). True when it shows."""
    found = ctx.wait_for_node(probe, proc, name)
    if not proc.running():
        ctx.item(False, f"the process ended ({proc.describe_exit()}) before node {name} appeared:\n"
                        f"{clip(proc.log_tail(6))}")
        return False
    if not found:
        names = sorted(n for n, _ in probe.node.get_node_names_and_namespaces() if not n.startswith("autograder"))
        ctx.item(False, f"no node named {name} within {scaled(25):.0f} s (nodes seen: {names}): pass '{name}' "
                        "to super().__init__()")
        return False
    return ctx.precondition(True, f"node {name} runs")


def node_ended(ctx, proc, name: str, before: str) -> bool:
    """When the student's process `proc` has ended before its node `name` did what the check waits
    for (`before`, e.g. "offered service /x"): that is the check's cause, with the process's exit
    and log, in place of wait_node's "node runs" (a node that appears and then raises in its
    __init__ did not start). True when it has ended; nothing recorded while it runs."""
    if proc.running():
        return False
    ctx.items[:] = [item for item in ctx.items if not (item["ok"] and item["message"] == f"node {name} runs")]
    ctx.item(False, f"the process ended ({proc.describe_exit()}) before node {name} {before}:\n"
                    f"{clip(proc.log_tail(6))}")
    return True


def endpoints(ctx, module: str, class_name: str) -> dict:
    """Context.endpoints for a class of a built package (its messages need the build)."""
    ws = require_build(ctx)
    return ctx.endpoints(class_name, module=module, env=student_env(ctx, ws))


# ---- package.xml -------------------------------------------------------------------------------

def ros_packages(ctx) -> set[str]:
    """The ROS packages the code could import: installed ones (the ament index) and the workspace's."""
    prefixes = tuple(p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p)
    names = set(_installed(prefixes, tuple(_index_mtime(p) for p in prefixes)))
    src = ctx.workspace_dir() / "src"
    names.update(p.parent.name for p in src.glob("*/package.xml"))
    return names


def _index_mtime(prefix: str) -> int | None:
    """When the ament index of `prefix` last gained or lost a package (None: it has none)."""
    try:
        return os.stat(os.path.join(prefix, "share", "ament_index", "resource_index", "packages")).st_mtime_ns
    except OSError:
        return None


@functools.lru_cache(maxsize=4)
def _installed(prefixes: tuple[str, ...], mtimes: tuple) -> frozenset[str]:
    """The installed ROS packages of these AMENT_PREFIX_PATH entries (as their indexes were at
    `mtimes`): read once per process while neither changes (a pillar grading's checks look
    twice, 0.02 CPU-s each)."""
    from course_lib.ros import ament

    return frozenset(ament.packages())


def dependency_items(ctx, package: str, weight: float = 1.0) -> None:
    """One item: every ROS package the package's Python code imports is a <depend> or
    <exec_depend> of its package.xml (``rosdep`` and a full ROS install rely on it). Like every
    package item it costs `weight` when wrong and earns nothing when right (the release's
    package.xml is right already: an untouched release must score 0)."""
    folder = ctx.package_dir(package)
    try:
        have = package_files.run_dependencies(folder / "package.xml")
    except (OSError, ElementTree.ParseError) as error:
        ctx.item(False, f"{package}/package.xml cannot be read ({error}): write it with the notebook's cell",
                 weight=weight)
        return
    known = ros_packages(ctx)
    missing = {name: where for name, where in package_files.package_imports(folder).items()
               if name in known and name not in have and name not in _NOT_ROS and name != package}
    if missing:
        lines = "; ".join(f"{where} imports {name}" for name, where in sorted(missing.items()))
        tags = " ".join(f"<depend>{name}</depend>" for name in sorted(missing))
        ctx.item(False, f"{package}/package.xml does not declare what the code uses ({lines}): add {tags}",
                 weight=weight)
    else:
        ctx.item(True, f"{package}/package.xml declares every ROS package its code imports", weight=0.0)


# ---- messages ----------------------------------------------------------------------------------

def use_interfaces(ctx) -> None:
    """Make the assignment's message packages importable in this check process: at grading the
    reference interface packages the grader built (never code the student built: the check runs
    as the grader), in a self-check the student's own workspace."""
    from course_lib.ros import workspace

    report = os.environ.get(contract.BUILD_REPORT_ENV)
    try:
        if report:
            for install in json.loads(Path(report).read_text()).get("reference_underlays", []):
                workspace.use_workspace(Path(install).parent)
        else:
            workspace.use_workspace(require_build(ctx))
    except (FileNotFoundError, RuntimeError) as error:
        raise StudentError(f"the messages of your workspace cannot be loaded: {error}") from None


def message_fields(path: Path) -> list[tuple[str, str]]:
    """The (type, name) fields of a .msg file, comments, blank lines and constants left out."""
    fields = []
    for line in Path(path).read_text(errors="replace").splitlines():
        line = line.split("#", 1)[0].strip()
        parts = line.split()
        if len(parts) >= 2 and "=" not in line:
            fields.append((parts[0], parts[1]))
    return fields


def message_item(ctx, package: str, message: str, expected: list[tuple[str, str]], weight: float = 1.0) -> bool:
    """One item: the student's msg/<message>.msg of `package` has exactly the contract's fields
    (costs `weight` when wrong, earns nothing when right, as dependency_items)."""
    path = ctx.package_dir(package) / "msg" / f"{message}.msg"
    if not path.is_file():
        return ctx.item(False, f"{package}/msg/{message}.msg does not exist: write it with the notebook's cell",
                        weight=weight)
    fields = message_fields(path)
    # builtin_interfaces/Time and builtin_interfaces/msg/Time name the same type.
    found = [(kind.replace("/msg/", "/"), name) for kind, name in fields]
    wanted = ", ".join(f"{kind} {name}" for kind, name in expected)
    if found == expected:
        return ctx.item(True, f"{package}/msg/{message}.msg has the fields {wanted}", weight=0.0)
    have = ", ".join(f"{kind} {name}" for kind, name in fields) or "no fields"
    return ctx.item(False, f"{package}/msg/{message}.msg has {have}; the contract says {wanted} "
                           "(a node that uses other fields cannot talk to the grader's)", weight=weight)
