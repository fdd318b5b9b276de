"""Tests for course_lib.selfcheck.launch_exercise: lesson 02b's launch file in YAML."""

import pytest
from support import lesson_answers

from course_lib import selfcheck

LAUNCH_NODE = """\
- node:
    pkg: image_stats
    exec: {}
    output: screen
    param:
    - {{from: $(find-pkg-share image_stats)/config/dark_fraction.yaml}}
    remap:
    - {{from: image, to: /camera/image_raw}}
"""
LAUNCH_YAML = "launch:\n" + LAUNCH_NODE.format("camera") + LAUNCH_NODE.format("dark_fraction")


@pytest.fixture
def image_stats_launch(tmp_path, monkeypatch):
    """The lesson's XML launch file, and image_stats installed (ament index, executables, share files)."""
    import os

    from support.launch_demo import make_prefix

    params = lesson_answers.lesson_file("02b_packages_launch_parameters.ipynb", "config/dark_fraction.yaml")
    prefix = make_prefix(tmp_path / "install", "image_stats", {"camera": "#!/bin/sh\n", "dark_fraction": "#!/bin/sh\n"},
                         {"config/dark_fraction.yaml": params})
    monkeypatch.setenv("AMENT_PREFIX_PATH", f"{prefix}{os.pathsep}{os.environ.get('AMENT_PREFIX_PATH', '')}")
    xml = tmp_path / "dark.launch.xml"
    xml.write_text(lesson_answers.lesson_file("02b_packages_launch_parameters.ipynb", "launch/dark.launch.xml"))
    return xml


@pytest.mark.parametrize("answer, expected", [
    (lesson_answers.lesson_file("02b_packages_launch_parameters.ipynb", "launch/dark.launch.yaml"), "Not done yet"),
    (LAUNCH_YAML.replace("    remap:\n    - {from: image, to: /camera/image_raw}\n", "", 1),
     "remaps are none, the XML file gives image:=/camera/image_raw"),
    (LAUNCH_YAML.replace("    output: screen\n", "", 1), "output is 'log'"),
    (LAUNCH_YAML.replace("exec: dark_fraction", "exec: camera"), "Node 2 runs image_stats/camera"),
    (LAUNCH_YAML.replace("remap:\n    - {from", "remap:\n      {from"), "cannot run"),
    (LAUNCH_YAML, "✔"),
])
def test_launch_yaml_check_fails_the_stub_and_wrong_files_and_passes_the_xml_twin(image_stats_launch, tmp_path,
                                                                                   answer, expected):
    yaml_file = tmp_path / "dark.launch.yaml"
    yaml_file.write_text(answer)
    verdict = selfcheck.task_launch_yaml(yaml_file, image_stats_launch)
    assert bool(verdict) == (expected == "✔") and expected in str(verdict), str(verdict)


SHARED_PARAMS = "$(find-pkg-share image_stats)/config/dark_fraction.yaml"


@pytest.mark.parametrize("given, expected", [
    ("config/dark_fraction.yaml", "parameter files are {cwd}/config/dark_fraction.yaml, the XML file gives "
                                  f"{SHARED_PARAMS}: $(find-pkg-share) finds the installed file"),
    ("dark_fraction.yaml", f"names the parameter file {{cwd}}/dark_fraction.yaml, which is no file (ros2 launch "
                           f"warns and starts the node without it). The XML file names {SHARED_PARAMS}"),
])
def test_launch_yaml_check_names_a_relative_parameter_file_and_find_pkg_share(image_stats_launch, tmp_path,
                                                                               monkeypatch, given, expected):
    """A relative path is relative to the folder ros2 launch runs in: the verdict names the file it
    found (or did not find) and the XML file's $(find-pkg-share ...), not parameter files' YAML."""
    cwd = tmp_path / "notebooks"
    (cwd / "config").mkdir(parents=True)
    (cwd / "config" / "dark_fraction.yaml").write_text(
        lesson_answers.lesson_file("02b_packages_launch_parameters.ipynb", "config/dark_fraction.yaml"))
    monkeypatch.chdir(cwd)
    yaml_file = tmp_path / "dark.launch.yaml"
    yaml_file.write_text(LAUNCH_YAML.replace(SHARED_PARAMS, given))
    verdict = str(selfcheck.task_launch_yaml(yaml_file, image_stats_launch))
    assert expected.format(cwd=cwd) in verdict and "\\n" not in verdict and "ros__parameters" not in verdict, verdict


def test_launch_yaml_check_shows_inline_parameters_on_one_line(image_stats_launch, tmp_path):
    yaml_file = tmp_path / "dark.launch.yaml"
    yaml_file.write_text(LAUNCH_YAML.replace("    - {from: " + SHARED_PARAMS + "}",
                                             "    - {name: rate, value: 5.0}", 1))
    verdict = str(selfcheck.task_launch_yaml(yaml_file, image_stats_launch))
    assert "parameter files are parameters {/**: {ros__parameters: {rate: 5.0}}}, the XML file gives " \
           f"{SHARED_PARAMS}" in verdict and "\n" not in verdict, verdict


