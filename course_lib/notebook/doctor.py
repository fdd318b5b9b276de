"""Environment check: is this machine ready for the course?

Run it from a terminal with ``python -m course_lib doctor`` (exit code 0 when everything passes)
or from a notebook with ``doctor.check()``. Each check prints one line; a failing check also
prints the fix. The last check is live: a second process answers a ping over ROS 2, so
discovery and transport are tested for real in the configured ROS_DOMAIN_ID.
"""

from __future__ import annotations

import dataclasses
import fcntl
import importlib
import os
import platform
import re
import subprocess
import sys
import time
import uuid
from pathlib import Path

from course_lib import waiting
from course_lib.ros import rosenv

SETUP_FIX = "run `make setup` in the course folder, then use the .venv/bin/python it creates"
ECHO_SUFFIX = "/reply"
#: What the round trip's second process prints once its node answers, and how long it may take
#: to get there (Python and rclpy start in a second when idle, in many on a busy machine): the
#: round trip's own timeout counts from then, so that a slow start is not taken for a blocked network.
ECHO_READY = "course doctor echo: ready"
ECHO_START_SECONDS = 60.0


@dataclasses.dataclass
class Check:
    """One line of the report."""

    name: str
    ok: bool
    detail: str
    fix: str = ""
    warning: bool = False  # a concern that does not make the environment unusable

    def line(self) -> str:
        mark = "ok  " if self.ok else "FAIL"
        if self.ok and self.warning:
            mark = "warn"
        text = f"[{mark}] {self.name}: {self.detail}"
        if self.fix and (not self.ok or self.warning):
            text += f"\n       fix: {self.fix}"
        return text


@dataclasses.dataclass
class Report:
    checks: list[Check]

    @property
    def ok(self) -> bool:
        return all(c.ok for c in self.checks)

    def failures(self) -> list[Check]:
        return [c for c in self.checks if not c.ok]

    def __str__(self) -> str:
        lines = [c.line() for c in self.checks]
        verdict = "All checks passed." if self.ok else f"{len(self.failures())} check(s) failed."
        return "\n".join(lines + [verdict])

    def _repr_pretty_(self, printer, cycle):  # IPython shows the report as text
        printer.text(str(self))


def _check_python() -> Check:
    version = ".".join(map(str, sys.version_info[:3]))
    machine = platform.machine()
    supported = sys.version_info[:2] in {(3, 10), (3, 11), (3, 12), (3, 13)} and machine == "x86_64" \
        and sys.platform == "linux"
    detail = f"Python {version} on {sys.platform} {machine} ({sys.executable})"
    install = rosenv.detect_install()
    if supported or install.kind in ("system", "conda"):
        return Check("python", True, detail)
    return Check("python", install.kind != "missing", detail,
                 "the ROS 2 Jazzy wheels exist for Linux x86_64 with CPython 3.10-3.13 only; use such an "
                 "interpreter (make setup PYTHON=python3.12) or a system ROS 2 Jazzy / RoboStack install",
                 warning=True)


def _check_install() -> Check:
    install = rosenv.detect_install()
    if install.kind == "missing":
        return Check("rclpy", False, "rclpy is not importable from " + sys.executable,
                     SETUP_FIX + "; for a system install: source /opt/ros/jazzy/setup.bash first")
    try:
        importlib.import_module("rclpy")
    except Exception as error:  # a broken install raises all sorts of errors
        return Check("rclpy", False, f"found at {install.rclpy_path} but import failed: {error}",
                     "reinstall: rm -rf .venv && make setup" if install.kind == "pip"
                     else "source /opt/ros/jazzy/setup.bash (or activate the RoboStack environment)")
    detail = install.describe()
    if install.distro and install.distro != rosenv.DISTRO:
        return Check("rclpy", True, f"{detail}, but ROS_DISTRO is {install.distro}",
                     f"the course is written for ROS 2 {rosenv.DISTRO}; other distributions may differ",
                     warning=True)
    return Check("rclpy", True, detail)


