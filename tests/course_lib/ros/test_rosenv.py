"""Tests for course_lib.ros.rosenv: install detection, child environments, domain reservations."""

import os
import subprocess
import sys
from itertools import pairwise
from xml.etree import ElementTree

import numpy as np
import pytest
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import Image

from course_lib.ros import processes, rosenv, session


def test_pip_wheels_are_detected_in_the_project_environment():
    install = rosenv.detect_install()
    assert install.kind == "pip", install
    assert install.rclpy_path is not None and install.rclpy_path.name == "rclpy"
    assert any((p / "share/ament_index/resource_index/packages/rclpy").exists() for p in install.prefixes)


def test_an_unreadable_prefix_on_the_ament_path_is_skipped(tmp_path, monkeypatch):
    """A grading run once passed a prefix of the grader's (mode 0700) to a student's process, where
    importing course_lib raised PermissionError. (Root reads everything, so the refusal is made here.)"""
    import pathlib

    private = tmp_path / "private"
    (private / "share" / "ament_index" / "resource_index").mkdir(parents=True)
    is_dir = pathlib.Path.is_dir

    def refusing(path, *args, **kwargs):
        if str(path).startswith(str(private)):
            raise PermissionError(13, "Permission denied", str(path))
        return is_dir(path, *args, **kwargs)

    monkeypatch.setattr(pathlib.Path, "is_dir", refusing)
    monkeypatch.setenv("AMENT_PREFIX_PATH", os.pathsep.join([str(private), os.environ.get("AMENT_PREFIX_PATH", "")]))
    install = rosenv.detect_install()
    assert install.prefixes and private not in install.prefixes


