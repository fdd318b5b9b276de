"""Use a built ROS 2 workspace without ros2cli: source it, and run its nodes.

On the pip install of the course there is no ``ros2`` command, so this module does what
``source install/setup.bash`` and ``ros2 run`` do; :mod:`course_lib.ros.pkg_create` does what
``ros2 pkg create`` does and :mod:`course_lib.ros.colcon` runs the real ``colcon build``::

    from course_lib import colcon, pkg_create, workspace
    pkg_create.create_package("ws", "my_nodes", dependencies=["rclpy"], node_name="talker")
    colcon.build("ws")                                      # the real colcon build
    node = workspace.run("ws", "my_nodes", "talker")        # like `ros2 run my_nodes talker`
    workspace.use_workspace("ws")                           # import ws messages in this kernel

The packages have the standard layout, so the same folders build and run unchanged with
``colcon build`` and ``ros2 run`` on a full ROS 2 install. In a terminal::

    python -m course_lib build ws              # colcon build with the environment set up
    source .venv/bin/activate && source ws/install/setup.bash
"""

from __future__ import annotations

import ctypes
import importlib
import os
import shutil
import subprocess
import sys
from pathlib import Path

from course_lib.ros import rosenv

_PATH_VARIABLES = ("AMENT_PREFIX_PATH", "CMAKE_PREFIX_PATH", "COLCON_PREFIX_PATH", "LD_LIBRARY_PATH",
                   "PATH", "PYTHONPATH", "PKG_CONFIG_PATH")
_SHELL_NOISE = {"_", "SHLVL", "PWD", "OLDPWD"}


# --- using the built workspace -----------------------------------------------------------------

def _install_dir(ws_dir) -> Path:
    install = Path(ws_dir).absolute() / "install"
    if not (install / "setup.bash").is_file():
        raise FileNotFoundError(f"{install / 'setup.bash'} does not exist: build the workspace first "
                                f"(colcon.build({str(Path(ws_dir))!r}) or `python -m course_lib build {ws_dir}`)")
    return install


def workspace_environment(ws_dir, base: dict[str, str] | None = None,
                          domain_id: int | None = None) -> dict[str, str]:
    """The environment after ``source ws_dir/install/setup.bash``, on top of the course's ROS environment.

    Args:
        ws_dir: a built workspace.
        base: the environment to start from; defaults to os.environ.
        domain_id: ROS_DOMAIN_ID for processes started with it.

    Returns:
        A new dict: PYTHONPATH has the packages' site-packages, AMENT_PREFIX_PATH the package
        prefixes, LD_LIBRARY_PATH their lib/ (generated message libraries), PATH their bin/.

    Raises:
        FileNotFoundError: the workspace is not built.
        RuntimeError: sourcing setup.bash failed.
    """
    install = _install_dir(ws_dir)
    start = rosenv.ros_environment(domain_id=domain_id, base=base)
    bash = shutil.which("bash", path=start.get("PATH")) or shutil.which("bash") or "/bin/bash"
    script = f'source "{install / "setup.bash"}" >/dev/null && env -0'
    completed = subprocess.run([bash, "--noprofile", "--norc", "-c", script], env=start, capture_output=True,
                               timeout=60, stdin=subprocess.DEVNULL)
    if completed.returncode != 0:
        raise RuntimeError(f"sourcing {install / 'setup.bash'} failed: "
                           f"{completed.stderr.decode(errors='replace').strip()}")
    sourced = {}
    for item in completed.stdout.decode(errors="surrogateescape").split("\0"):
        name, separator, value = item.partition("=")
        if separator and name not in _SHELL_NOISE:
            sourced[name] = value
    env = dict(start)
    env.update({name: value for name, value in sourced.items() if start.get(name) != value})
    for name in _PATH_VARIABLES:
        if name in env:
            # setup.bash leaves a trailing ':' (meaning "the current folder") in some variables.
            env[name] = os.pathsep.join(rosenv.unique(p for p in env[name].split(os.pathsep) if p))
    return env


