"""``ros2 pkg create|list|executables|prefix``, from course_lib.ros.workspace and course_lib.ros.ament."""

from __future__ import annotations

import getpass
import os
import shutil
import subprocess

from course_lib.ros2cli.common import Verb, run_group, unsupported

#: Verbs of ros2cli's ``ros2 pkg`` that the course leaves out.
LEFT_OUT = ("xml",)


# --- ros2 pkg create ---------------------------------------------------------------------

def _create_arguments(parser) -> None:
    parser.add_argument("package_name", help="The package name")
    parser.add_argument("--package-format", "--package_format", type=int, default=3, choices=[2, 3],
                        help="The package.xml format.")
    parser.add_argument("--description", default="TODO: Package description",
                        help="The description given in the package.xml")
    parser.add_argument("--license", default="TODO: License declaration",
                        help="The license attached to this package")
    parser.add_argument("--destination-directory", default=os.curdir,
                        help="Directory where to create the package directory")
    parser.add_argument("--build-type", default="ament_cmake", choices=["cmake", "ament_cmake", "ament_python"],
                        help="The build type to process the package with (the course's ros2: ament_python)")
    parser.add_argument("--dependencies", nargs="+", default=[], help="list of dependencies")
    parser.add_argument("--maintainer-email", help="email address of the maintainer of this package")
    parser.add_argument("--maintainer-name", default=getpass.getuser(), help="name of the maintainer of this package")
    parser.add_argument("--node-name", help="name of the empty executable")


def _git_email() -> str:
    git = shutil.which("git")
    if git is None:
        return ""
    done = subprocess.run([git, "config", "user.email"], capture_output=True, text=True, timeout=10)
    return done.stdout.strip()


def _create(args) -> str | None:
    from course_lib.ros import pkg_create

    if args.build_type != "ament_python":
        default = " (the default)" if args.build_type == "ament_cmake" else ""
        raise unsupported(f"ros2 pkg create: --build-type {args.build_type}{default}", ["--build-type ament_python"])
    if args.package_format != 3:
        raise unsupported("ros2 pkg create: --package-format 2", ["--package-format 3"])
    if args.package_name == "test":
        return ("Aborted since 'ament_python' packages can't be named 'test'. Please choose a different "
                "package name.")
    email = args.maintainer_email or _git_email() or f"{args.maintainer_name}@todo.todo"
    package_path = os.path.join(args.destination_directory, args.package_name)
    if os.path.exists(package_path):
        return (f"\nAborted!\nThe directory already exists: {package_path}\nEither remove the directory or "
                "choose a different destination directory or package name")
    print("going to create a new package")
    print("package name:", args.package_name)
    print("destination directory:", os.path.abspath(args.destination_directory))
    print("package format:", args.package_format)
    print("version: 0.0.0")
    print("description:", args.description)
    print("maintainer:", [f"{args.maintainer_name} <{email}>"])
    print("licenses:", [args.license])
    print("build type:", args.build_type)
    print("dependencies:", list(args.dependencies))
    if args.node_name:
        print("node_name:", args.node_name)
    written = pkg_create.write_python_package(
        package_path, args.package_name, dependencies=args.dependencies, node_name=args.node_name,
        rclpy_node=False, description=args.description, maintainer=args.maintainer_name,
        maintainer_email=email, license=args.license)
    source = os.path.join(package_path, args.package_name)
    for made in written:  # in ros2pkg's order, named from --destination-directory ("./pkg/...")
        relative = os.path.relpath(made, written[0])
        path = package_path if relative == os.curdir else os.path.join(package_path, relative)
        if path == source:
            print("creating source folder")
        print("creating folder" if made.is_dir() else "creating", path)
    return None


# --- ros2 pkg list / executables / prefix ------------------------------------------------

def _list(args) -> None:
    from course_lib.ros import ament

    for name in ament.packages():
        print(name)


def _executables_arguments(parser) -> None:
    parser.add_argument("package_name", nargs="?", help="The package name")
    parser.add_argument("--full-path", action="store_true", default=False, help="Show full path of each executable")


def _executables(args) -> str | None:
    from course_lib.ros import ament

    names = [args.package_name] if args.package_name else list(ament.packages())
    if args.package_name and args.package_name not in ament.packages():
        return f"Package '{args.package_name}' not found"
    for package in sorted(names):
        for name in ament.executables(package):
            print(ament.executable(package, name) if args.full_path else f"{package} {name}")
    return None


def _prefix_arguments(parser) -> None:
    parser.add_argument("package_name", help="The package name")
    parser.add_argument("--share", action="store_true", help="Show share directory for the package")


def _prefix(args) -> str | None:
    from course_lib.ros import ament

    try:
        print(ament.share(args.package_name) if args.share else ament.prefix(args.package_name))
    except LookupError:
        return "Package not found"  # ros2pkg's PACKAGE_NOT_FOUND
    return None


VERBS = {
    "create": Verb("Create a new ROS 2 package", _create_arguments, _create),
    "executables": Verb("Output a list of package specific executables", _executables_arguments, _executables),
    "list": Verb("Output a list of available packages", lambda parser: None, _list),
    "prefix": Verb("Output the prefix path of a package", _prefix_arguments, _prefix),
}


def main(argv: list[str]):
    return run_group("ros2 pkg", "Various package related sub-commands", VERBS, argv, missing=LEFT_OUT)
