"""course_lib.launch without processes: the tags of XML and YAML launch files, and each error.

A launch file is run into the processes it would start (actions.run_launch_file), and their
command lines and environments are compared with what ros2/launch and launch_ros produce. The
package `demo` lives in a temporary prefix with an ament index marker (the demo_prefix fixture).
Parameters are in test_launch_parameters.py, substitutions in test_launch_substitutions.py.
"""

import os
import re
import textwrap

import pytest
from support.launch_demo import BOTH, write

from course_lib.launch import cli, substitutions
from course_lib.launch.actions import run_launch_file
from course_lib.launch.entities import LaunchFileError
from course_lib.launch.parser import split_command_line

pytestmark = pytest.mark.usefixtures("launch_files_in_tmp_path")


# --- node ------------------------------------------------------------------------------------

@BOTH
def test_node_gets_the_command_line_launch_ros_builds(tmp_path, demo_prefix, form):
    path = write(tmp_path, form, """
        <launch>
          <node pkg="demo" exec="talker" name="talker" namespace="robot" output="screen"
                args="first 'two words'" ros_args="--log-level debug">
            <remap from="chatter" to="talk"/>
            <remap from="/image" to="/camera/image_raw"/>
          </node>
        </launch>""", """
        launch:
        - node:
            pkg: demo
            exec: talker
            name: talker
            namespace: robot
            output: screen
            args: first 'two words'
            ros_args: --log-level debug
            remap:
            - {from: chatter, to: talk}
            - {from: /image, to: /camera/image_raw}
        """)
    node, = run_launch_file(path).processes
    assert node.command == [str(demo_prefix / "lib" / "demo" / "talker"), "first", "two words",
                            "--ros-args", "--log-level", "debug",
                            "--ros-args", "-r", "__node:=talker", "-r", "__ns:=/robot",
                            "-r", "chatter:=talk", "-r", "/image:=/camera/image_raw"]
    assert (node.label, node.output, node.node_name, node.namespace) == ("talker", "screen", "talker", "/robot")
    assert node.line == 2


@BOTH
def test_node_without_name_or_namespace_keeps_its_own(tmp_path, demo_prefix, form):
    """No __node or __ns rule; output defaults to log; exec_name sets the process label."""
    path = write(tmp_path, form, '<launch><node pkg="demo" exec="listener" exec_name="ears"/></launch>',
                 "launch:\n- node: {pkg: demo, exec: listener, exec_name: ears}")
    node, = run_launch_file(path).processes
    assert node.command == [str(demo_prefix / "lib" / "demo" / "listener"), "--ros-args"]
    assert (node.label, node.output, node.node_name, node.namespace) == ("ears", "log", None, None)


def test_node_without_pkg_runs_exec_as_a_command(tmp_path):
    path = write(tmp_path, "xml", '<launch><node exec="sleep" args="5"/></launch>', "")
    node, = run_launch_file(path).processes
    assert node.command == ["sleep", "5", "--ros-args"] and node.label == "sleep"


@BOTH
def test_node_environment_has_set_env_and_its_own_env_tags(tmp_path, demo_prefix, form):
    path = write(tmp_path, form, """
        <launch>
          <set_env name="COURSE_A" value="a"/>
          <node pkg="demo" exec="talker"><env name="COURSE_B" value="$(env COURSE_A)b"/></node>
          <node pkg="demo" exec="listener"/>
        </launch>""", """
        launch:
        - set_env: {name: COURSE_A, value: a}
        - node:
            pkg: demo
            exec: talker
            env: [{name: COURSE_B, value: $(env COURSE_A)b}]
        - node: {pkg: demo, exec: listener}
        """)
    talker, listener = run_launch_file(path, environment={"PATH": "/bin"}).processes
    assert talker.environment == {"PATH": "/bin", "COURSE_A": "a", "COURSE_B": "ab"}
    assert listener.environment == {"PATH": "/bin", "COURSE_A": "a"}
    assert "COURSE_A" not in os.environ  # the launch never changes this process's environment


