"""``ros2 interface show|list|package|packages``, from course_lib.ros.interfaces."""

from __future__ import annotations

import sys

from course_lib.ros2cli.common import Verb, run_group

#: Verbs of ros2cli's ``ros2 interface`` that the course leaves out.
LEFT_OUT = ("proto",)

_KINDS = (("msg", "Messages", "only_msgs"), ("srv", "Services", "only_srvs"), ("action", "Actions", "only_actions"))


def _kind_arguments(parser) -> None:
    parser.add_argument("-m", "--only-msgs", action="store_true", help="Print out only the message types")
    parser.add_argument("-s", "--only-srvs", action="store_true", help="Print out only the service types")
    parser.add_argument("-a", "--only-actions", action="store_true", help="Print out only the action types")


def _chosen_kinds(args) -> list[tuple[str, str]]:
    chosen = [(kind, title) for kind, title, flag in _KINDS if getattr(args, flag)]
    return chosen or [(kind, title) for kind, title, _ in _KINDS]


def _show_arguments(parser) -> None:
    comments = parser.add_mutually_exclusive_group()
    comments.add_argument("--all-comments", action="store_true",
                          help="Show all comments, including for nested interface definitions")
    comments.add_argument("--no-comments", action="store_true", help="Show no comments or whitespace")
    parser.add_argument("type", help="Show an interface definition (e.g. 'example_interfaces/msg/String'). "
                                     "Passing '-' reads the argument from stdin")


def _show(args) -> str | None:
    from course_lib.ros import interfaces

    name = sys.stdin.readline().strip() if args.type == "-" else args.type
    if not name:
        return "the passed value is empty"
    if len(name.split("/")) != 3:  # the library also reads "std_msgs/String"; ros2cli does not
        return f"Invalid name '{name}'. Expected three parts separated by '/'"
    comments = "all" if args.all_comments else "none" if args.no_comments else "top"
    print(interfaces.show(name, comments=comments))  # LookupError: rosidl_runtime_py's words
    return None


def _list(args) -> None:
    from course_lib.ros import interfaces

    for kind, title in _chosen_kinds(args):
        print(f"{title}:")
        for package in interfaces.packages():
            for name in interfaces.package_interfaces(package, kind):
                print(f"    {package}/{kind}/{name}")


def _package_arguments(parser) -> None:
    _kind_arguments(parser)
    parser.add_argument("package_name", help="Name of the ROS package (e.g. 'example_interfaces')")


def _package(args) -> str | None:
    from course_lib.ros import ament, interfaces

    if args.package_name not in ament.packages():
        return f"Unknown package '{args.package_name}'"
    for kind, _ in _chosen_kinds(args):
        for name in interfaces.package_interfaces(args.package_name, kind):
            print(f"{args.package_name}/{kind}/{name}")
    return None


def _packages(args) -> None:
    from course_lib.ros import interfaces

    kinds = [kind for kind, _ in _chosen_kinds(args)]
    for package in interfaces.packages():
        if any(interfaces.package_interfaces(package, kind) for kind in kinds):
            print(package)


VERBS = {
    "list": Verb("List all interface types available", _kind_arguments, _list),
    "package": Verb("Output a list of available interface types within one package", _package_arguments, _package),
    "packages": Verb("Output a list of packages that provide interfaces", _kind_arguments, _packages),
    "show": Verb("Output the interface definition", _show_arguments, _show),
}


def main(argv: list[str]):
    return run_group("ros2 interface", "Show information about ROS interfaces", VERBS, argv, missing=LEFT_OUT)
