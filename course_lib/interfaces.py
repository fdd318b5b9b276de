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
    package, kind, type_name = _split(name)
    try:
        share = Path(get_package_share_directory(package))
    except PackageNotFoundError:
        raise LookupError(f"package {package!r} is not installed (or its workspace is not sourced); "
                          "installed interface packages can be listed with interfaces.packages()") from None
    path = share / kind / f"{type_name}.{kind}"
    if not path.is_file():
        available = ", ".join(package_interfaces(package, kind)) or "none"
        raise LookupError(f"{package} has no {kind} {type_name!r}; it has: {available}")
    return path


def show(name: str, expand: bool = True) -> str:
    """The definition of an interface, with nested message types indented below their field.

    Args:
        name: "package/msg/Type" (also "package/Type").
        expand: include the definitions of nested message types, like `ros2 interface show`.
    """
    package, kind, _ = _split(name)
    text = definition_path(name).read_text()
    if not expand:
        return text.rstrip("\n")
    return "\n".join(_expand(text, package, indent=""))


def _expand(text: str, package: str, indent: str):
    for line in text.splitlines():
        yield indent + line
        field = line.split("#", 1)[0].strip()
        if not field or "=" in field.split()[0]:
            continue
        field_type = re.sub(r"\[.*\]$", "", field.split()[0])
        field_type = re.sub(r"<=\d+$", "", field_type)
        if field_type in PRIMITIVES or "=" in field:  # constants never nest
            continue
        nested = field_type if "/" in field_type else (
            f"std_msgs/{field_type}" if field_type == "Header" else f"{package}/{field_type}")
        try:
            nested_text = definition_path(nested).read_text()
        except (LookupError, ValueError):
            continue
        nested_package = _split(nested)[0]
        yield from _expand(_strip_comment_lines(nested_text), nested_package, indent + "\t")


def _strip_comment_lines(text: str) -> str:
    return "\n".join(line for line in text.splitlines() if line.strip() and not line.lstrip().startswith("#"))


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