def test_two_nodes_with_one_name_are_warned_about(tmp_path, demo_prefix):
    path = write(tmp_path, "xml", """
        <launch>
          <node pkg="demo" exec="talker" name="same" namespace="/a"/>
          <node pkg="demo" exec="listener" name="same" namespace="/a"/>
        </launch>""", "")
    context = run_launch_file(path)
    assert context.warnings == [("listener", "there are now at least 2 nodes with the name /a/same "
                                             "created within this launch context")]


# --- arg, let, include -------------------------------------------------------------------------

@BOTH
def test_arguments_take_defaults_command_line_values_and_let(tmp_path, demo_prefix, form):
    path = write(tmp_path, form, """
        <launch>
          <arg name="robot" default="r1" description="which robot"/>
          <arg name="rate" default="5"/>
          <let name="topic" value="$(var robot)/chatter"/>
          <node pkg="demo" exec="talker" name="$(var robot)_talker" args="$(var rate) $(var missing fallback)">
            <remap from="chatter" to="$(var topic)"/>
          </node>
        </launch>""", """
        launch:
        - arg: {name: robot, default: r1, description: which robot}
        - arg: {name: rate, default: "5"}
        - let: {name: topic, value: $(var robot)/chatter}
        - node:
            pkg: demo
            exec: talker
            name: $(var robot)_talker
            args: $(var rate) $(var missing fallback)
            remap: [{from: chatter, to: $(var topic)}]
        """)
    context = run_launch_file(path, {"robot": "r2"})
    assert context.configurations == {"robot": "r2", "rate": "5", "topic": "r2/chatter"}
    assert context.processes[0].command[1:] == ["5", "fallback", "--ros-args", "-r", "__node:=r2_talker",
                                            "-r", "chatter:=r2/chatter"]


@BOTH
def test_a_required_argument_that_is_not_given_is_named(tmp_path, form):
    path = write(tmp_path, form, '<launch>\n  <arg name="robot" description="which robot"/>\n</launch>',
                 "launch:\n- arg: {name: robot, description: which robot}")
    with pytest.raises(LaunchFileError, match=r"missing required argument 'robot' \(description: 'which robot'\)"
                                              r".*pass it as robot:=VALUE") as error:
        run_launch_file(path)
    assert error.value.line == 2 and error.value.file == path


@BOTH
def test_include_passes_its_args_and_what_it_sets_stays_set(tmp_path, demo_prefix, form):
    """As in Jazzy's IncludeLaunchDescription: the included file runs in the includer's scope."""
    write(tmp_path, form, """
        <launch>
          <arg name="who"/>
          <let name="set_inside" value="yes"/>
          <node pkg="demo" exec="talker" name="$(var who)"/>
        </launch>""", """
        launch:
        - arg: {name: who}
        - let: {name: set_inside, value: "yes"}
        - node: {pkg: demo, exec: talker, name: $(var who)}
        """, name="child")
    child = "child.launch.xml" if form == "xml" else "child.launch.yaml"
    path = write(tmp_path, form, f"""
        <launch>
          <include file="$(dirname)/{child}"><arg name="who" value="alice"/></include>
          <node pkg="demo" exec="listener" name="after_$(var set_inside)"/>
        </launch>""", f"""
        launch:
        - include:
            file: $(dirname)/{child}
            arg: [{{name: who, value: alice}}]
        - node: {{pkg: demo, exec: listener, name: after_$(var set_inside)}}
        """)
    assert [node.node_name for node in run_launch_file(path).processes] == ["alice", "after_yes"]


def test_an_include_without_a_required_argument_names_the_include(tmp_path, demo_prefix):
    """Like Jazzy: the check looks through includes, and an include must pass the argument itself."""
    write(tmp_path, "xml", '<launch>\n<arg name="who"/>\n</launch>', "", name="child")
    path = write(tmp_path, "xml", '<launch>\n  <include file="$(dirname)/child.launch.xml"/>\n</launch>', "")
    with pytest.raises(LaunchFileError, match=r"missing required argument 'who'.*pass it as who:=VALUE") as error:
        run_launch_file(path)
    assert (error.value.file.name, error.value.line) == ("child.launch.xml", 2)
    with pytest.raises(LaunchFileError, match=r"missing required argument 'who'.*add <arg name=\"who\" "
                                              r"value=\"...\"/> to the <include> at .*test.launch.xml:2"):
        run_launch_file(path, {"who": "me"})


