"""course_lib/checks/packages.py: what the checks read from a student's packages without building
them: package.xml against the code's imports, and a .msg file against the contract."""

from __future__ import annotations

from pathlib import Path

import pytest

from course_lib import contract
from course_lib.checks import context, packages
from course_lib.checks.context import StudentError


class Recorder:
    """The part of context.Context these functions use: the work directory and the items."""

    def __init__(self, workdir: Path):
        self.workdir = workdir
        self.items: list[dict] = []

    def item(self, ok, message, weight=1.0):
        self.items.append({"ok": bool(ok), "message": message, "weight": weight})
        return bool(ok)

    workspace_dir = context.Context.workspace_dir
    package_dir = context.Context.package_dir


def write_package(workdir: Path, depends: list[str], code: str) -> Path:
    folder = workdir / "ros2_ws" / "src" / "brightness"
    (folder / "brightness").mkdir(parents=True)
    tags = "".join(f"<depend>{d}</depend>" for d in depends)
    (folder / "package.xml").write_text(f'<package format="3"><name>brightness</name>{tags}</package>')
    (folder / "brightness" / "brightness_node.py").write_text(code)
    (folder / "setup.py").write_text("import setuptools\n")  # not the package's code
    return folder


CODE = "import numpy as np\nimport rclpy\nfrom sensor_msgs.msg import Image\nfrom std_msgs.msg import UInt8\n"


def test_a_missing_depend_costs_an_item_that_names_the_file_and_the_fix(tmp_path):
    ctx = Recorder(tmp_path)
    write_package(tmp_path, ["rclpy", "std_msgs"], CODE)
    packages.dependency_items(ctx, "brightness")
    (item,) = ctx.items
    assert not item["ok"] and item["weight"] == 1.0
    assert "brightness/brightness_node.py imports sensor_msgs" in item["message"]
    assert "add <depend>sensor_msgs</depend>" in item["message"]
    assert "numpy" not in item["message"]  # not a ROS package: no <depend> asked for


def test_declared_dependencies_earn_nothing_by_themselves(tmp_path):
    """Right is the release's state already: the item passes with weight 0 (an untouched release scores 0)."""
    ctx = Recorder(tmp_path)
    write_package(tmp_path, ["rclpy", "sensor_msgs"], CODE.replace("std_msgs", "sensor_msgs"))
    packages.dependency_items(ctx, "brightness")
    assert ctx.items == [{"ok": True, "weight": 0.0,
                          "message": "brightness/package.xml declares every ROS package its code imports"}]


def test_exec_depend_counts_and_workspace_packages_are_ros_packages(tmp_path):
    ctx = Recorder(tmp_path)
    folder = write_package(tmp_path, ["rclpy", "sensor_msgs"],
                           CODE + "from tutorial_interfaces.msg import MsgTutorial\n")
    (folder / "package.xml").write_text(folder.joinpath("package.xml").read_text().replace(
        "</package>", "<exec_depend>std_msgs</exec_depend></package>"))
    other = tmp_path / "ros2_ws" / "src" / "tutorial_interfaces"
    other.mkdir()
    (other / "package.xml").write_text("<package><name>tutorial_interfaces</name></package>")
    packages.dependency_items(ctx, "brightness")
    assert "imports tutorial_interfaces" in ctx.items[0]["message"] and "std_msgs" not in ctx.items[0]["message"]


def test_message_fields_read_like_rosidl(tmp_path):
    msg = tmp_path / "CroppedPicture.msg"
    msg.write_text("# which picture\nint32 CAT=1\nint32 DOG = 2\nint32 picture  # 1 or 2\n\n"
                   "sensor_msgs/msg/CompressedImage image\n")
    assert packages.message_fields(msg) == [("int32", "picture"), ("sensor_msgs/msg/CompressedImage", "image")]


@pytest.mark.parametrize("definition, ok", [("builtin_interfaces/Time stamp\nint32 data\n", True),
                                            ("builtin_interfaces/msg/Time stamp\nint32 data\n", True),
                                            ("builtin_interfaces/Time stamp\nint64 data\n", False),
                                            ("int32 data\nbuiltin_interfaces/Time stamp\n", False)])
def test_a_message_with_other_fields_costs_an_item(tmp_path, definition, ok):
    ctx = Recorder(tmp_path)
    folder = tmp_path / "ros2_ws" / "src" / "tutorial_interfaces" / "msg"
    folder.mkdir(parents=True)
    (folder / "MsgTutorial.msg").write_text(definition)
    expected = [("builtin_interfaces/Time", "stamp"), ("int32", "data")]
    assert packages.message_item(ctx, "tutorial_interfaces", "MsgTutorial", expected) is ok
    assert ctx.items[0]["weight"] == (0.0 if ok else 1.0)
    if not ok:
        assert "the contract says builtin_interfaces/Time stamp, int32 data" in ctx.items[0]["message"]


def test_an_unbuilt_workspace_says_to_run_the_build_cell(tmp_path, monkeypatch):
    monkeypatch.delenv(contract.BUILD_REPORT_ENV, raising=False)
    with pytest.raises(StudentError, match="run the notebook's build cell"):
        packages.require_build(Recorder(tmp_path))


def test_a_failed_grader_build_is_the_reason_of_every_check_that_needs_it(tmp_path, monkeypatch):
    report = tmp_path / "build.json"
    report.write_text('{"ok": false, "reason": "colcon build failed in package \'pubsub\':\\nSyntaxError: x", '
                      '"workspace": "/nowhere"}')
    monkeypatch.setenv(contract.BUILD_REPORT_ENV, str(report))
    with pytest.raises(StudentError, match="(?s)did not build.*SyntaxError: x"):
        packages.require_build(Recorder(tmp_path))


def test_the_ament_index_is_read_once_until_a_package_is_installed_or_the_path_changes(tmp_path, monkeypatch):
    from course_lib.ros import ament

    index = tmp_path / "prefix" / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    (index / "first_pkg").write_text("")
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(tmp_path / "prefix"))
    reads = []
    monkeypatch.setattr(ament, "packages", lambda real=ament.packages: reads.append(1) or real())
    ctx = Recorder(tmp_path)
    assert "first_pkg" in packages.ros_packages(ctx) and "first_pkg" in packages.ros_packages(ctx)
    assert len(reads) == 1
    (index / "second_pkg").write_text("")
    assert "second_pkg" in packages.ros_packages(ctx) and len(reads) == 2
    monkeypatch.setenv("AMENT_PREFIX_PATH", f"{tmp_path / 'prefix'}:{tmp_path / 'other'}")
    packages.ros_packages(ctx)
    assert len(reads) == 3