def _check_messages() -> Check:
    missing = []
    for package in ("std_msgs", "sensor_msgs", "geometry_msgs", "builtin_interfaces"):
        try:
            importlib.import_module(f"{package}.msg")
        except Exception:
            missing.append(package)
    if missing:
        return Check("messages", False, "cannot import " + ", ".join(missing), SETUP_FIX)
    return Check("messages", True, "std_msgs, sensor_msgs, geometry_msgs, builtin_interfaces")


def _check_rmw() -> Check:
    try:
        from rclpy.utilities import get_rmw_implementation_identifier
        rmw = get_rmw_implementation_identifier()
    except Exception as error:
        return Check("rmw", False, f"no RMW implementation could be loaded: {error}",
                     "install ros-jazzy-rclpy[fastrtps] (make setup), or unset RMW_IMPLEMENTATION")
    chosen = os.environ.get("RMW_IMPLEMENTATION")
    return Check("rmw", True, rmw + (f" (RMW_IMPLEMENTATION={chosen})" if chosen else " (default)"))


def _check_network_settings() -> Check:
    domain = os.environ.get("ROS_DOMAIN_ID", "")
    try:
        domain_id = rosenv.check_domain_id(int(domain or "0"))
    except ValueError:
        return Check("ROS_DOMAIN_ID", False, f"ROS_DOMAIN_ID={domain!r} is not a valid domain id",
                     "export ROS_DOMAIN_ID=<0..101> (or unset it for 0)")
    scope = os.environ.get("ROS_AUTOMATIC_DISCOVERY_RANGE", "")
    by_us = " (course_lib's default)" if "ROS_AUTOMATIC_DISCOVERY_RANGE" in rosenv.DEFAULTS_APPLIED else ""
    detail = f"ROS_DOMAIN_ID={domain_id}{'' if domain else ' (unset)'}, " \
             f"ROS_AUTOMATIC_DISCOVERY_RANGE={scope or 'unset (SUBNET)'}{by_us}"
    if "ROS_LOCALHOST_ONLY" in os.environ:
        return Check("discovery", True, detail + ", ROS_LOCALHOST_ONLY is set",
                     "unset ROS_LOCALHOST_ONLY (deprecated in Jazzy); use ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST",
                     warning=True)
    if scope != "LOCALHOST":
        return Check("discovery", True, detail,
                     "export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST so that your nodes do not meet "
                     "other machines' nodes on a shared network (course_lib sets it for the nodes it starts)",
                     warning=True)
    return Check("discovery", True, detail)


def _check_large_data() -> Check:
    """Whether camera frames travel whole between processes (rosenv.large_data_environment)."""
    profile = os.environ.get("FASTRTPS_DEFAULT_PROFILES_FILE")
    if profile == str(rosenv.FASTDDS_PROFILE):
        return Check("camera frames", True, "Fast DDS with the course's shared-memory profile "
                     f"({rosenv.FASTDDS_PROFILE.name}): full-size frames reach other processes")
    chosen = [f"{name}={os.environ[name]}" for name in rosenv.FASTDDS_USER_SETTINGS if os.environ.get(name)]
    if chosen:
        return Check("camera frames", True, "your own Fast DDS set-up: " + ", ".join(chosen))
    shm = rosenv.shared_memory_mb()
    return Check("camera frames", True, f"Fast DDS defaults (/dev/shm has {shm} MB, the course's profile needs "
                 f"{rosenv.SHARED_MEMORY_NEEDED_MB} MB): most frames of 640x480 and more are lost between processes",
                 f"give /dev/shm at least {rosenv.SHARED_MEMORY_NEEDED_MB} MB (docker run --shm-size=1g), "
                 "then restart the kernel", warning=True)


#: Where Fast DDS keeps its shared-memory segments on Linux, and the lock file of each segment:
#: fastrtps_<16 characters>_el, locked (flock) while the process that opened the segment runs.
SHM_DIR = Path("/dev/shm")
_SEGMENT_LOCK = re.compile(r"^fastrtps_[0-9a-z]{16}_el$")