# --- group, push_ros_namespace, set_env, conditions --------------------------------------------

@BOTH
def test_a_scoped_group_undoes_namespace_configurations_and_environment(tmp_path, demo_prefix, form):
    path = write(tmp_path, form, """
        <launch>
          <group>
            <push_ros_namespace namespace="robot"/>
            <push_ros_namespace namespace="arm"/>
            <let name="inside" value="1"/>
            <set_env name="COURSE_INSIDE" value="1"/>
            <node pkg="demo" exec="talker" name="a"/>
            <node pkg="demo" exec="talker" name="b" namespace="/absolute"/>
          </group>
          <group scoped="false">
            <push-ros-namespace namespace="/leaks"/>
          </group>
          <node pkg="demo" exec="listener" name="c" namespace="rel"/>
        </launch>""", """
        launch:
        - group:
          - push_ros_namespace: {namespace: robot}
          - push_ros_namespace: {namespace: arm}
          - let: {name: inside, value: "1"}
          - set_env: {name: COURSE_INSIDE, value: "1"}
          - node: {pkg: demo, exec: talker, name: a}
          - node: {pkg: demo, exec: talker, name: b, namespace: /absolute}
        - group:
            scoped: false
            children:
            - push-ros-namespace: {namespace: /leaks}
        - node: {pkg: demo, exec: listener, name: c, namespace: rel}
        """)
    context = run_launch_file(path, environment={})
    assert [(node.node_name, node.namespace) for node in context.processes] == [
        ("a", "/robot/arm"), ("b", "/absolute"), ("c", "/leaks/rel")]
    assert context.processes[0].environment == {"COURSE_INSIDE": "1"} and context.processes[2].environment == {}
    assert context.configurations == {"ros_namespace": "/leaks"}


@BOTH
def test_a_group_that_does_not_forward_keeps_only_what_it_keeps(tmp_path, demo_prefix, form):
    """launch_xml's and launch_yaml's test_group.py: inside <group scoped="True" forwarding="False">
    with <keep name="bar" value="$(var bar)"/> and <keep name="baz" value="BAZ"/>, 'foo' is gone,
    bar is 'BAR' and baz 'BAZ'. As GroupAction resets them, the pushed namespace and <set_env>
    do not reach inside either; after the group all is as before."""
    path = write(tmp_path, form, """
        <launch>
          <let name="foo" value="FOO"/>
          <let name="bar" value="BAR"/>
          <set_env name="COURSE_OUTSIDE" value="1"/>
          <push_ros_namespace namespace="robot"/>
          <group scoped="True" forwarding="False">
            <keep name="bar" value="$(var bar)"/>
            <keep name="baz" value="BAZ"/>
            <node pkg="demo" exec="talker" name="inside" args="$(var foo none) $(var bar) $(var baz)"/>
          </group>
          <group forwarding="true">
            <keep name="foo" value="kept_$(var foo)"/>
            <node pkg="demo" exec="talker" name="forwarded" args="$(var foo) $(var bar)"/>
          </group>
          <node pkg="demo" exec="talker" name="after" args="$(var foo) $(var baz none)"/>
        </launch>""", """
        launch:
        - let: {name: foo, value: FOO}
        - let: {name: bar, value: BAR}
        - set_env: {name: COURSE_OUTSIDE, value: "1"}
        - push_ros_namespace: {namespace: robot}
        - group:
            scoped: True
            forwarding: False
            keep:
            - {name: bar, value: $(var bar)}
            - {name: baz, value: BAZ}
            children:
            - node: {pkg: demo, exec: talker, name: inside, args: $(var foo none) $(var bar) $(var baz)}
        - group:
            forwarding: true
            keep: [{name: foo, value: kept_$(var foo)}]
            children:
            - node: {pkg: demo, exec: talker, name: forwarded, args: $(var foo) $(var bar)}
        - node: {pkg: demo, exec: talker, name: after, args: $(var foo) $(var baz none)}
        """)
    inside, forwarded, after = run_launch_file(path, environment={}).processes
    assert (inside.command[1:4], inside.namespace, inside.environment) == (["none", "BAR", "BAZ"], None, {})
    assert (forwarded.command[1:3], forwarded.namespace) == (["kept_FOO", "BAR"], "/robot")
    assert (after.command[1:3], after.namespace, after.environment) == (
        ["FOO", "none"], "/robot", {"COURSE_OUTSIDE": "1"})


