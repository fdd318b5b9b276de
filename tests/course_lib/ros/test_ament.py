"""course_lib.ros.ament: packages, prefixes and executables from the ament index."""

import os

import pytest

from course_lib.ros import ament


def test_installed_message_packages_are_listed_with_their_prefix():
    found = ament.packages()
    assert "std_msgs" in found and "sensor_msgs" in found
    assert (found["std_msgs"] / "share" / "std_msgs" / "package.xml").is_file()


def test_share_is_below_the_prefix():
    assert ament.share("std_msgs") == ament.prefix("std_msgs") / "share" / "std_msgs"


def test_unknown_package_names_the_fix():
    with pytest.raises(LookupError, match="source install/setup.bash"):
        ament.prefix("no_such_package_xyz")


def test_executable_of_a_built_workspace(tmp_path, monkeypatch):
    lib = tmp_path / "lib" / "demo"
    lib.mkdir(parents=True)
    (tmp_path / "share" / "ament_index" / "resource_index" / "packages").mkdir(parents=True)
    (tmp_path / "share" / "ament_index" / "resource_index" / "packages" / "demo").write_text("")
    (lib / "talker").write_text("#!/bin/sh\n")
    (lib / "talker").chmod(0o755)
    (lib / "notes.txt").write_text("not executable")
    monkeypatch.setenv("AMENT_PREFIX_PATH", f"{tmp_path}:" + os.environ["AMENT_PREFIX_PATH"])
    assert ament.executables("demo") == ["talker"]
    assert ament.executable("demo", "talker") == lib / "talker"
    with pytest.raises(LookupError, match="it has: talker"):
        ament.executable("demo", "listener")
