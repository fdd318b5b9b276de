"""Tests for course_lib.notebook.doctor: it passes here, and each failure it can find names the fix."""

import os
import subprocess
import sys

from course_lib.notebook import doctor
from course_lib.ros import rosenv


def run_doctor(*args, **env_changes):
    env = dict(os.environ)
    for name, value in env_changes.items():
        if value is None:
            env.pop(name, None)
        else:
            env[name] = value
    return subprocess.run([sys.executable, "-m", "course_lib", "doctor", *args], capture_output=True,
                          text=True, env=env, timeout=300)


def test_doctor_passes_with_a_live_round_trip_between_two_processes():
    result = run_doctor()
    assert result.returncode == 0, result.stdout + result.stderr
    assert "[ok  ] pub/sub round trip: a second process answered" in result.stdout
    assert "pip wheels" in result.stdout and "rmw_fastrtps_cpp" in result.stdout


def test_a_bad_domain_id_fails_with_the_fix():
    result = run_doctor("--no-live", ROS_DOMAIN_ID="300")
    assert result.returncode == 1
    assert "[FAIL] ROS_DOMAIN_ID" in result.stdout and "export ROS_DOMAIN_ID=<0..101>" in result.stdout


def test_discovery_switched_off_fails_the_round_trip_with_advice():
    """No answer can come with discovery off, however long the wait (its timeout counts once the
    second process runs): a second is enough to see the failure and its advice."""
    result = run_doctor("--timeout", "1", ROS_AUTOMATIC_DISCOVERY_RANGE="OFF")
    assert result.returncode == 1, result.stdout
    assert "[FAIL] pub/sub round trip: no answer from a second process within 1 s" in result.stdout
    assert "ROS_AUTOMATIC_DISCOVERY_RANGE is not OFF" in result.stdout
    assert "[warn] discovery" in result.stdout  # OFF is also reported as a setting to change


def test_deprecated_localhost_only_is_a_warning_not_a_failure(monkeypatch):
    monkeypatch.setenv("ROS_LOCALHOST_ONLY", "1")
    report = doctor.run(live=False)
    line = next(c for c in report.checks if c.name == "discovery")
    assert line.ok and line.warning and "unset ROS_LOCALHOST_ONLY" in line.fix


def test_notebook_call_raises_naming_the_failed_check(monkeypatch):
    monkeypatch.setenv("ROS_DOMAIN_ID", "banana")
    try:
        doctor.check(live=False)
    except RuntimeError as error:
        assert "ROS_DOMAIN_ID='banana' is not a valid domain id" in str(error)
    else:
        raise AssertionError("doctor.check() accepted ROS_DOMAIN_ID=banana")


def camera_frames_line():
    return next(c for c in doctor.run(live=False).checks if c.name == "camera frames")


def test_camera_frames_line_names_the_course_profile_or_the_users_own(monkeypatch):
    monkeypatch.delenv("FASTDDS_BUILTIN_TRANSPORTS", raising=False)
    monkeypatch.setenv("FASTRTPS_DEFAULT_PROFILES_FILE", str(rosenv.FASTDDS_PROFILE))
    line = camera_frames_line()
    assert line.ok and not line.warning and "the course's shared-memory profile" in line.detail
    monkeypatch.setenv("FASTRTPS_DEFAULT_PROFILES_FILE", "/home/me/mine.xml")
    assert "your own Fast DDS set-up: FASTRTPS_DEFAULT_PROFILES_FILE=/home/me/mine.xml" in camera_frames_line().detail


def test_a_small_dev_shm_is_a_warning_with_the_fix(monkeypatch):
    for name in rosenv.FASTDDS_USER_SETTINGS:
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setattr(rosenv, "shared_memory_mb", lambda: 64)
    line = camera_frames_line()
    assert line.ok and line.warning and "/dev/shm has 64 MB" in line.detail and "--shm-size=1g" in line.fix


def test_a_killed_process_leaves_its_segment_which_fastdds_shm_clean_removes(domain_id):
    """A ROS process killed with SIGKILL cannot close its Fast DDS segment: it stays in /dev/shm,
    holding memory. The doctor says so and names Fast DDS's own tool, which
    remove_stale_segments runs to remove it (a student's hub server does so every minute)."""
    import select
    import signal
    from pathlib import Path

    code = ("import rclpy, rclpy.node, time; rclpy.init(); node = rclpy.node.Node('killed_here'); "
            "print('ready', flush=True); time.sleep(60)")
    process = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True,
                               env=rosenv.ros_environment(domain_id=domain_id))
    try:
        ready, _, _ = select.select([process.stdout], [], [], 60)
        assert ready and process.stdout.readline().strip() == "ready"
        # Its own segments: the ones it maps (other tests' processes make segments meanwhile).
        maps = Path(f"/proc/{process.pid}/maps").read_text().split()
        own = {Path(word) for word in maps if word.startswith(f"{doctor.SHM_DIR}/fastrtps_")
               and doctor._SEGMENT_LOCK.match(Path(word).name + "_el")}
        assert own, "the process mapped no shared-memory segment"
        assert not own & set(doctor.stale_segments()), "a running process's segment is not stale"
    finally:
        process.send_signal(signal.SIGKILL)
        process.wait(timeout=10)
        process.stdout.close()
    assert own <= set(doctor.stale_segments())
    line = doctor._check_shared_memory().line()
    assert line.startswith("[warn] shared memory:") and "fastdds shm clean" in line, line
    assert doctor.remove_stale_segments() >= len(own)
    assert not any(p.exists() for p in own)
