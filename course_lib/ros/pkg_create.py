"""Create ROS 2 packages the way ``ros2 pkg create`` does: ament_python node packages and
ament_cmake interface (message) packages, in the standard layout that ``colcon build`` builds.
"""

from __future__ import annotations

import re
from pathlib import Path
from xml.sax.saxutils import escape

DEFAULT_MAINTAINER = "student"
DEFAULT_EMAIL = "student@example.com"
DEFAULT_DESCRIPTION = "TODO: Package description"

_PACKAGE_NAME = re.compile(r"^[a-z][a-z0-9_]*$")
_MESSAGE_NAME = re.compile(r"^[A-Z][A-Za-z0-9]*$")
#: The kinds of interface files a package of interfaces holds, each in the folder of its name.
_KINDS = {"msg": "message", "srv": "service", "action": "action"}

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
        The folders and files made, in the order ``ros2 pkg create`` makes them (ros2pkg's
        api/create.py: the package folder, package.xml, the source folder, setup.py, ...); a
        file kept because it existed is left out.
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
    # (path, text) in ros2 pkg create's order; text None: a folder; kept: a file written only if absent.
    steps = [
        ("", None),
        ("package.xml", _package_xml(name, description, maintainer, maintainer_email, license, body,
                                     "ament_python")),
        (name, None),
        ("setup.py", _setup_py(name, description, maintainer, maintainer_email, license, scripts)),
        ("setup.cfg", _setup_cfg(name)),
        ("resource", None),
        (f"resource/{name}", ""),
        (f"{name}/__init__.py", ""),
        ("test", None),
        ("test/test_copyright.py", _TEST_COPYRIGHT),
        ("test/test_flake8.py", _TEST_FLAKE8),
        ("test/test_pep257.py", _TEST_PEP257),
        *[(f"{name}/{node}.py", _node_source(name, node, rclpy_node)) for node in node_names],
    ]
    kept = {f"{name}/__init__.py", *(f"{name}/{node}.py" for node in node_names)}
    made = []
    for relative, text in steps:
        path = package_dir / relative
        if text is None:
            path.mkdir(parents=True, exist_ok=True)
        elif relative in kept and path.exists():
            continue
        else:
            _write(path, text)
        made.append(path)
    return made


def create_interface_package(ws_dir, name: str, messages: dict[str, str], *,
                             dependencies=("builtin_interfaces",), description: str = DEFAULT_DESCRIPTION,
                             maintainer: str = DEFAULT_MAINTAINER, maintainer_email: str = DEFAULT_EMAIL,
                             license: str = "Apache-2.0", exist_ok: bool = False) -> Path:
    """Create an ament_cmake package of custom messages (``ros2 pkg create`` plus the usual edits).

    Args:
        ws_dir: the workspace folder (created when missing).
        name: the package name, e.g. "tutorial_interfaces".
        messages: {interface name: definition}, e.g.
            {"MsgTutorial": "builtin_interfaces/Time stamp\\nint32 data\\n"}; a name ending in
            ".srv" is a service ("int64 a\\nint64 b\\n---\\nint64 sum\\n"), one ending in ".action"
            an action (goal, result and feedback between "---" lines), any other a message.
        dependencies: message packages the definitions use (find_package and DEPENDENCIES);
            action_msgs is added when there are actions (their generated types use it).
        exist_ok: when the package exists, rewrite CMakeLists.txt, package.xml and the given
            interfaces (other interface files are kept).

    Returns:
        The package folder.

    Raises:
        ValueError: a bad package or message name, or no messages.
        FileExistsError: the package exists and exist_ok is False.
    """
    if not messages:
        raise ValueError("messages is empty: give at least one, e.g. {'MsgTutorial': 'int32 data'}")
    files = []  # "msg/Name.msg", "srv/Name.srv", "action/Name.action"
    for message in messages:
        stem, dot, kind = message.rpartition(".")
        stem, kind = (stem, kind) if dot and kind in _KINDS else (message, "msg")
        if not _MESSAGE_NAME.match(stem):
            raise ValueError(f"{_KINDS[kind]} name {message!r} must be CamelCase starting with a capital letter "
                             f"(e.g. 'MsgTutorial'); ROS turns it into the file {kind}/MsgTutorial.{kind}")
        files.append(f"{kind}/{stem}.{kind}")
    if any(file.startswith("action/") for file in files):
        dependencies = [*dependencies, "action_msgs"]
    dependencies = list(dict.fromkeys(dependencies))
    for dependency in dependencies:
        _check_package_name(dependency)
    package_dir = _prepare_package_dir(Path(ws_dir) / "src" / name, name, exist_ok)
    finds = "".join(f"find_package({dependency} REQUIRED)\n" for dependency in dependencies)
    listed = "".join(f'  "{file}"\n' for file in files)
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
    for message, file in zip(messages, files, strict=True):
        definition = messages[message]
        _write(package_dir / file, definition if definition.endswith("\n") else definition + "\n")
    return package_dir


def _write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
