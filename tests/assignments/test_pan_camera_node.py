"""The services_actions reference node (pan_camera's main(), which students are given) ends on SIGTERM
as on Ctrl-C, like lesson 04's find_pictures_server: the same main() with the same hang (issue 51).

Its main() hands SIGTERM to course_lib.ros.sigterm before rclpy.init; tests/course_lib/ros/test_sigterm.py
says why. Here: SIGTERM to ROUNDS spinning main() calls in one process (support.sigterm_rounds), and
`kill` of a real node process, which exits 0.
"""

from __future__ import annotations

import sys

import pytest
from support import course as course_support
from support import sigterm_rounds
from support.from_source import REFERENCE_SOURCE

from course_lib import contract


@pytest.fixture(scope="module")
def node_env(tmp_path_factory):
    from course_lib.ros import workspace

    (install,) = course_support.reference_interface_installs(tmp_path_factory, "services_actions")
    env = workspace.workspace_environment(install.parent)
    env["PYTHONPATH"] = ":".join([str(REFERENCE_SOURCE / "pan_camera"), str(contract.ROOT), env.get("PYTHONPATH", "")])
    return env


@pytest.mark.slow
def test_sigterm_ends_the_nodes_main_every_time_as_ctrl_c_does(node_env):
    """SIGTERM ends each of ROUNDS spinning main() calls of pan_camera_node within ENDS_WITHIN seconds."""
    ran = sigterm_rounds.run_rounds("pan_camera.pan_camera_node", node_env)
    assert ran.returncode == 0 and sigterm_rounds.DONE in ran.stdout, ran.stdout + ran.stderr[-2000:]


@pytest.mark.slow
def test_a_node_process_ends_on_sigterm_with_exit_code_0(node_env):
    """`kill` of a pan_camera_node process that spins ends it at once, as Ctrl-C does (exit code 0)."""
    code, log = sigterm_rounds.exit_code_after_sigterm([sys.executable, "-m", "pan_camera.pan_camera_node"],
                                                       "pan_camera", node_env)
    assert code == 0, log