@BOTH
def test_arg_choices_describe_and_check_the_value_as_launch_does(tmp_path, demo_prefix, form, capsys):
    """launch_xml's test_arg.py (test_arg_with_choices): the description becomes "something. Valid
    choices are: ['asd', 'bsd']"; launch's DeclareLaunchArgument refuses another value in its words
    (test_declare_launch_argument.py: 'Valid options are'), whether it is given or the default."""
    path = write(tmp_path, form, """
        <launch>
          <arg name="my_arg" default="asd" description="something">
            <choice value="asd"/>
            <choice value="bsd"/>
          </arg>
          <arg name="mode" default="fast">
            <choice value="slow"/>
          </arg>
        </launch>""", """
        launch:
        - arg:
            name: my_arg
            default: asd
            description: something
            choice: [{value: asd}, {value: bsd}]
        - arg:
            name: mode
            default: fast
            choice: [{value: slow}]
        """)
    assert run_launch_file(path, {"my_arg": "bsd", "mode": "slow"}).configurations == {"my_arg": "bsd", "mode": "slow"}
    with pytest.raises(LaunchFileError) as error:
        run_launch_file(path, {"my_arg": "csd", "mode": "slow"})
    assert (error.value.message, error.value.line) == (
        """Argument "my_arg" provided value "csd" is not valid. Valid options are: ['asd', 'bsd']""", 2)
    with pytest.raises(LaunchFileError, match=r"""Argument "mode" provided value "fast" is not valid. Valid options """
                                              r"""are: \['slow'\]$"""):
        run_launch_file(path)
    assert cli.main(["-s", str(path)]) == 0
    assert "        something. Valid choices are: ['asd', 'bsd']" in capsys.readouterr().out.splitlines()
    assert actions_description(path, "mode") == "One of: ['slow']"


def actions_description(path, name: str) -> str:
    from course_lib.launch import actions, parser

    declared = actions.declared_arguments(parser.load_description(path), None, path)
    return next(argument.description for argument, _, _ in declared if argument.name == name)


@BOTH
def test_if_and_unless_choose_what_runs(tmp_path, demo_prefix, form):
    path = write(tmp_path, form, """
        <launch>
          <arg name="with_listener" default="false"/>
          <node pkg="demo" exec="talker" unless="$(var with_listener)"/>
          <node pkg="demo" exec="listener" if="$(var with_listener)"/>
        </launch>""", """
        launch:
        - arg: {name: with_listener, default: "false"}
        - node: {pkg: demo, exec: talker, unless: $(var with_listener)}
        - node: {pkg: demo, exec: listener, if: $(var with_listener)}
        """)
    assert [node.label for node in run_launch_file(path).processes] == ["talker"]
    assert [node.label for node in run_launch_file(path, {"with_listener": "True"}).processes] == ["listener"]
    with pytest.raises(LaunchFileError, match="a condition must be true, false, 1 or 0"):
        run_launch_file(path, {"with_listener": "maybe"})


# --- command lines ----------------------------------------------------------------------------

@pytest.mark.parametrize("text, expected", [
    ("a b  c", ["a", "b", "c"]),
    ("--name 'two words'", ["--name", "two words"]),
    ("$(var x) $(var y)", ["X", "Y"]),
    ("pre_$(var x)_post last", ["pre_X_post", "last"]),
    ("first $(var x)/file more words", ["first", "X/file", "more", "words"]),
])
def test_args_split_like_launch_splits_command_lines(text, expected):
    class Values:
        configurations = {"x": "X", "y": "Y"}

    arguments = split_command_line(substitutions.parse(text))
    assert [substitutions.perform(argument, Values()) for argument in arguments] == expected


# --- errors that name the file and line ---------------------------------------------------------

