"""Where the course's ``ros2`` goes: into the virtual environment on the pip install only.

The rule: the course provides ``ros2`` when rclpy comes from the ros-jazzy-* wheels and there is
no real ros2cli, that is, no ``ros2cli`` Python package and no other ``ros2`` on PATH. On a
system or conda install the real ``ros2`` exists, and a venv made with
``--system-site-packages`` puts its own bin/ first on PATH when activated: a ``ros2`` there
would shadow the real one, so none is written (and one written earlier is removed).

``make setup`` runs ``python -m course_lib install-ros2``.
"""

from __future__ import annotations

import importlib.util
import os
import shutil
import sys
from pathlib import Path

from course_lib.ros import rosenv

#: The second line of the script; it tells our ``ros2`` from a real one.
MARKER = "# ros2 of course_lib (course_lib.ros2cli): the pip install has no ros2cli"


def other_ros2(bin_dir: Path, path: str | None = None) -> Path | None:
    """A ``ros2`` executable on PATH (``path``, default $PATH) other than ours in ``bin_dir``."""
    folders = [folder for folder in (os.environ.get("PATH", "") if path is None else path).split(os.pathsep)
               if folder and Path(folder).resolve() != Path(bin_dir).resolve()]
    found = shutil.which("ros2", path=os.pathsep.join(folders))
    return None if found is None or is_ours(Path(found)) else Path(found)


def is_ours(script: Path) -> bool:
    try:
        with open(script, encoding="utf-8", errors="replace") as handle:
            return MARKER in handle.read(1024)
    except OSError:
        return False


def should_provide(install: rosenv.RosInstall, real_ros2: Path | None, ros2cli_importable: bool) -> bool:
    """True when the course's ``ros2`` is needed: pip wheels and no real ros2 anywhere."""
    return install.kind == "pip" and real_ros2 is None and not ros2cli_importable


def script_text(python: str) -> str:
    return (f"#!{python}\n{MARKER}\n"
            "import sys\n\nfrom course_lib.ros2cli import main\n\nsys.exit(main())\n")


def install(bin_dir: Path | None = None, path: str | None = None) -> str:
    """Write (or remove) ``bin_dir/ros2`` as the rule says; return what was done, in one line.

    Args:
        bin_dir: the venv's bin/ (default: this interpreter's).
        path: the PATH to look for a real ros2 on (default: $PATH).
    """
    bin_dir = Path(sys.executable).parent if bin_dir is None else Path(bin_dir)
    target = bin_dir / "ros2"
    install_kind = rosenv.detect_install()
    real = other_ros2(bin_dir, path)
    ros2cli = importlib.util.find_spec("ros2cli") is not None
    if not should_provide(install_kind, real, ros2cli):
        why = (f"the real ros2 at {real}" if real else "the real ros2cli" if ros2cli
               else f"no pip install of ROS 2 ({install_kind.describe()})")
        if target.exists() and is_ours(target):
            target.unlink()
            return f"install-ros2: removed {target}: {why} is used instead"
        return f"install-ros2: not needed, {why} is used"
    text = script_text(str(Path(sys.executable)))
    if target.is_file() and target.read_text(errors="replace") == text:
        return f"install-ros2: {target} is up to date"
    if target.exists() and not is_ours(target):
        return f"install-ros2: {target} exists and is not the course's: left alone"
    target.write_text(text)
    target.chmod(0o755)
    return f"install-ros2: wrote {target} (the course's ros2 for the pip install)"


def main(argv: list[str] | None = None) -> int:
    print(install())
    return 0