def test_child_environment_is_isolated_and_finds_the_ament_index():
    env = rosenv.ros_environment(domain_id=42, base={"PATH": "/usr/bin", "ROS_LOCALHOST_ONLY": "1"})
    assert env["ROS_DOMAIN_ID"] == "42"
    assert env["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "LOCALHOST"
    assert "ROS_LOCALHOST_ONLY" not in env
    assert sys.prefix in env["AMENT_PREFIX_PATH"].split(os.pathsep)
    assert env["PATH"].split(os.pathsep)[0] == os.path.dirname(sys.executable)


@pytest.mark.parametrize("bad", [-1, 233, 1000, "7"])
def test_out_of_range_domain_ids_are_refused_with_the_range(bad):
    with pytest.raises(ValueError, match="0 to 232"):
        rosenv.ros_environment(domain_id=bad)


def test_reservations_are_exclusive_across_processes():
    with rosenv.reserve_domain_id() as mine:
        code = (f"from course_lib import rosenv; r = rosenv.reserve_domain_id(range({mine.domain_id}, "
                f"{mine.domain_id + 1})); print(r.domain_id)")
        other = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
        assert other.returncode != 0 and "reserved by other processes" in other.stderr
    # Released: now another process can take it.
    other = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert other.stdout.strip() == str(mine.domain_id), other.stderr


def test_modes_are_separate_flags(monkeypatch):
    monkeypatch.setenv("COURSE_LIB_UNDER_TEST", "1")
    monkeypatch.delenv("COURSE_LIB_GRADING", raising=False)
    assert rosenv.under_test() and not rosenv.under_grading()
    monkeypatch.setenv("COURSE_LIB_UNDER_TEST", "0")
    monkeypatch.setenv("COURSE_LIB_GRADING", "1")
    assert rosenv.under_grading() and not rosenv.under_test()


# ---- the Fast DDS set-up for camera frames ----------------------------------------------------

def test_child_processes_get_the_course_fast_dds_profile():
    env = rosenv.ros_environment(base={"PATH": "/usr/bin"})
    assert env["FASTRTPS_DEFAULT_PROFILES_FILE"] == str(rosenv.FASTDDS_PROFILE)
    sizes = [int(e.text) for e in ElementTree.parse(rosenv.FASTDDS_PROFILE).iter()
             if e.tag.endswith("segment_size")]
    assert sizes and sizes[0] >= 2 * 1920 * 1080 * 3, "a segment holds two 1920x1080 bgr8 frames"


@pytest.mark.parametrize("name, value", [("FASTRTPS_DEFAULT_PROFILES_FILE", "/home/me/my_profile.xml"),
                                         ("FASTDDS_BUILTIN_TRANSPORTS", "LARGE_DATA")])
def test_a_users_own_fast_dds_choice_is_kept(name, value):
    env = rosenv.ros_environment(base={"PATH": "/usr/bin", name: value})
    assert env[name] == value
    assert set(rosenv.FASTDDS_USER_SETTINGS) & set(env) == {name}


def test_a_small_dev_shm_keeps_fast_dds_defaults(monkeypatch):
    monkeypatch.setattr(rosenv, "shared_memory_mb", lambda: 64)  # Docker's default --shm-size
    env = rosenv.ros_environment(base={"PATH": "/usr/bin"})
    assert not set(rosenv.FASTDDS_USER_SETTINGS) & set(env)


def test_child_processes_import_numpy_with_one_blas_thread_unless_the_user_chose():
    """OpenBLAS's threads (one per core, spinning at import) are left out of the course's ROS processes."""
    count_threads = "import os, numpy; print(len(os.listdir('/proc/self/task')))"
    env = rosenv.ros_environment(base={"PATH": os.environ["PATH"]})
    assert env["OPENBLAS_NUM_THREADS"] == "1"
    done = subprocess.run([sys.executable, "-c", count_threads], env=env, capture_output=True, text=True, check=True)
    assert done.stdout == "1\n", "numpy started threads of its own"
    assert rosenv.ros_environment(base={"PATH": "/usr/bin", "OPENBLAS_NUM_THREADS": "4"})["OPENBLAS_NUM_THREADS"] == "4"


def without_fast_dds_settings() -> dict:
    return {k: v for k, v in os.environ.items() if k not in rosenv.FASTDDS_USER_SETTINGS}


def test_importing_course_lib_gives_the_notebook_session_the_profile():
    code = "import os, course_lib; print(os.environ['FASTRTPS_DEFAULT_PROFILES_FILE'])"
    done = subprocess.run([sys.executable, "-c", code], env=without_fast_dds_settings(), capture_output=True,
                          text=True, timeout=60)
    assert done.stdout.strip() == str(rosenv.FASTDDS_PROFILE), done.stderr


def test_env_command_gives_a_shell_the_notebook_sessions_variables():
    """`eval "$(python -m course_lib env)"` (what make lab does) sets what importing course_lib sets."""
    script = f'eval "$({sys.executable} -m course_lib env)" && echo "$FASTRTPS_DEFAULT_PROFILES_FILE" && ' \
             'echo "$ROS_AUTOMATIC_DISCOVERY_RANGE" && echo "$AMENT_PREFIX_PATH"'
    done = subprocess.run(["sh", "-c", script], env=without_fast_dds_settings(), capture_output=True, text=True,
                          timeout=60)
    profile, scope, prefixes = done.stdout.splitlines()
    assert profile == str(rosenv.FASTDDS_PROFILE), done.stderr
    assert scope == "LOCALHOST"
    assert sys.prefix in prefixes.split(os.pathsep)


def test_full_size_camera_frames_reach_a_notebook_session_from_another_process(domain_id, tmp_path):
    """1920x1080 frames from the camera process arrive at the session's best-effort subscriber
    (with Fast DDS's 512 KB default segment most of them are lost)."""
    import cv2

    period = 0.5
    # A video file as the camera's source: its frames cost milliseconds to read, where a simulated
    # 1080p frame is drawn in Python. Each of its frames has a grey level of its own, so the
    # frames received say how many the camera sent between them, however late it sent them.
    levels = range(0, 250, 10)
    video = str(tmp_path / "full_size.avi")
    writer = cv2.VideoWriter(video, cv2.VideoWriter_fourcc(*"MJPG"), 1 / period, (1920, 1080))
    for level in levels:
        writer.write(np.full((1080, 1920, 3), level, np.uint8))
    writer.release()
    session.start(domain_id=domain_id)
    try:
        node = session.add_node(Node("full_size_viewer"))
        received = []  # the video's frame number of each frame received
        node.create_subscription(Image, "image", lambda m: received.append(round(m.data[0] / 10)),
                                 qos_profile_sensor_data)
        with processes.python_node("course_lib.imaging.camera:main", "--ros-args", "-p", "width:=1920", "-p",
                                   "height:=1080", "-p", f"rate:={1 / period}", "-p", f"source:={video}",
                                   domain_id=domain_id) as camera:
            camera.wait_for_node("image_publisher", timeout=60)
            # Backstops only: the camera sends a frame every 0.5 s, and the test goes on at the
            # ninth frame received, however long the machine takes to bring them.
            assert session.wait_for(lambda: len(received) >= 1, timeout=120), camera.log_tail()
            assert session.wait_for(lambda: len(received) >= 9, timeout=300), (received, camera.log_tail())
        numbers = received[:9]
        lost = sum((later - earlier - 1) % len(levels) for earlier, later in pairwise(numbers))
        # A loaded CI machine drops some best-effort frames (5 in 13 seen once). At least half
        # must arrive: without the fix about 9 in 10 are lost.
        assert lost <= len(numbers) - 1, f"{lost} frames lost between {len(numbers)} received: {numbers}"
    finally:
        session.stop()