@pytest.mark.parametrize("form, text, line, message", [
    ("xml", "<launch>\n  <timer period='1'/>\n</launch>",
     2, r"<timer> is not supported here \(a full ROS 2 install has it\); supported tags: node"),
    # launch's frontend/expose.py, launch_xml's and launch_yaml's entity.py; launch_xml's
    # test_arg.py (test_arg_wrong_attribute, test_arg_with_subtag) holds "`arg`" and "whats_this".
    ("yaml", "launch:\n- arg: {name: a}\n- nodes: {pkg: demo, exec: talker}",
     3, r"Unrecognized entity of the type: nodes \(did you mean 'node'\?\)$"),
    ("xml", "<launch>\n  <arg name='a' whats_this='hello' default='asd'/>\n</launch>",
     2, r"Unexpected attribute\(s\) found in `arg`: \{'whats_this'\}$"),
    ("xml", "<launch>\n  <arg name='a' default='asd'>\n    <whats_this/>\n  </arg>\n</launch>",
     3, r"Unexpected nested tag\(s\) found in `arg`: \{'whats_this'\}$"),
    ("yaml", "launch:\n- arg: {name: a, whats_this: hello}",
     2, r"Unexpected key\(s\) found in `arg`: \{'whats_this'\}$"),
    ("xml", "<launch>\n  <node pkg='demo' exec='talker' respawn='true'/>\n</launch>",
     2, r"<node> attribute 'respawn' is not supported here; <node> supports: pkg, exec, name"),
    ("yaml", "launch:\n- node:\n    pkg: demo\n    exec: talker\n    namepsace: x",
     5, r"Unexpected key\(s\) found in `node`: \{'namepsace'\} \(did you mean 'namespace'\?\)$"),
    ("xml", "<launch>\n  <node pkg='demo' exec='talker'>\n    <parameter name='a' value='1'/>\n  </node>\n</launch>",
     3, r"Unexpected nested tag\(s\) found in `node`: \{'parameter'\} \(did you mean 'param'\?\)$"),
    ("xml", "<launch>\n  <arg name='a'>\n    <choice value='x' valeu='y'/>\n  </arg>\n</launch>",
     3, r"Unexpected attribute\(s\) found in `choice`: \{'valeu'\} \(did you mean 'value'\?\)$"),
    ("xml", "<launch>\n  <group>\n    <keep name='a'/>\n  </group>\n</launch>",
     3, "<keep> needs the attribute 'value'"),
    ("xml", "<launch>\n  <arg name='a' default='$(command ls)'/>\n</launch>",
     2, r"\$\(command\) is not supported here"),
    ("xml", "<launch>\n  <node pkg='demo'/>\n</launch>", 2, "<node> needs the attribute 'exec'"),
    ("xml", "<launch>\n  <node pkg='demo' exec='talker'\n</launch>", 3, "not well-formed XML"),
    ("yaml", "launch:\n- node: {pkg: demo, exec: [talker\n", 3, "not valid YAML"),
    ("yaml", "launch:\n- arg:\n    name: rate\n    default: 5", 4,
     r"'default' must be text; in YAML quote it: default: \"5\""),
    ("xml", "<launch>\n<node pkg='demo' exec='talker'><param name='a' from='x.yaml'/></node></launch>",
     2, "<param> has both name and from"),
    ("xml", "<launch>\n<node pkg='demo' exec='talker'><param name='a' value='1'><param name='b' value='2'/>"
            "</param></node></launch>", 2, "both value= and nested <param> tags"),
    ("xml", "<launch>\n<node pkg='demo' exec='talker' if='1' unless='0'/></launch>", 2, "both if and unless"),
    ("xml", "<group/>", 1, "the root tag must be <launch>"),
])
def test_errors_name_the_file_the_line_and_what_is_supported(tmp_path, demo_prefix, form, text, line, message):
    path = tmp_path / f"bad.launch.{form}"
    path.write_text(text)
    with pytest.raises(LaunchFileError, match=message) as error:
        run_launch_file(path)
    assert (error.value.file, error.value.line) == (path, line)
    assert str(error.value).startswith(f"{path}:{line}: ")


