"""course_lib.ros.package_files: a package's own files read without building or importing it."""

import ast
import xml.etree.ElementTree as ElementTree

import pytest

from course_lib.ros import package_files

PACKAGE_XML = """<?xml version="1.0"?>
<package format="3">
  <name>brightness</name>
  <version>0.1.0</version>
  <description>d</description>
  <maintainer email="a@b.c">a</maintainer>
  <license>Apache-2.0</license>
  <buildtool_depend>ament_python</buildtool_depend>
  <depend>rclpy</depend>
  <exec_depend>sensor_msgs</exec_depend>
  <build_depend>std_msgs</build_depend>
  <test_depend>ament_flake8</test_depend>
  <export><build_type>ament_python</build_type></export>
</package>
"""


def test_run_dependencies_are_depend_and_exec_depend_only(tmp_path):
    (tmp_path / "package.xml").write_text(PACKAGE_XML)
    assert package_files.run_dependencies(tmp_path / "package.xml") == {"rclpy", "sensor_msgs"}


def test_a_broken_package_xml_raises_parse_error(tmp_path):
    (tmp_path / "package.xml").write_text(PACKAGE_XML.replace("</package>", ""))
    with pytest.raises(ElementTree.ParseError):
        package_files.run_dependencies(tmp_path / "package.xml")


def test_imported_modules_gives_top_level_names_and_first_lines():
    tree = ast.parse("import numpy as np\nfrom std_msgs.msg import UInt8\nfrom . import local\nimport numpy.linalg\n")
    assert package_files.imported_modules(tree) == {"numpy": 1, "std_msgs": 2}


def test_package_imports_skip_tests_setup_and_files_that_do_not_parse(tmp_path):
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "node.py").write_text("import rclpy\nfrom sensor_msgs.msg import Image\n")
    (tmp_path / "pkg" / "broken.py").write_text("import cv2\ndef (:\n")
    (tmp_path / "test").mkdir()
    (tmp_path / "test" / "test_x.py").write_text("import pytest\n")
    (tmp_path / "setup.py").write_text("from setuptools import setup\n")
    assert package_files.package_imports(tmp_path) == {"rclpy": "pkg/node.py", "sensor_msgs": "pkg/node.py"}


def test_console_scripts_reads_entries_wherever_setup_builds_its_list(tmp_path):
    (tmp_path / "setup.py").write_text(
        "from setuptools import setup\nSCRIPTS = ['talker = demo.talker:main']\n"
        "setup(name='demo', entry_points={'console_scripts': SCRIPTS + ['listener=demo.listener:main']})\n")
    assert package_files.console_scripts(tmp_path / "setup.py") == {"talker": "demo.talker:main",
                                                                    "listener": "demo.listener:main"}


def test_dependencies_of_chosen_tags(tmp_path):
    (tmp_path / "package.xml").write_text(PACKAGE_XML)
    assert package_files.dependencies(tmp_path / "package.xml") == {"rclpy", "sensor_msgs", "std_msgs"}
    assert package_files.dependencies(tmp_path / "package.xml", ("test_depend",)) == {"ament_flake8"}


def test_built_console_scripts_are_read_from_the_newest_egg_info_of_the_build(tmp_path):
    """--symlink-install keeps the egg-info in build/, a copying build in install/; the last build's counts."""
    import os

    assert package_files.built_console_scripts(tmp_path, "pkg") is None
    symlinked = tmp_path / "build/pkg/pkg.egg-info/entry_points.txt"
    symlinked.parent.mkdir(parents=True)
    symlinked.write_text("[console_scripts]\nTalker = pkg.talker:main\nlistener = pkg.listener:main\n")
    assert package_files.built_console_scripts(tmp_path, "pkg") == {"Talker": "pkg.talker:main",
                                                                    "listener": "pkg.listener:main"}
    copied = tmp_path / "install/pkg/lib/python3.11/site-packages/pkg-0.0.0-py3.11.egg-info/entry_points.txt"
    copied.parent.mkdir(parents=True)
    copied.write_text("[console_scripts]\ntalker = pkg.talker:main\n")
    os.utime(symlinked, (1, 1))
    assert package_files.built_console_scripts(tmp_path, "pkg") == {"talker": "pkg.talker:main"}
