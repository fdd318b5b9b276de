"""Tests for course_lib.ros.underlay: the venv's local_setup.* files, as a ROS install's."""

from __future__ import annotations

import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from course_lib.ros import pkg_create, rosenv, underlay, wheelfix

SHELLS = [shell for shell in ("sh", "bash", "zsh") if shutil.which(shell)]


@pytest.fixture
def venv(tmp_path):
    """A folder that looks like a virtual environment, with the local_setup files written into it."""
    prefix = tmp_path / "some venv's"  # a space and a quote, which the scripts must survive
    prefix.mkdir()
    (prefix / "pyvenv.cfg").write_text("home = /usr/bin\n")
    underlay.write(prefix)
    return prefix


@pytest.mark.parametrize("shell", SHELLS)
def test_sourcing_local_setup_gives_what_environment_says(venv, shell):
    """The shell script and underlay.environment (what colcon builds run in) agree; a value that
    is there already moves to the front, once."""
    names = ("PATH", "AMENT_PREFIX_PATH", "CMAKE_PREFIX_PATH", "VIRTUAL_ENV", "Python3_ROOT_DIR")
    base = {"HOME": str(venv), "PATH": f"/elsewhere/bin:{venv}/bin:/usr/bin:/bin", "AMENT_PREFIX_PATH": f"/a:{venv}"}
    script = f". {shlex.quote(str(venv / ('local_setup.' + shell)))}"
    script += "".join(f'; printf "%s\\n" "${{{name}:-}}"' for name in names)
    done = subprocess.run([shell, "-c", script], env=base, capture_output=True, text=True, timeout=30)
    assert done.returncode == 0, done.stderr
    expected = underlay.environment(base, venv, ros_prefix=rosenv.detect_install().kind == "pip")
    assert done.stdout.splitlines() == [expected.get(name, "") for name in names]
    assert expected["PATH"] == f"{venv}/bin:/elsewhere/bin:/usr/bin:/bin"


def test_write_refuses_what_is_no_venv_or_not_its_own(tmp_path, venv):
    with pytest.raises(ValueError, match="no virtual environment"):
        underlay.write(tmp_path)
    assert underlay.write(venv) == [venv / f"local_setup.{shell}" for shell in underlay.SHELLS]  # again: the same
    (venv / "local_setup.bash").write_text("# a ROS install's own\n")
    with pytest.raises(ValueError, match="not written by the course"):
        underlay.write(venv)


def test_this_environment_is_an_underlay_and_builds_run_in_what_it_sets():
    """After `make setup`; colcon builds (wheelfix.build_environment) get what sourcing it gives."""
    assert (Path(sys.prefix) / "local_setup.sh").read_text().startswith(underlay.MARKER)
    base = {"PATH": "/usr/bin", "AMENT_PREFIX_PATH": "/somewhere"}
    assert wheelfix.build_environment(base) == underlay.environment(base, sys.prefix)


@pytest.mark.slow  # a colcon build
def test_plain_colcon_build_warns_nothing_and_its_setup_chains_the_venv(tmp_path):
    """In the lab's environment (make lab: course_lib env, then local_setup.sh) a plain `colcon build`
    does not warn that the venv on AMENT_PREFIX_PATH "doesn't contain any 'local_setup.*' files",
    and install/setup.bash sources the venv first, as it sources /opt/ros/jazzy on a robot: the
    course's python comes first again, also after another one was put first."""
    pkg_create.create_package(tmp_path, "chained", node_name="hello")
    other = tmp_path / "other" / "bin"
    other.mkdir(parents=True)
    (other / "python").write_text("#!/bin/sh\necho 'No module named course_lib' >&2\nexit 1\n")
    (other / "python").chmod(0o755)
    lab = (f'eval "$({sys.executable} -m course_lib env)" && . "{sys.prefix}/local_setup.sh" && '
           f'PATH="{other}:$PATH" && cd "{tmp_path}" && ')
    env = {"HOME": str(tmp_path), "PATH": "/usr/bin:/bin"}
    built = subprocess.run(["bash", "-c", lab + "colcon build --symlink-install"], env=env, capture_output=True,
                           text=True, timeout=300)
    assert built.returncode == 0, built.stdout + built.stderr
    assert "local_setup" not in built.stdout + built.stderr
    used = subprocess.run(["bash", "-c", lab + "source install/setup.bash && python -c 'import course_lib' && "
                                              "ros2 pkg executables chained"],
                          env=env, capture_output=True, text=True, timeout=60)
    assert used.returncode == 0 and used.stdout == "chained hello\n", used.stdout + used.stderr
