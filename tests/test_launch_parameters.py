"""course_lib.launch's node parameters without processes: how ``<param>`` values are typed, named
and handed to the node, in XML and YAML, against launch_ros's own expectations.

Each launch file is run into the command line of its node (actions.run_launch_file); the
parameter files it passes (--params-file) are read back, as the node would read them.
"""

import os

import pytest

from course_lib.launch.actions import run_launch_file
from launch_demo import BOTH, params_of, write

pytestmark = pytest.mark.usefixtures("launch_files_in_tmp_path")


def test_xml_param_values_are_typed_by_yaml_rules(tmp_path, demo_prefix):
    path = write(tmp_path, "xml", """
        <launch>
          <arg name="count" default="7"/>
          <node pkg="demo" exec="talker" name="talker" namespace="robot">
            <param name="an_int" value="5"/>
            <param name="a_float" value="5.0"/>
            <param name="a_bool" value="true"/>
            <param name="a_list" value="[1, 2, 3]"/>
            <param name="words" value="a;b" value-sep=";"/>
            <param name="a_text" value="hello world"/>
            <param name="quoted" value="'5'"/>
            <param name="empty" value=""/>
            <param name="from_arg" value="$(var count)"/>
            <param name="text_with_arg" value="n$(var count)"/>
          </node>
        </launch>""", "")
    node, = run_launch_file(path).processes
    files = params_of(node.command)
    assert all(list(file) == ["/robot/talker"] for file in files)  # one file per tag, keyed by full name
    values = {name: value for file in files for name, value in file["/robot/talker"]["ros__parameters"].items()}
    assert values == {"an_int": 5, "a_float": 5.0, "a_bool": True, "a_list": [1, 2, 3], "words": ["a", "b"],
                      "a_text": "hello world", "quoted": "5", "empty": "", "from_arg": 7, "text_with_arg": "n7"}
    assert type(values["a_float"]) is float and type(values["a_bool"]) is bool


def test_yaml_param_values_keep_their_yaml_types(tmp_path, demo_prefix):
    """In YAML, value: "5" is text; a substitution's result is typed by YAML's rules."""
    path = write(tmp_path, "yaml", "", """
        launch:
        - arg: {name: count, default: "7"}
        - node:
            pkg: demo
            exec: talker
            param:
            - {name: an_int, value: 5}
            - {name: text_five, value: "5"}
            - {name: floats, value: [1.5, 2.5]}
            - {name: from_arg, value: $(var count)}
        """)
    node, = run_launch_file(path).processes
    files = params_of(node.command)
    assert all(list(file) == ["/**"] for file in files)  # no name given: every node's parameters
    values = {name: value for file in files for name, value in file["/**"]["ros__parameters"].items()}
    assert values == {"an_int": 5, "text_five": "5", "floats": [1.5, 2.5], "from_arg": 7}


@BOTH
def test_nested_params_get_dotted_names(tmp_path, demo_prefix, form):
    path = write(tmp_path, form, """
        <launch>
          <node pkg="demo" exec="talker" name="cam">
            <param name="camera">
              <param name="size"><param name="width" value="640"/></param>
              <param name="name" value="front"/>
            </param>
          </node>
        </launch>""", """
        launch:
        - node:
            pkg: demo
            exec: talker
            name: cam
            param:
            - name: camera
              param:
              - {name: size, param: [{name: width, value: 640}]}
              - {name: name, value: front}
        """)
    node, = run_launch_file(path).processes
    assert params_of(node.command) == [{"/**": {"ros__parameters": {"camera.size.width": 640,
                                                                   "camera.name": "front"}}}]


@BOTH
def test_param_from_a_file_is_passed_as_it_is(tmp_path, demo_prefix, form):
    path = write(tmp_path, form, """
        <launch>
          <node pkg="demo" exec="talker">
            <param from="$(find-pkg-share demo)/config/params.yaml"/>
            <param name="gain" value="3"/>
          </node>
        </launch>""", """
        launch:
        - node:
            pkg: demo
            exec: talker
            param:
            - {from: $(find-pkg-share demo)/config/params.yaml}
            - {name: gain, value: 3}
        """)
    node, = run_launch_file(path).processes
    first = node.command.index("--params-file")
    assert node.command[first + 1] == str(demo_prefix / "share" / "demo" / "config" / "params.yaml")
    assert params_of(node.command)[-1] == {"/**": {"ros__parameters": {"gain": 3}}}  # later files win


def test_a_missing_parameter_file_is_warned_about_and_skipped(tmp_path, demo_prefix):
    """As launch_ros does: a warning, and the node starts without it."""
    path = write(tmp_path, "xml", '<launch><node pkg="demo" exec="talker"><param from="nope.yaml"/></node></launch>',
                 "")
    context = run_launch_file(path)
    assert "--params-file" not in context.processes[0].command
    assert context.warnings == [("launch_ros.actions.node",
                                 f"Parameter file path is not a file: {os.path.abspath('nope.yaml')}")]


def test_allow_substs_performs_substitutions_in_the_parameter_file(tmp_path, demo_prefix):
    (tmp_path / "p.yaml").write_text("/**:\n  ros__parameters:\n    who: $(var who)\n")
    path = write(tmp_path, "xml", """
        <launch>
          <arg name="who" default="me"/>
          <node pkg="demo" exec="talker"><param from="$(dirname)/p.yaml" allow_substs="true"/></node>
        </launch>""", "")
    assert params_of(run_launch_file(path).processes[0].command) == [{"/**": {"ros__parameters": {"who": "me"}}}]

