"""Launch files in ROS 2's XML and YAML formats, run like ``ros2 launch`` (not on PyPI).

From a terminal (the ``ros2`` command calls :func:`main`)::

    ros2 launch my_package talk.launch.xml rate:=5
    ros2 launch ./talk.launch.yaml --show-args

From a notebook::

    from course_lib import launch
    demo = launch.start("talk.launch.xml", rate=5)   # running the cell again restarts it
    demo.wait_for_nodes(); print(demo.log); demo.stop()

Supported, with the semantics of ros2/launch and launch_ros on Jazzy: ``<launch>``, ``<node>``
(pkg, exec, name, namespace, exec_name, output, args, ros_args, cwd, launch-prefix; nested
``<param>``, ``<remap>``, ``<env>``), ``<executable>`` (cmd, name, cwd, output, launch-prefix;
nested ``<env>``), ``<param>`` (name/value typed by YAML's rules or by ``type=``, ``value-sep``
lists, nested names, ``from=`` a YAML file), ``<arg>`` (with ``<choice>``), ``<let>``,
``<include>`` (with ``<arg>``), ``<group>`` (scoped, forwarding, with ``<keep>``),
``<push_ros_namespace>``, ``<set_env>``, ``if``/``unless`` on every tag, and the
substitutions ``$(var)``, ``$(env)``, ``$(find-pkg-share)``, ``$(find-pkg-prefix)``,
``$(dirname)``, ``$(filename)``, ``$(eval)``, ``$(not)``, ``$(and)``, ``$(or)``, ``$(any)``,
``$(all)``, ``$(equals)``, ``$(not-equals)``, ``$(if)``. Anything else is an error naming the
file and line. Python launch files are not run here (a full ROS 2 install runs them).

The parts: entities.py reads XML/YAML into tags with line numbers, substitutions.py the
``$(...)`` grammar, coercion.py launch's rules for typing text, parser.py turns tags into
actions, actions.py runs them (executables.py makes ``<node>`` and ``<executable>`` the
processes to start; parameters.py types and writes a node's parameters), runner.py starts and
stops the processes, cli.py is ``ros2 launch``.
"""

# The parser registers its reading of launch files with actions (actions.reads_launch_files);
# cli imports it too, but a user of actions alone relies on this import.
from course_lib.launch import parser  # noqa: F401
from course_lib.launch.cli import main
from course_lib.launch.entities import LaunchFileError
from course_lib.launch.runner import Launch, start, stop_all

__all__ = ["Launch", "LaunchFileError", "main", "start", "stop_all"]