def stale_segments(folder: Path = SHM_DIR) -> list[Path]:
    """The Fast DDS segments in `folder` whose process has ended without closing them (it was
    killed): their lock file is not locked. Each holds memory until it is removed."""
    stale = []
    for lock in sorted(folder.glob("fastrtps_*_el")):
        if not _SEGMENT_LOCK.match(lock.name):
            continue
        try:
            with open(lock, "rb") as handle:
                fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)  # released when closed
        except OSError:
            continue  # locked: its process runs (or the file just went)
        stale.append(lock.with_name(lock.name[: -len("_el")]))
    return stale


def remove_stale_segments() -> int:
    """Remove the Fast DDS segments of processes that were killed (stale_segments) with Fast DDS's
    own ``fastdds shm clean``, which frees only segments whose process has ended; return how many
    were stale. Nothing runs when none is.

    Raises:
        FileNotFoundError: the fastdds tool is neither beside this interpreter (the pip wheels put
            it there) nor on PATH (a system ROS install).
    """
    stale = stale_segments()
    if not stale:
        return 0
    fastdds = rosenv.environment_tool("fastdds")
    if fastdds is None:
        raise FileNotFoundError("Fast DDS's fastdds tool is not installed here: run `make setup` (the pip wheels "
                                "bring it) or source a ROS 2 install")
    subprocess.run([fastdds, "shm", "clean"], check=True, capture_output=True, timeout=60)
    return len(stale)


def _check_shared_memory() -> Check:
    """Fast DDS segments left in /dev/shm by killed processes (memory that nothing frees)."""
    stale = stale_segments()
    if not stale:
        return Check("shared memory", True, "no Fast DDS segments left behind by ended processes")
    held = 0
    for segment in stale:
        try:
            held += segment.stat().st_blocks * 512
        except OSError:
            pass
    return Check("shared memory", True, f"{len(stale)} Fast DDS segment(s) of processes that were killed hold "
                 f"{held // 2**20} MB of memory in {SHM_DIR}",
                 "run `fastdds shm clean` (Fast DDS's own tool, in this environment's bin/; it removes only "
                 "segments whose process has ended)", warning=True)


def _check_opencv() -> Check:
    try:
        import cv2
    except Exception as error:
        return Check("opencv", False, f"cv2 does not import: {error}", SETUP_FIX)
    if not hasattr(cv2, "aruco") or not hasattr(cv2.aruco, "ArucoDetector"):
        return Check("opencv", False, f"OpenCV {cv2.__version__} has no cv2.aruco.ArucoDetector",
                     "install opencv-contrib-python-headless (make setup) and uninstall other opencv-python packages")
    return Check("opencv", True, f"OpenCV {cv2.__version__} with cv2.aruco.ArucoDetector")


def _check_interface_builds() -> Check:
    install = rosenv.detect_install()
    if install.kind != "pip":
        return Check("interface builds", True, f"{install.kind} install: colcon uses it as installed")
    from course_lib.ros import wheelfix
    problems = wheelfix.check()
    if problems:
        return Check("interface builds", True, "; ".join(problems),
                     "run `python -m course_lib repair-wheels` (make setup does it)", warning=True)
    return Check("interface builds", True, "CMake files of the wheels point into this environment")


