"""tf2_msgs on the pip install: built from the course's copy of its definitions by the real colcon,
once per set-up, and installed into the environment where a wheel would have put it.

PyPI has no ros-jazzy-tf2-msgs wheel, but the robot's ``/tf`` and ``/tf_static`` carry
``tf2_msgs/msg/TFMessage``, and students write ``from tf2_msgs.msg import TFMessage`` as on a full
ROS install. ``interfaces/tf2_msgs`` holds upstream's four interfaces (TFMessage, TF2Error,
FrameGraph, LookupTransform) with upstream's fields; this module builds them as lesson 01b builds a
message package (``course_lib.ros.colcon``: rosidl's generators and a C compiler, about 20 s) and
copies the result into the environment: the libraries into ``lib/``, the Python package into
site-packages, ``share/tf2_msgs`` (the definitions, package.xml, CMake files, so that a student's
package can depend on it) and the ament index's entries. ``share/tf2_msgs/course_lib_install.json``
lists what was copied, with the key of the sources it was built from: a second run with the same
sources changes nothing. On a system or conda install, whose ROS has tf2_msgs, nothing is built.

``make setup`` runs it as the first step of ``python -m course_lib install-robot``.
"""

from __future__ import annotations

import hashlib
import json
import shutil
import sys
import sysconfig
import tempfile
from pathlib import Path

SOURCES = Path(__file__).parent / "interfaces"
#: The interface packages the course provides on the pip install.
PACKAGES = ("tf2_msgs",)
RECORD = "course_lib_install.json"
# colcon's per-package shell hooks name the prefix they were built in, which is a temporary folder.
_HOOK_SUFFIXES = (".sh", ".bash", ".zsh", ".ps1", ".dsv")


def source_key(package: str) -> str:
    """What the installed build depends on: the package's files, this interpreter and environment."""
    digest = hashlib.sha256(f"{sys.version}\0{sys.prefix}\0".encode())
    folder = SOURCES / package
    for path in sorted(p for p in folder.rglob("*") if p.is_file()):
        digest.update(str(path.relative_to(folder)).encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()[:32]


def installed_key(package: str, prefix: Path) -> str | None:
    """The source key of the course's build of `package` in `prefix`, None when there is none."""
    try:
        return json.loads((prefix / "share" / package / RECORD).read_text())["key"]
    except (OSError, ValueError, KeyError):
        return None


def _site_packages(prefix: Path) -> Path:
    purelib = Path(sysconfig.get_paths()["purelib"])
    return prefix / purelib.relative_to(sys.prefix)


def _copy(build: Path, prefix: Path, package: str) -> list[str]:
    """Copy the package's files from a colcon install (merged) into `prefix`; their paths."""
    python_dir = Path("lib") / f"python{sys.version_info.major}.{sys.version_info.minor}" / "site-packages"
    pairs = [(p, prefix / "lib" / p.name) for p in (build / "lib").glob(f"lib{package}__*.so")]
    pairs += [(p, _site_packages(prefix) / p.relative_to(build / python_dir))
              for p in (build / python_dir / package).rglob("*") if p.is_file() and "__pycache__" not in p.parts]
    share = build / "share" / package
    pairs += [(p, prefix / p.relative_to(build)) for p in share.rglob("*")
              if p.is_file() and not (p.parent == share and p.suffix in _HOOK_SUFFIXES)]
    pairs += [(p, prefix / p.relative_to(build)) for p in (build / "include").rglob("*") if p.is_file()]
    pairs += [(p, prefix / p.relative_to(build)) for p in (build / "share" / "ament_index").rglob(package)]
    for source, target in pairs:
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(source, target)
    return sorted(str(target.relative_to(prefix)) for _, target in pairs)


def install(package: str, prefix: Path | None = None) -> str:
    """Build `package` from SOURCES and install it into `prefix` (default: this environment) unless
    the same sources are installed there already; return what was done, in one line.

    Raises:
        course_lib.ros.colcon.BuildError: the build failed (the message ends with colcon's log).
    """
    from course_lib.ros import colcon

    prefix = Path(sys.prefix if prefix is None else prefix).absolute()
    key = source_key(package)
    if installed_key(package, prefix) == key:
        return f"install-robot: {package} is up to date in {prefix}"
    with tempfile.TemporaryDirectory(prefix=f"course-{package}-") as scratch:
        ws = Path(scratch)
        shutil.copytree(SOURCES / package, ws / "src" / package)
        colcon.build(ws, extra_args=["--merge-install"])
        copied = _copy(ws / "install", prefix, package)
    record = prefix / "share" / package / RECORD
    record.write_text(json.dumps({"key": key, "files": copied}, indent=1) + "\n")
    return f"install-robot: built {package} and installed {len(copied)} files into {prefix}"


def main(argv: list[str] | None = None) -> int:
    """Build and install PACKAGES on the pip install (a step of ``python -m course_lib install-robot``)."""
    from course_lib.ros import colcon, rosenv

    if argv:
        print(f"interface_install takes no arguments, got {' '.join(argv)}", file=sys.stderr)
        return 2
    install_kind = rosenv.detect_install()
    if install_kind.kind != "pip":
        print(f"install-robot: not needed, {install_kind.describe()} has {', '.join(PACKAGES)}")
        return 0
    for package in PACKAGES:
        try:
            print(install(package))
        except colcon.BuildError as error:
            print(f"install-robot: building {package} failed: {error}", file=sys.stderr)
            return 1
    return 0
