"""Tests for course_lib.rosenv: install detection, child environments, domain reservations."""

import os
import subprocess
import sys

import pytest

from course_lib import rosenv


def test_pip_wheels_are_detected_in_the_project_environment():
    install = rosenv.detect_install()
    assert install.kind == "pip", install
    assert install.rclpy_path is not None and install.rclpy_path.name == "rclpy"
    assert any((p / "share/ament_index/resource_index/packages/rclpy").exists() for p in install.prefixes)


def test_child_environment_is_isolated_and_finds_the_ament_index():
    env = rosenv.ros_environment(domain_id=42, base={"PATH": "/usr/bin", "ROS_LOCALHOST_ONLY": "1"})
    assert env["ROS_DOMAIN_ID"] == "42"
    assert env["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "LOCALHOST"
    assert "ROS_LOCALHOST_ONLY" not in env
    assert sys.prefix in env["AMENT_PREFIX_PATH"].split(os.pathsep)
    assert env["PATH"].split(os.pathsep)[0] == os.path.dirname(sys.executable)


@pytest.mark.parametrize("bad", [-1, 233, 1000, "7"])
def test_out_of_range_domain_ids_are_refused_with_the_range(bad):
    with pytest.raises(ValueError, match="0 to 232"):
        rosenv.ros_environment(domain_id=bad)


def test_reservations_are_exclusive_across_processes():
    with rosenv.reserve_domain_id() as mine:
        code = ("from course_lib import rosenv; r = rosenv.reserve_domain_id(range(%d, %d)); print(r.domain_id)"
                % (mine.domain_id, mine.domain_id + 1))
        other = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
        assert other.returncode != 0 and "reserved by other processes" in other.stderr
    # Released: now another process can take it.
    other = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert other.stdout.strip() == str(mine.domain_id), other.stderr


def test_modes_are_separate_flags(monkeypatch):
    monkeypatch.setenv("COURSE_LIB_UNDER_TEST", "1")
    monkeypatch.delenv("COURSE_LIB_GRADING", raising=False)
    assert rosenv.under_test() and not rosenv.under_grading()
    monkeypatch.setenv("COURSE_LIB_UNDER_TEST", "0")
    monkeypatch.setenv("COURSE_LIB_GRADING", "1")
    assert rosenv.under_grading() and not rosenv.under_test()
