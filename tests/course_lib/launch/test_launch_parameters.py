"""course_lib.launch's node parameters without processes: how ``<param>`` values are typed, named
and handed to the node, in XML and YAML, against launch_ros's own expectations.

Each launch file is run into the command line of its node (actions.run_launch_file); the
parameter files it passes (--params-file) are read back, as the node would read them.
"""

import os

import pytest
from support.launch_demo import BOTH, params_of, write

from course_lib.launch.actions import run_launch_file
from course_lib.launch.entities import LaunchFileError

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


# --- value-sep and type, as launch_ros's own front-end test holds them ---------------------------

# test_launch_ros/test/test_launch_ros/frontend/test_node_frontend.py (Jazzy), the parameters of its
# talker in test_launch_frontend_xml and test_launch_frontend_yaml; its check_launch_node asserts
# the values below (param_group1.param3 == [2, 5, 8], ..., param15 == ['2', '5', '8']).
FRONTEND_XML = r"""
    <launch>
        <let name="a_string" value="\'[2, 5, 8]\'"/>
        <let name="a_list" value="[2, 5, 8]"/>
        <let name="my_value" value="100"/>
        <node pkg="demo" exec="talker">
            <param name="param1" value="ads"/>
            <param name="param_group1">
                <param name="param_group2">
                    <param name="param2" value="2"/>
                </param>
                <param name="param3" value="2, 5, 8" value-sep=", "/>
                <param name="param4" value="$(var a_list)"/>
                <param name="param5" value="$(var a_string)"/>
                <param name="param6" value="2., 5., 8." value-sep=", "/>
                <param name="param7" value="'2', '5', '8'" value-sep=", "/>
                <param name="param8" value="&quot;'2'&quot;, &quot;'5'&quot;, &quot;'8'&quot;" value-sep=", "/>
                <param name="param9" value="\'2\', \'5\', \'8\'" value-sep=", "/>
                <param name="param10" value="&quot;'asd'&quot;, &quot;'bsd'&quot;, &quot;'csd'&quot;" value-sep=", "/>
                <param name="param11" value="'\asd', '\bsd', '\csd'" value-sep=", "/>
                <param name="param12" value="''"/>
                <param name="param13" value="$(var my_value)" type="str"/>
                <param name="param14" value="'2', '5', '8'" value-sep=", " type="list_of_str"/>
                <param name="param15" value="2, 5, 8" value-sep=", " type="list_of_str"/>
            </param>
        </node>
    </launch>"""

FRONTEND_YAML = r"""
    launch:
        - let: {name: 'a_string', value: "'[2, 5, 8]'"}
        - let: {name: 'a_list', value: '[2, 5, 8]'}
        - let: {name: 'my_value', value: '100'}
        - node:
            pkg: demo
            exec: talker
            param:
                -   name: param1
                    value: ads
                -   name: param_group1
                    param:
                    -   name: param_group2
                        param:
                        -   name: param2
                            value: 2
                    -   {name: param3, value: [2, 5, 8]}
                    -   {name: param4, value: $(var a_list)}
                    -   {name: param5, value: $(var a_string)}
                    -   {name: param6, value: [2., 5., 8.]}
                    -   {name: param7, value: ['2', '5', '8']}
                    -   {name: param8, value: ["'2'", "'5'", "'8'"]}
                    -   {name: param9, value: ["\\'2\\'", "\\'5\\'", "\\'8\\'"]}
                    -   {name: param10, value: ["'asd'", "'bsd'", "'csd'"]}
                    -   {name: param11, value: ['\asd', '\bsd', '\csd']}
                    -   {name: param12, value: ''}
                    -   {name: param13, value: '$(var my_value)', type: str}
                    -   {name: param14, value: ["'2'", "'5'", "'8'"], type: list_of_str}
                    -   {name: param15, value: ['2', '5', '8'], type: list_of_str}
    """


@BOTH
def test_value_sep_and_type_give_the_values_launch_ros_s_frontend_test_expects(tmp_path, demo_prefix, form):
    """launch_ros's test_node_frontend.py: the same file in XML and YAML gives these values."""
    path = write(tmp_path, form, FRONTEND_XML, FRONTEND_YAML)
    node, = run_launch_file(path).processes
    first, group = [file["/**"]["ros__parameters"] for file in params_of(node.command)]
    assert first == {"param1": "ads"}
    assert group == {
        "param_group1.param_group2.param2": 2, "param_group1.param3": [2, 5, 8], "param_group1.param4": [2, 5, 8],
        "param_group1.param5": "[2, 5, 8]", "param_group1.param6": [2.0, 5.0, 8.0],
        "param_group1.param7": ["2", "5", "8"], "param_group1.param8": ["'2'", "'5'", "'8'"],
        "param_group1.param9": ["'2'", "'5'", "'8'"], "param_group1.param10": ["'asd'", "'bsd'", "'csd'"],
        "param_group1.param11": ["asd", "bsd", "csd"], "param_group1.param12": "", "param_group1.param13": "100",
        "param_group1.param14": ["'2'", "'5'", "'8'"], "param_group1.param15": ["2", "5", "8"]}
    assert type(group["param_group1.param6"][0]) is float


