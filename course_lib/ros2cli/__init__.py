"""The ``ros2`` command on the pip install of ROS 2: the part of ros2cli the course teaches.

ros2cli is not on PyPI, so ``make setup`` puts this stand-in into the virtual environment as
``ros2`` (only there, and only when no real ``ros2`` exists: see :mod:`.install`). It has the
real tool's verbs, options and output for what it supports, each a thin layer over course_lib:

=============================================  =============================================
``ros2 run PKG EXE [args]``                    :mod:`.run` (course_lib.ros.ament)
``ros2 launch PKG FILE`` / ``ros2 launch PATH``  :mod:`.launch` (course_lib.launch)
``ros2 node list|info``                        :mod:`.node` (course_lib.ros.graph)
``ros2 topic list|echo|hz|info|pub``           :mod:`.topic` (course_lib.ros.graph)
``ros2 topic type|find|bw|delay``              :mod:`.topic` (course_lib.ros.graph)
``ros2 service list|type|find|call``           :mod:`.service` (the tool node's clients)
``ros2 action list|info|type|send_goal``       :mod:`.action` (rclpy.action)
``ros2 bag record|info|play``                  :mod:`.bag` (course_lib.ros.bag_files)
``ros2 param list|get|set|dump|load``          :mod:`.param` (course_lib.ros.parameters)
``ros2 interface show|list|package|packages``  :mod:`.interface` (course_lib.ros.interfaces)
``ros2 pkg create|list|executables|prefix``    :mod:`.pkg` (course_lib.ros.workspace, ament)
``ros2 daemon start|stop|status``              :mod:`.daemon` (the graph verbs ask it: .daemon_server)
=============================================  =============================================

Anything else (a command, a verb or an option) prints one line that says so and names what is
supported; a full ROS 2 install has the rest.
"""

from course_lib.ros2cli.cli import main

__all__ = ["main"]
