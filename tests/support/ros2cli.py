"""Running the installed ``.venv/bin/ros2`` (the course's) from the tests of its verbs."""

import subprocess
import sys
from pathlib import Path

ROS2 = Path(sys.executable).parent / "ros2"


def ros2(*args, env, timeout=60, check=True):
    """Run the installed ros2 with ``args``; the CompletedProcess (text), checked for exit code 0."""
    done = subprocess.run([str(ROS2), *args], env=env, capture_output=True, text=True, timeout=timeout,
                          stdin=subprocess.DEVNULL)
    if check:
        assert done.returncode == 0, f"ros2 {' '.join(args)} failed ({done.returncode}):\n{done.stderr}"
    return done


def ros2_together(*commands, env, timeout=60):
    """Run several independent ros2 commands at the same time (each one mostly waits for
    discovery); their CompletedProcesses, in order."""
    started = [subprocess.Popen([str(ROS2), *args], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True, stdin=subprocess.DEVNULL) for args in commands]
    done = []
    for args, process in zip(commands, started, strict=True):
        out, err = process.communicate(timeout=timeout)
        done.append(subprocess.CompletedProcess([str(ROS2), *args], process.returncode, out, err))
    return done


#: The end of a node script the tests run as a process, as a package's main() runs its node:
#: ``node_script(code, "Talker()")`` appends it, `node` being the expression that makes the node.
_NODE_MAIN = """

def main():
    rclpy.init(args=sys.argv)
    node = None
    try:
        node = {node}
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


main()
"""


def node_script(code: str, node: str) -> str:
    """`code` (imports and node classes; it imports sys, rclpy and ExternalShutdownException) followed
    by a main() that spins the node `node` makes until Ctrl-C, then shuts down cleanly."""
    return code.rstrip("\n") + "\n" + _NODE_MAIN.format(node=node)