def test_type_names_the_type_a_text_takes(tmp_path, demo_prefix):
    """launch/frontend/type_utils.py's names; a substitution's result takes the type too."""
    path = write(tmp_path, "xml", """
        <launch>
          <arg name="n" default="7"/>
          <node pkg="demo" exec="talker">
            <param name="text" value="5" type="str"/>
            <param name="real" value="5" type="float"/>
            <param name="flag" value="1" type="bool"/>
            <param name="reals" value="1;2.5" value-sep=";" type="list_of_float"/>
            <param name="flags" value="true,0" value-sep="," type="list_of_bool"/>
            <param name="ints" value="[1, 2]" type="list_of_int"/>
            <param name="as_yaml" value="5" type="yaml"/>
            <param name="n_real" value="$(var n)" type="float"/>
            <param name="n_text" value="$(var n)" type="str"/>
            <param name="n_ints" value="$(var n),2" value-sep="," type="list_of_int"/>
          </node>
        </launch>""", "")
    node, = run_launch_file(path).processes
    values = {name: value for file in params_of(node.command) for name, value in file["/**"]["ros__parameters"].items()}
    assert values == {"text": "5", "real": 5.0, "flag": True, "reals": [1.0, 2.5], "flags": [True, False],
                      "ints": [1, 2], "as_yaml": 5, "n_real": 7.0, "n_text": "7", "n_ints": [7, 2]}
    assert type(values["real"]) is float and type(values["n_real"]) is float


@pytest.mark.parametrize("form, param, message", [
    # launch/frontend/type_utils.py, launch/utilities/type_utils.py (coerce_to_type, coerce_list,
    # normalize_typed_substitution), launch_xml's and launch_yaml's entity.py (get_attr), and
    # launch/frontend/parse_substitution.py (parse_if_substitutions): their words.
    ("xml", '<param name="p" value="1" type="float64"/>', "Got invalid type identifier 'float64'"),
    ("xml", '<param name="p" value="1,a" value-sep=","/>', "The result is a non-uniform list"),
    ("xml", '<param name="p" value="1,2.5" value-sep=","/>',
     "Attribute 'value' of Entity 'param' expected to be of type 'None'.'['1', '2.5']' can not be converted "
     "to one of those types"),
    ("xml", '<param name="p" value="[1, 2.5]"/>',
     "Attribute 'value' of Entity 'param' expected to be of type 'None'.'[1, 2.5]' can not be converted"),
    ("xml", '<param name="p" value="abc" type="int"/>', "value='abc' is not an instance of <class 'int'>"),
    ("xml", '<param name="p" value="1,2" value-sep="," type="int"/>',
     "Cannot convert input '['1', '2']' of type '<class 'list'>' to '<class 'int'>'"),
    ("xml", '<param name="p" type="int"><param name="q" value="1"/></param>',
     "nested parameters and type attributes are mutually exclusive"),
    ("yaml", "{name: p, value: 5, type: str}",
     "Attribute 'value' of Entity 'param' expected to be of type '<class 'str'>', got '<class 'int'>'"),
    ("yaml", '{name: p, value: "5", type: int}', "value='5' is not an instance of <class 'int'>"),
    ("yaml", "{name: p, value: [1, a]}", "The result is a non-uniform list"),
    ("yaml", '{name: p, value: "1,2", value-sep: ","}', r"Unexpected key(s) found in `param`: {'value-sep'}"),
])
def test_values_that_do_not_fit_their_type_get_launch_s_words(tmp_path, demo_prefix, form, param, message):
    path = write(tmp_path, form, f'<launch>\n<node pkg="demo" exec="talker">\n  {param}\n</node>\n</launch>',
                 f"launch:\n- node:\n    pkg: demo\n    exec: talker\n    param:\n    - {param}\n")
    with pytest.raises(LaunchFileError) as error:
        run_launch_file(path)
    assert error.value.message == message or error.value.message.startswith(message)
    assert error.value.line == (3 if form == "xml" else 6)


def test_a_substitution_that_does_not_fit_its_type_fails_when_the_node_starts(tmp_path, demo_prefix):
    """launch's coerce_to_type: int() and float() say what they could not read."""
    path = write(tmp_path, "xml", """
        <launch>
          <arg name="n" default="seven"/>
          <node pkg="demo" exec="talker"><param name="p" value="$(var n)" type="int"/></node>
        </launch>""", "")
    with pytest.raises(LaunchFileError) as error:
        run_launch_file(path)
    assert (error.value.message, error.value.line) == ("invalid literal for int() with base 10: 'seven'", 3)
    assert run_launch_file(path, {"n": "8"}).processes  # the same file with a number is fine