def _check_round_trip(timeout: float) -> Check:
    """Ping a second process over ROS 2 and wait for its answer."""
    try:
        import rclpy
        from rclpy.context import Context
        from rclpy.executors import SingleThreadedExecutor
        from std_msgs.msg import String

        from course_lib.ros import processes
    except Exception as error:
        return Check("pub/sub round trip", False, f"cannot start: {error}", SETUP_FIX)
    domain_id = int(os.environ.get("ROS_DOMAIN_ID") or 0)
    token = uuid.uuid4().hex[:12]
    topic = f"/course_doctor_{token}"
    context = Context()
    rclpy.init(context=context, domain_id=domain_id)
    answers: list[float] = []
    started = time.monotonic()
    node = rclpy.create_node(f"course_doctor_{token}", context=context)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    echo = None
    try:
        sent: dict[str, float] = {}
        node.create_subscription(String, topic + ECHO_SUFFIX,
                                 lambda msg: answers.append(time.monotonic() - sent.get(msg.data, started)), 10)
        publisher = node.create_publisher(String, topic, 10)
        echo = processes.python_node("course_lib.notebook.doctor:echo_main", topic, name="doctor-echo",
                                     domain_id=domain_id)
        try:
            echo.wait_for_output(ECHO_READY, timeout=ECHO_START_SECONDS)
        except (RuntimeError, TimeoutError) as error:
            return Check("pub/sub round trip", False, f"the second process did not start: {error}", SETUP_FIX)
        started = time.monotonic()
        next_ping = [0.0]

        def ping() -> None:  # repeat: the first pings go out before discovery
            if time.monotonic() >= next_ping[0]:
                text = f"ping {len(sent)}"
                sent[text] = time.monotonic()
                publisher.publish(String(data=text))
                next_ping[0] = time.monotonic() + 0.2

        ping()
        waiting.spin_until(lambda: answers or not echo.running(), max(0.0, started + timeout - time.monotonic()),
                           executor=executor, between=ping)
        elapsed = time.monotonic() - started
        if not answers:
            state = f"it exited with code {echo.returncode}" if not echo.running() else "it is running"
            return Check("pub/sub round trip", False,
                         f"no answer from a second process within {timeout:.0f} s in domain {domain_id} "
                         f"({state}); its log ends with: {echo.log[-400:].strip() or '(empty)'}",
                         "check that no firewall blocks UDP on loopback, that ROS_DOMAIN_ID is the same "
                         "in both processes, and that ROS_AUTOMATIC_DISCOVERY_RANGE is not OFF")
        return Check("pub/sub round trip", True,
                     f"a second process answered in domain {domain_id} after {elapsed:.2f} s "
                     f"(discovery included; one ping took {answers[0] * 1000:.1f} ms)")
    finally:
        if echo is not None:
            echo.stop()
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown(context=context)


def echo_main(args=None) -> None:
    """The second process of the round trip: answer every String on TOPIC on TOPIC/reply."""
    import rclpy
    from rclpy.node import Node
    from std_msgs.msg import String

    topic = (args or sys.argv[1:])[0]
    rclpy.init()
    try:
        node = Node("course_doctor_echo")
        reply = node.create_publisher(String, topic + ECHO_SUFFIX, 10)
        node.create_subscription(String, topic, reply.publish, 10)
        print(ECHO_READY, flush=True)
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        rclpy.try_shutdown()


def run(live: bool = True, timeout: float = 15.0) -> Report:
    """Run every check and return the report (without printing it).

    Args:
        live: also run the two-process pub/sub round trip.
        timeout: seconds to wait for the round trip.
    """
    checks = [_check_python(), _check_install()]
    if checks[-1].ok:
        checks += [_check_messages(), _check_rmw()]
    checks += [_check_network_settings(), _check_large_data(), _check_shared_memory(), _check_opencv()]
    if checks[1].ok:
        checks.append(_check_interface_builds())
        if live:
            checks.append(_check_round_trip(timeout))
    return Report(checks)


def check(live: bool = True) -> Report:
    """The one-line notebook call: print the report; raise if a check failed.

    Raises:
        RuntimeError: naming the failed checks and their fixes.
    """
    report = run(live=live)
    print(report)
    if not report.ok:
        raise RuntimeError("The environment check failed:\n" + "\n".join(c.line() for c in report.failures()))
    return report


def main(argv: list[str] | None = None) -> int:
    import argparse

    parser = argparse.ArgumentParser(prog="python -m course_lib doctor", description=__doc__.split("\n")[0])
    parser.add_argument("--no-live", action="store_true", help="skip the two-process round trip")
    parser.add_argument("--timeout", type=float, default=15.0, help="seconds to wait for the round trip")
    options = parser.parse_args(argv)
    report = run(live=not options.no_live, timeout=options.timeout)
    print(report)
    return 0 if report.ok else 1
