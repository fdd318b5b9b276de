"""autograder/builds/workspace_build.py's kept workspace builds, with the real colcon: a workspace whose files
are another's but for its modules' contents gets that build, moved to its own folder, and runs
its own code; any other change, a failed build or AUTOGRADER_REUSE_BUILDS=0 means colcon runs."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

from autograder.builds import caches, workspace_build
from course_lib import contract
from course_lib.ros import workspace

pytestmark = pytest.mark.slow

PACKAGE_XML = """<?xml version="1.0"?>
<package format="3">
  <name>greeter</name>
  <version>0.0.0</version>
  <description>says who wrote it</description>
  <maintainer email="student@example.org">student</maintainer>
  <license>Apache-2.0</license>
  <export><build_type>ament_python</build_type></export>
</package>
"""
SETUP_PY = """from setuptools import find_packages, setup

setup(
    name='greeter',
    version='0.0.0',
    packages=find_packages(),
    data_files=[('share/ament_index/resource_index/packages', ['resource/greeter']),
                ('share/greeter', ['package.xml'])],
    entry_points={'console_scripts': ['{executable} = greeter.greet:main']},
)
"""
SETUP_CFG = "[develop]\nscript_dir=$base/lib/greeter\n[install]\ninstall_scripts=$base/lib/greeter\n"


def write_workspace(root: Path, author: str, executable: str = "greet", setup_py: str = SETUP_PY) -> Path:
    ws = root / "ros2_ws"
    package = ws / "src" / "greeter"
    (package / "greeter").mkdir(parents=True)
    (package / "resource").mkdir()
    (package / "resource" / "greeter").write_text("")
    (package / "package.xml").write_text(PACKAGE_XML)
    (package / "setup.cfg").write_text(SETUP_CFG)
    (package / "setup.py").write_text(setup_py.replace("{executable}", executable))
    (package / "greeter" / "__init__.py").write_text("")
    (package / "greeter" / "greet.py").write_text(f"def main():\n    print('written by {author}')\n")
    return ws


class CountingColcon:
    """workspace_build.run_here, counting the colcon runs."""

    def __init__(self):
        self.runs = 0

    def __call__(self, command, cwd, env, wall_seconds):
        self.runs += 1
        return workspace_build.run_here(command, cwd, env, wall_seconds)


def build(root: Path, builds, colcon) -> workspace_build.BuildReport:
    scratch = root / "scratch"
    scratch.mkdir(exist_ok=True)
    return workspace_build.build_workspace(root / "ros2_ws", caches.InterfaceCache(root.parent / "cache"), scratch,
                                    colcon, builds=builds)


def run_executable(ws: Path, executable: str = "greet") -> str:
    env = workspace.workspace_environment(ws)
    done = subprocess.run([str(ws / "install" / "greeter" / "lib" / "greeter" / executable)], env=env,
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


def mentions(tree: Path, text: str) -> list[str]:
    """The files and links under `tree` that hold `text`."""
    found = []
    for directory, dirs, files in os.walk(tree):
        for name in [*files, *dirs]:
            path = os.path.join(directory, name)
            if os.path.islink(path):
                if text in os.readlink(path):
                    found.append(path)
            elif name in files and text.encode() in Path(path).read_bytes():
                found.append(path)
    return found


def test_an_identical_workspace_gets_the_build_moved_to_its_folder_and_runs_its_own_module(tmp_path):
    builds, colcon = caches.WorkspaceBuilds(tmp_path / "builds"), CountingColcon()
    write_workspace(tmp_path / "alice", "alice")
    write_workspace(tmp_path / "bob", "bob")
    first = build(tmp_path / "alice", builds, colcon)
    second = build(tmp_path / "bob", builds, colcon)
    assert first.ok and not first.reused and second.ok and second.reused
    assert colcon.runs == 1
    bob = tmp_path / "bob" / "ros2_ws"
    assert run_executable(bob) == "written by bob"
    assert run_executable(tmp_path / "alice" / "ros2_ws") == "written by alice"
    assert mentions(bob / "build", str(tmp_path / "alice")) == []
    assert mentions(bob / "install", str(tmp_path / "alice")) == []
    assert mentions(bob / "install", str(bob))  # its own paths are in it instead


def test_another_setup_py_is_built_by_colcon(tmp_path):
    builds, colcon = caches.WorkspaceBuilds(tmp_path / "builds"), CountingColcon()
    write_workspace(tmp_path / "alice", "alice")
    write_workspace(tmp_path / "carol", "carol", executable="hello")
    assert build(tmp_path / "alice", builds, colcon).ok
    report = build(tmp_path / "carol", builds, colcon)
    assert report.ok and not report.reused and colcon.runs == 2
    assert run_executable(tmp_path / "carol" / "ros2_ws", "hello") == "written by carol"


def test_a_failed_build_is_not_kept_and_reuse_can_be_switched_off(tmp_path, monkeypatch):
    builds, colcon = caches.WorkspaceBuilds(tmp_path / "builds"), CountingColcon()
    broken = SETUP_PY.replace("name='greeter',", "name='greeter'(,")
    for student in ("dave", "erin"):
        write_workspace(tmp_path / student, student, setup_py=broken)
        report = build(tmp_path / student, builds, colcon)
        assert not report.ok and "colcon build failed in package 'greeter'" in report.reason
    assert colcon.runs == 2 and not any(builds.root.glob("*"))
    monkeypatch.setenv(contract.REUSE_BUILDS_ENV, "0")
    for student in ("frank", "grace"):
        write_workspace(tmp_path / student, student)
        assert build(tmp_path / student, builds, colcon).ok
    assert colcon.runs == 4 and not any(builds.root.glob("*"))
