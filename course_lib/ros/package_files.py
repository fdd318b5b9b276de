"""What a ROS 2 package's own files say, read without building or importing anything.

- :func:`run_dependencies`: the packages its ``package.xml`` lets the code use at run time;
- :func:`imported_modules` / :func:`package_imports`: the top-level modules its Python code imports;
- :func:`console_scripts`: the executables its ``setup.py`` declares (what ``ros2 run`` can start).

On a full ROS install, ``rosdep check --from-paths src`` and ``ros2 pkg executables <package>``
answer the first and the last question for a built workspace; these read the source, so a lesson's
self-check and the grader's checks can name a missing ``<depend>`` or a wrong entry point before
anything runs.
"""

from __future__ import annotations

import ast
import re
import xml.etree.ElementTree as ElementTree
from pathlib import Path


def dependencies(package_xml, tags=("depend", "build_depend", "exec_depend")) -> set[str]:
    """The package names a package.xml (format 2 or 3) lists in elements of these `tags`.

    Raises:
        OSError: the file cannot be read.
        xml.etree.ElementTree.ParseError: it is not well-formed XML.
    """
    root = ElementTree.parse(package_xml).getroot()
    return {(element.text or "").strip() for element in root if element.tag in tags}


def run_dependencies(package_xml) -> set[str]:
    """The packages a package.xml lets the code use at run time: ``<depend>`` and ``<exec_depend>``."""
    return dependencies(package_xml, ("depend", "exec_depend"))


def imported_modules(tree: ast.AST) -> dict[str, int]:
    """{top-level module: line of its first import} of a parsed module's absolute imports."""
    found: dict[str, int] = {}
    for node in ast.walk(tree):
        names = ([alias.name for alias in node.names] if isinstance(node, ast.Import) else
                 [node.module] if isinstance(node, ast.ImportFrom) and node.module and not node.level else [])
        for name in names:
            found.setdefault(name.split(".")[0], node.lineno)
    return found


def package_imports(folder: Path) -> dict[str, str]:
    """{top-level module: the first file (relative to `folder`) that imports it} of a package's
    Python files; its tests, setup.py and build folders are left out, and so are files that do
    not parse (the build or the import names their error, with the line)."""
    found: dict[str, str] = {}
    for path in sorted(Path(folder).rglob("*.py")):
        relative = path.relative_to(folder)
        if relative.parts[0] in ("test", "build", "install") or relative.name == "setup.py":
            continue
        try:
            tree = ast.parse(path.read_text(errors="replace"))
        except SyntaxError:
            continue
        for module in imported_modules(tree):
            found.setdefault(module, str(relative))
    return found


def console_scripts(setup_py) -> dict[str, str]:
    """{executable: "module:function"} of the strings in setup.py that read like console-script
    entries (``'talker = my_package.talker:main'``), wherever the file builds its list.

    Raises:
        OSError: the file cannot be read.
        SyntaxError: it is not valid Python.
    """
    scripts = {}
    for node in ast.walk(ast.parse(Path(setup_py).read_text(), str(setup_py))):
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            match = re.fullmatch(r"\s*([\w.-]+)\s*=\s*(\S+?)\s*", node.value)
            if match:
                scripts[match.group(1)] = match.group(2)
    return scripts


def built_console_scripts(ws_dir, package: str) -> dict[str, str] | None:
    """{executable: "module:function"} as the workspace's last build of an ament_python package
    installed them: the ``entry_points.txt`` that setuptools wrote from setup.py (in build/ with
    --symlink-install, where the installed scripts look them up, else in install/); None when there
    is none (not built)."""
    import configparser

    ws_dir = Path(ws_dir)
    found = sorted([*(ws_dir / "build" / package).glob("*.egg-info/entry_points.txt"),
                    *(ws_dir / "install" / package).glob("lib/python*/site-packages/*.egg-info/entry_points.txt")],
                   key=lambda path: path.stat().st_mtime)
    if not found:
        return None
    parser = configparser.ConfigParser(delimiters=("=",))
    parser.optionxform = str  # executable names keep their case
    parser.read(found[-1])
    return {name: value.replace(" ", "") for name, value in parser["console_scripts"].items()} \
        if parser.has_section("console_scripts") else {}
