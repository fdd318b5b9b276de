"""Message definitions as the installed packages declare them: ``ros2 interface`` for notebooks.

    interfaces.show("geometry_msgs/msg/Twist")    # like `ros2 interface show`, nested types expanded
    interfaces.package("sensor_msgs")             # like `ros2 interface package sensor_msgs`
"""

from __future__ import annotations

import re
from pathlib import Path

from ament_index_python.packages import PackageNotFoundError, get_package_share_directory

#: Field types that are not messages of their own.
PRIMITIVES = {"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16",
              "int32", "uint32", "int64", "uint64", "string", "wstring"}


def _split(name: str) -> tuple[str, str, str]:
    parts = name.strip().split("/")
    if len(parts) == 2:  # "std_msgs/String", the ROS 1 spelling
        parts = [parts[0], "msg", parts[1]]
    if len(parts) != 3 or parts[1] not in ("msg", "srv", "action"):
        raise ValueError(f"{name!r} is not an interface name: write it as package/msg/Type, "
                         "e.g. 'geometry_msgs/msg/Twist'")
    return parts[0], parts[1], parts[2]


def definition_path(name: str) -> Path:
    """The installed .msg/.srv/.action file of an interface.

    Raises:
        LookupError: the package or the interface is not installed, with what is available.
    """
    from course_lib.ros.node_logs import kernel_hint

    package, kind, type_name = _split(name)
    try:
        share = Path(get_package_share_directory(package))
    except PackageNotFoundError:  # rosidl_runtime_py's words, as `ros2 interface show` prints them
        raise LookupError(f"Unknown package '{package}'"
                          + kernel_hint("interfaces.packages() lists the installed interface packages")) from None
    path = share / kind / f"{type_name}.{kind}"
    if not path.is_file():
        available = ", ".join(package_interfaces(package, kind)) or "none"
        raise LookupError(f"Could not find the interface '{share / kind / type_name}.idl'"
                          + kernel_hint(f"{package} has the {kind} types {available}"))
    return path


def show(name: str, expand: bool = True, comments: str = "top") -> str:
    """The definition of an interface, with nested message types indented below their field.

    Args:
        name: "package/msg/Type" (also "package/Type", "package/srv/Type").
        expand: include the definitions of nested message types, like `ros2 interface show`.
        comments: "top" keeps the interface's own comments and blank lines but none of the
            nested types' (what `ros2 interface show` prints), "all" keeps every comment
            (``--all-comments``), "none" drops them all (``--no-comments``).
    """
    if comments not in ("top", "all", "none"):
        raise ValueError(f"comments={comments!r}: use 'top', 'all' or 'none'")
    if not expand:
        return definition_path(name).read_text().rstrip("\n")
    return "\n".join(_lines(name, comments != "none", comments == "all", ""))


def _lines(name: str, with_comments: bool, nested_comments: bool, indent: str):
    package = _split(name)[0]
    for line in definition_path(name).read_text().splitlines():
        line = line.rstrip()
        code = _without_comment(line).strip()
        if with_comments:
            yield indent + line if line else ""
        elif code:
            yield indent + code
        nested = _nested_type(code, package)
        if nested is not None:
            yield from _lines(nested, nested_comments, nested_comments, indent + "\t")


def _without_comment(line: str) -> str:
    """The line up to its comment; a # inside a quoted string constant is not a comment."""
    quote = None
    for index, char in enumerate(line):
        if quote:
            quote = None if char == quote else quote
        elif char in "\"'":
            quote = char
        elif char == "#":
            return line[:index]
    return line


def _nested_type(code: str, package: str) -> str | None:
    """The message type a field line nests ("std_msgs/Header" for "Header header"), else None."""
    parts = code.split()
    if len(parts) < 2 or "=" in code or code == "---":
        return None
    field_type = re.sub(r"<=\d+$", "", re.sub(r"\[.*\]$", "", parts[0]))
    if field_type in PRIMITIVES:
        return None
    nested = field_type if "/" in field_type else (
        "std_msgs/Header" if field_type == "Header" else f"{package}/{field_type}")
    try:
        definition_path(nested)
    except (LookupError, ValueError):
        return None
    return nested


def package_interfaces(package: str, kind: str = "msg") -> list[str]:
    """Names of the interfaces of one kind that a package installs, sorted."""
    try:
        share = Path(get_package_share_directory(package))
    except PackageNotFoundError:
        return []
    return sorted(p.stem for p in (share / kind).glob(f"*.{kind}"))


def package(package: str) -> list[str]:
    """Every interface of a package as full names, like `ros2 interface package`."""
    return [f"{package}/{kind}/{name}" for kind in ("msg", "srv", "action")
            for name in package_interfaces(package, kind)]


def packages() -> list[str]:
    """Packages that register interfaces in the ament index, like `ros2 interface packages`."""
    from ament_index_python.resources import get_resources

    return sorted(get_resources("rosidl_interfaces"))