@pytest.mark.parametrize("node, message", [
    ('pkg="demo" exec="talker" name="my-node"', "the node name 'my-node' is invalid"),
    ('pkg="demo" exec="talker" namespace="1robot"', "the namespace '/1robot' of this node is invalid"),
    ('pkg="nope" exec="talker"', "Package 'nope' not found"),
    ('pkg="demo" exec="speaker"', "No executable 'speaker' found in package 'demo'; it has: listener, talker"),
    ('pkg="demo" exec="talker" output="own_log"', 'output="own_log" is not supported here; use screen, log or both'),
])
def test_bad_nodes_are_reported_at_their_line(tmp_path, demo_prefix, node, message):
    path = write(tmp_path, "xml", f"<launch>\n  <node {node}/>\n</launch>", "")
    with pytest.raises(LaunchFileError, match=message) as error:
        run_launch_file(path)
    assert error.value.line == 2


def test_python_launch_files_are_explained_not_run(tmp_path):
    path = tmp_path / "demo.launch.py"
    path.write_text("def generate_launch_description(): ...\n")
    with pytest.raises(LaunchFileError, match="Python launch files are not supported.*a full ROS 2 install runs them"):
        run_launch_file(path)


def test_a_file_with_another_ending_is_read_as_xml_or_yaml(tmp_path, demo_prefix):
    (tmp_path / "demo.launch").write_text("launch:\n- node: {pkg: demo, exec: talker}\n")
    assert [node.label for node in run_launch_file(tmp_path / "demo.launch").processes] == ["talker"]


# --- the command line without running nodes -----------------------------------------------------

def test_show_args_lists_arguments_like_ros2_launch(tmp_path, demo_prefix, capsys):
    write(tmp_path, "xml", '<launch><arg name="who" default="$(var robot)_x"/></launch>', "", name="child")
    path = write(tmp_path, "xml", """
        <launch>
          <arg name="robot" description="Which robot"/>
          <arg name="rate" default="5"/>
          <group if="true"><arg name="debug" default="false"/></group>
          <include file="$(dirname)/child.launch.xml"/>
        </launch>""", "")
    assert cli.main(["-s", str(path)]) == 0
    assert capsys.readouterr().out == textwrap.dedent("""\
        Arguments (pass arguments as '<name>:=<value>'):

            'robot':
                Which robot

            'rate':
                no description given
                (default: '5')

            'debug':*
                no description given
                (default: 'false')

            'who':
                no description given
                (default: LaunchConfig('robot') + '_x')

        * argument(s) which are only used if specific conditions occur
        """)


def test_show_args_of_a_package_file_without_arguments(tmp_path, demo_prefix, capsys):
    (demo_prefix / "share" / "demo" / "launch").mkdir(exist_ok=True)
    (demo_prefix / "share" / "demo" / "launch" / "none.launch.yaml").write_text("launch: []\n")
    assert cli.main(["demo", "none.launch.yaml", "--show-args"]) == 0
    assert capsys.readouterr().out == "Arguments (pass arguments as '<name>:=<value>'):\n\n  No arguments.\n"


@pytest.mark.parametrize("argv, message", [
    (["demo", "missing.launch.xml"],
     "file 'missing.launch.xml' was not found in the share directory of package 'demo'"),
    # ros2launch's command/launch.py: "Package '{}' not found: {}" with ament_index_python's error.
    (["nopkg", "x.launch.xml"], r"^Package 'nopkg' not found: package 'nopkg' not found, searching: \['"),
    (["no_such.launch.xml"], r"^Package 'no_such.launch.xml' not found: package 'no_such.launch.xml' not found"),
    (["--print", "x.launch.xml"],
     r"-p/--print is not supported by the course's ros2 launch \(it supports -s/--show-args"),
    (["--launch-prefix", "gdb", "x.launch.xml"], "--launch-prefix is not supported"),
    (["FILE", "rate=5"], "malformed launch argument 'rate=5', expected format '<name>:=<value>'"),
])
def test_command_line_mistakes_get_one_line(tmp_path, demo_prefix, capsys, argv, message):
    path = write(tmp_path, "xml", "<launch/>", "")
    argv = [str(path) if part == "FILE" else part for part in argv]
    assert cli.main(argv) != 0
    error = capsys.readouterr().err
    assert error.count("\n") == 1
    assert error.startswith("ros2 launch: ") == ("not supported" in message)  # the course's own line
    assert re.search(message, error)
