"""course_lib.launch's <executable> (and what <node> shares with it) without processes: the
process a launch file would start, against launch's own front-end tests.

Each launch file is run into its processes (actions.run_launch_file); their command lines,
process names, folders, outputs and environments are what launch's ExecuteProcess prepares.
test_launch.py starts such processes for real.
"""

import re

import pytest
from support.launch_demo import BOTH, write

from course_lib.launch.actions import run_launch_file
from course_lib.launch.entities import LaunchFileError

pytestmark = pytest.mark.usefixtures("launch_files_in_tmp_path")


@BOTH
def test_executable_is_prepared_as_launch_s_front_end_tests_read_it(tmp_path, form):
    """launch_xml's executable.xml / test_executable.py and launch_yaml's test_executable.py: cmd
    "ls -l -a -s" is ['ls', '-l', '-a', '-s'], cwd '/', name my_ls, output log, env var=1, and the
    launch-prefix $(env LAUNCH_PREFIX '') is empty. (Their shell, emulate_tty, sigterm_timeout and
    sigkill_timeout are refused here: see the next test.)"""
    path = write(tmp_path, form, """
        <launch>
            <executable cmd="ls -l -a -s" cwd="/" name="my_ls" output="log" launch-prefix="$(env LAUNCH_PREFIX '')">
                <env name="var" value="1"/>
            </executable>
        </launch>""", """
        launch:
        -   executable:
                cmd: ls -l -a -s
                cwd: '/'
                name: my_ls
                output: log
                'launch-prefix': $(env LAUNCH_PREFIX '')
                env:
                    -   name: var
                        value: '1'
        """)
    process, = run_launch_file(path, environment={"PATH": "/bin"}).processes
    assert (process.command, process.cwd, process.label, process.output) == (
        ["ls", "-l", "-a", "-s"], "/", "my_ls", "log")
    assert process.environment == {"PATH": "/bin", "var": "1"}
    assert (process.node_name, process.namespace) == (None, None)  # no node: nothing to wait for in the graph


@pytest.mark.parametrize("form, text, line, message", [
    # launch_xml's test_executable.py (test_executable_wrong_subtag) wants "`executable`" and
    # "whats_this" in the error; launch's ExecuteProcess.parse reads no args (that is <node>'s).
    ("xml", "<executable cmd='ls'>\n<env name='var' value='1'/>\n<whats_this/>\n</executable>",
     4, r"^Unexpected nested tag\(s\) found in `executable`: \{'whats_this'\}$"),
    ("xml", "<executable cmd='ls' args='-l'/>", 2, r"^Unexpected attribute\(s\) found in `executable`: \{'args'\}"),
    ("yaml", "- executable: {cmd: ls, args: -l}", 2, r"^Unexpected key\(s\) found in `executable`: \{'args'\}"),
    ("xml", "<executable cmd='ls' shell='true'/>",
     2, r"^<executable> attribute 'shell' is not supported here; <executable> supports: cmd, name, cwd, output"),
    ("yaml", "- executable: {cmd: ls, sigterm_timeout: 7.0}", 2, r"^<executable> attribute 'sigterm_timeout' is not"),
    ("xml", "<executable cmd='ls' on_exit='shutdown'/>", 2, r"^<executable> attribute 'on_exit' is not supported"),
    ("xml", "<executable name='x'/>", 2, r"^<executable> needs the attribute 'cmd'$"),
    ("xml", "<executable cmd='ls' output='own_log'/>", 2, r'^output="own_log" is not supported here; use screen, log'),
])
def test_what_executable_does_not_run_here_is_refused(tmp_path, form, text, line, message):
    path = write(tmp_path, form, f"<launch>\n{text}\n</launch>", f"launch:\n{text}\n")
    with pytest.raises(LaunchFileError) as error:
        run_launch_file(path)
    assert re.search(message, error.value.message) and error.value.line == line, error.value


def test_process_names_and_launch_prefixes_follow_launch(tmp_path, demo_prefix):
    """launch's Executable.prepare: the name is the tag's, else the base name of the first word
    after the prefix; without a prefix of its own a process takes the launch-prefix launch
    configuration (ros2 launch --launch-prefix) where launch-prefix-filter matches its name."""
    path = write(tmp_path, "xml", """
        <launch>
          <arg name="tool" default="/usr/bin/env"/>
          <executable cmd="$(var tool) true"/>
          <executable cmd="true" launch-prefix="nice -n 5" name="$(var tool)_named"/>
          <executable cmd="true" launch-prefix="nice -n 5"/>
          <node pkg="demo" exec="talker" launch-prefix="nice" cwd="$(dirname)"/>
          <node pkg="demo" exec="listener" exec_name="hearing"/>
        </launch>""", "")
    env, named, niced, talker, listener = run_launch_file(path).processes
    assert (env.command, env.label) == (["/usr/bin/env", "true"], "env")
    assert (named.command, named.label) == (["nice", "-n", "5", "true"], "/usr/bin/env_named")
    assert (niced.label, talker.label, talker.command[0], talker.cwd) == ("nice", "nice", "nice", str(tmp_path))
    assert talker.command[1] == str(demo_prefix / "lib" / "demo" / "talker") and listener.label == "hearing"
    prefixed = run_launch_file(path, {"launch-prefix": "time -p", "launch-prefix-filter": "(env|listener)"}).processes
    assert [process.command[:2] for process in prefixed] == [
        ["time", "-p"], ["nice", "-n"], ["nice", "-n"], ["nice", str(demo_prefix / "lib" / "demo" / "talker")],
        ["time", "-p"]]