def use_workspace(ws_dir) -> list[str]:
    """Make a built workspace usable in this running interpreter (a notebook kernel).

    Extends sys.path with the workspace's site-packages, updates os.environ like sourcing
    install/setup.bash does (child processes and ROS look-ups see the workspace), and loads
    the generated message libraries with ctypes: the dynamic loader reads LD_LIBRARY_PATH only
    when a process starts, so without the preload ``import my_interfaces.msg`` fails in a
    running kernel with "cannot open shared object file".

    Returns:
        The workspace's package names.

    Raises:
        FileNotFoundError: the workspace is not built.
        RuntimeError: a package of the workspace was already imported from an older build
            (restart the kernel to import the new one).
    """
    env = workspace_environment(ws_dir)
    for name in _PATH_VARIABLES + ("ROS_PACKAGE_PATH",):
        if name in env and os.environ.get(name) != env[name]:
            os.environ[name] = env[name]
    install = _install_dir(ws_dir)
    packages = sorted(p.name for p in install.iterdir() if (p / "share" / p.name / "package.xml").is_file())
    for entry in reversed([p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]):
        if _is_inside(Path(entry), install) and entry not in sys.path:
            sys.path.insert(0, entry)
    libraries = [lib for package in packages for lib in sorted((install / package / "lib").glob("*.so"))]
    _preload(libraries)
    importlib.invalidate_caches()
    stale = [name for name in packages if name in sys.modules
             and not _is_inside(Path(getattr(sys.modules[name], "__file__", None) or "/"), install)]
    if stale:
        raise RuntimeError(f"{', '.join(stale)} was already imported from elsewhere in this kernel; "
                           "restart the kernel (Kernel > Restart) and call use_workspace() before importing it")
    return packages


def _preload(libraries: list[Path]) -> None:
    # The libraries need each other; load in passes until no more can be loaded.
    pending = list(libraries)
    errors: dict[Path, str] = {}
    while pending:
        progress = False
        for library in list(pending):
            try:
                ctypes.CDLL(str(library), mode=ctypes.RTLD_GLOBAL)
            except OSError as error:
                errors[library] = str(error)
                continue
            pending.remove(library)
            progress = True
        if not progress:
            details = "; ".join(errors[library] for library in pending)
            raise RuntimeError(f"cannot load {len(pending)} libraries of the workspace ({details}); "
                               "restart the kernel, or start Jupyter from a terminal where you ran "
                               "`source install/setup.bash`")


def _is_inside(path: Path, parent: Path) -> bool:
    return path.resolve().is_relative_to(parent.resolve())


# --- running nodes -----------------------------------------------------------------------------

def _parameter_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_parameter_value(item) for item in value) + "]"
    return str(value)


def executables(ws_dir, package: str) -> list[str]:
    """The executables ``ros2 run`` would offer for a package of the built workspace."""
    from course_lib.ros import ament

    return ament.executables_in(Path(ws_dir).absolute() / "install" / package, package)


def executable_command(ws_dir, package: str, executable: str, *, ros_args=(), remap: dict | None = None,
                       params: dict | None = None, params_file=None) -> list[str]:
    """The command line of ``ros2 run package executable --ros-args ...`` for a built workspace.

    Args:
        ws_dir: a built workspace.
        package, executable: as for ``ros2 run``.
        ros_args: more arguments after ``--ros-args`` (e.g. ["--log-level", "debug"]).
        remap: {from: to} topic or name remappings (``-r from:=to``).
        params: {name: value} parameters (``-p name:=value``; bools become true/false).
        params_file: a YAML parameter file (``--params-file``).

    Returns:
        The command as a list, starting with the installed executable.

    Raises:
        FileNotFoundError: the package or executable does not exist; the message lists what does.
    """
    install = _install_dir(ws_dir)
    if not (install / package).is_dir():
        built = sorted(p.name for p in install.iterdir() if p.is_dir())
        raise FileNotFoundError(f"package {package!r} is not in {install}; built packages: "
                                f"{', '.join(built) or 'none'} (did you build after creating it?)")
    path = install / package / "lib" / package / executable
    if not path.is_file():
        available = executables(ws_dir, package)
        raise FileNotFoundError(f"package {package!r} has no executable {executable!r}; available: "
                                f"{', '.join(available) or 'none'} (add it to entry_points in setup.py "
                                "and build again)")
    extra = []
    for source, target in (remap or {}).items():
        extra += ["-r", f"{source}:={target}"]
    for name, value in (params or {}).items():
        extra += ["-p", f"{name}:={_parameter_value(value)}"]
    if params_file is not None:
        extra += ["--params-file", str(Path(params_file).absolute())]
    extra += [str(arg) for arg in ros_args]
    return [str(path)] + (["--ros-args", *extra] if extra else [])


def run(ws_dir, package: str, executable: str, *, ros_args=(), remap: dict | None = None,
        params: dict | None = None, params_file=None, domain_id: int | None = None, name: str | None = None):
    """Start a node of a built workspace as a process, like ``ros2 run``.

    Args:
        domain_id: ROS_DOMAIN_ID of the process; None keeps this process's.
        name: a label for the process in logs; defaults to the executable.
        The others as for :func:`executable_command`.

    Returns:
        A started course_lib.ros.processes.NodeProcess (``.log``, ``.wait_for_node()``, ``.stop()``).
    """
    from course_lib.ros import processes

    command = executable_command(ws_dir, package, executable, ros_args=ros_args, remap=remap,
                                 params=params, params_file=params_file)
    env = workspace_environment(ws_dir, domain_id=domain_id)
    return processes.NodeProcess(command, name=name or executable, domain_id=domain_id, env=env).start()
