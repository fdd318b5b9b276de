"""course_lib.ros2cli.install: the course's ros2 goes into the venv on the pip install only and
never shadows a real ros2; a kernel started without the venv activated still finds it."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from course_lib.ros import rosenv
from course_lib.ros2cli import install


def fake_ros2(folder: Path, ours: bool = False) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    script = folder / "ros2"
    script.write_text(install.script_text(sys.executable) if ours else "#!/bin/sh\necho real ros2\n")
    script.chmod(0o755)
    return script


@pytest.mark.parametrize("kind, real, ros2cli, provided", [
    ("pip", False, False, True),
    ("pip", True, False, False),     # a sourced /opt/ros/jazzy next to a pip venv
    ("pip", False, True, False),     # ros2cli importable through --system-site-packages
    ("system", False, False, False),
    ("conda", False, False, False),
    ("missing", False, False, False),
])
def test_the_rule(kind, real, ros2cli, provided):
    """Only pip wheels with no real ros2cli anywhere get the course's ros2."""
    found = Path("/opt/ros/jazzy/bin/ros2") if real else None
    assert install.should_provide(rosenv.RosInstall(kind, None, (), "jazzy"), found, ros2cli) is provided


def test_a_real_ros2_on_path_is_found_and_ours_is_not(tmp_path):
    """Another ros2 on PATH counts as real; ours (the marker line) and the venv's bin do not."""
    venv_bin, system_bin = tmp_path / "venv" / "bin", tmp_path / "opt" / "bin"
    fake_ros2(venv_bin, ours=True)
    assert install.other_ros2(venv_bin, path=f"{venv_bin}:{tmp_path / 'empty'}") is None
    real = fake_ros2(system_bin)
    # The venv's bin comes first on PATH once activated; the real one behind it still counts.
    assert install.other_ros2(venv_bin, path=f"{venv_bin}:{system_bin}") == real


def test_install_writes_ours_and_steps_aside_for_a_real_one(tmp_path):
    """On this pip install: written when no real ros2 is on PATH, removed when one appears,
    and someone else's ros2 in the venv is never touched."""
    venv_bin, system_bin = tmp_path / "bin", tmp_path / "system"
    venv_bin.mkdir()
    assert "wrote" in install.install(venv_bin, path=str(venv_bin))
    assert install.is_ours(venv_bin / "ros2") and os.access(venv_bin / "ros2", os.X_OK)
    assert "up to date" in install.install(venv_bin, path=str(venv_bin))
    fake_ros2(system_bin)
    assert "removed" in install.install(venv_bin, path=f"{venv_bin}:{system_bin}")
    assert not (venv_bin / "ros2").exists()
    theirs = fake_ros2(venv_bin)
    install.install(venv_bin, path=str(venv_bin))
    assert theirs.read_text() == "#!/bin/sh\necho real ros2\n"


def test_a_kernel_without_the_venv_on_path_finds_ros2_after_importing_course_lib():
    """`!ros2 ...` in a notebook whose kernel was not started from an activated venv."""
    env = {**os.environ, "PATH": "/usr/bin:/bin"}
    code = "import shutil, course_lib; print(shutil.which('ros2'))"
    found = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)
    assert found.stdout.strip() == str(Path(sys.executable).parent / "ros2"), found.stderr
