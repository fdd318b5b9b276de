"""``ros2 doctor`` and ``ros2 wtf`` (course_lib.ros2cli.doctor), held to ros2doctor's words (Jazzy:
ros2doctor/command/doctor.py, api/format.py, api/topic.py, test/test_api.py and
test/test_qos_compatibility.py), and the course's own checks of what breaks on the pip install."""

import select
import signal
import subprocess
import sys
import types

import pytest
from support.ros2cli import node_script, ros2

from course_lib.ros import processes, rosenv
from course_lib.ros2cli import doctor

# As ros2doctor's test fixtures: a talker with a best-effort and a reliable publisher, a listener
# with reliable subscriptions to both; and a publisher nobody listens to.
NODES = node_script('''
import sys

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

RELIABLE = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)


class Talker(Node):
    def __init__(self):
        super().__init__('talker_node')
        best_effort = QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT)
        self.publishers_ = [self.create_publisher(String, 'incompatible_chatter', best_effort),
                            self.create_publisher(String, 'compatible_chatter', RELIABLE),
                            self.create_publisher(String, 'lonely_chatter', RELIABLE)]


class Listener(Node):
    def __init__(self):
        super().__init__('listener')
        for topic in ('incompatible_chatter', 'compatible_chatter'):
            self.create_subscription(String, topic, lambda msg: None, RELIABLE)
''', "Talker() if sys.argv[1] == 'talker' else Listener()")


@pytest.fixture(scope="module")
def live(tmp_path_factory):
    """The talker and the listener, each in a process of its own, on a reserved domain."""
    script = tmp_path_factory.mktemp("doctor") / "qos_nodes.py"
    script.write_text(NODES)
    with rosenv.reserve_domain_id() as reservation:
        started = []
        try:
            for role, node in (("talker", "talker_node"), ("listener", "listener")):
                started.append(processes.NodeProcess([sys.executable, str(script), role], name=node,
                                                     domain_id=reservation.domain_id).start())
            for process in started:
                process.wait_for_node(process.name, timeout=30)
            yield types.SimpleNamespace(env=rosenv.ros_environment(domain_id=reservation.domain_id),
                                        domain_id=reservation.domain_id)
        finally:
            for process in started:
                process.stop()


def test_failed_modules_name_the_incompatible_qos_and_the_exit_code_stays_0(live):
    """ros2doctor's test_check: 'Failed modules' and 'middleware' on the last line, EXIT_OK;
    the error as ros2doctor words it, on stderr."""
    done = ros2("doctor", env=live.env)
    lines = [line for line in done.stdout.splitlines() if line]
    assert "Failed modules" in lines[-1] and "middleware" in lines[-1], done.stdout
    assert lines[-2].endswith(" check(s) failed") and lines[-1] == "Failed modules: middleware", done.stdout
    assert ("UserWarning: ERROR: QoS compatibility error found on topic '/incompatible_chatter': "
            "Best effort publisher and reliable subscription;") in done.stderr
    # ros2doctor's topic check: a warning, which fails its module only with --include-warnings.
    assert "UserWarning: Publisher without subscriber detected on /lonely_chatter." in done.stderr
    assert "Publisher without subscriber detected on /compatible_chatter" not in done.stderr
    with_warnings = ros2("wtf", "--include-warnings", env=live.env).stdout.splitlines()[-1]
    assert with_warnings.startswith("Failed modules: ") and "topic" in with_warnings.split(), with_warnings


def test_report_lays_out_ros2doctors_sections_and_qos_pairs(live):
    """ros2doctor's test_report (-r and --report): the QoS pairs in its padded key : value lines."""
    for flag in ("-r", "--report"):
        out = ros2("doctor", flag, env=live.env).stdout
        assert ("topic [type]            : /compatible_chatter [std_msgs/msg/String]\n"
                "publisher node          : talker_node\n"
                "subscriber node         : listener\n"
                "compatibility status    : OK") in out
        assert ("topic [type]            : /incompatible_chatter [std_msgs/msg/String]\n"
                "publisher node          : talker_node\n"
                "subscriber node         : listener\n"
                "compatibility status    : ERROR: Best effort publisher and reliable subscription;") in out
    sections = [line for line in out.splitlines() if line.startswith("   ")]
    assert sections == ["   PLATFORM INFORMATION", "   ROS 2 INFORMATION", "   NETWORK CONFIGURATION",
                        "   RMW MIDDLEWARE", "   TOPIC LIST", "   QOS COMPATIBILITY LIST"], out
    assert "\ntopic               : /lonely_chatter\npublisher count     : 1\nsubscriber count    : 0\n" in out
    assert "/rosout" not in out.split("   TOPIC LIST")[1].split("   QOS")[0]  # ros2doctor's SKIP_TOPICS
    assert "middleware name    : rmw_fastrtps_cpp" in out and "distribution name      : jazzy" in out
    assert "flags        : 73<UP,LOOPBACK,RUNNING>" in out  # lo, as ifconfig gives its flags


def test_report_failed_prints_only_the_failed_modules_reports(live):
    out = ros2("doctor", "--report-failed", env=live.env).stdout
    assert "Failed modules: middleware" in out
    assert "   RMW MIDDLEWARE" in out and "   QOS COMPATIBILITY LIST" in out and "   TOPIC LIST" not in out


def test_an_empty_graph_passes_and_reports_no_topic():
    """ros2doctor's test_topic_check and test_topic_report: no topic but the skipped ones: no
    topic warning, and the report's one entry 'none', 0, 0. The summary is ros2doctor's."""
    with rosenv.reserve_domain_id() as reservation:
        env = rosenv.ros_environment(domain_id=reservation.domain_id)
        check = ros2("doctor", env=env)  # warnings (this machine's /dev/shm, say) do not fail it
        report = ros2("doctor", "--report", env=env).stdout
    summary = check.stdout
    assert summary.startswith("\nAll ") and summary.endswith(" checks passed\n\n"), summary + check.stderr
    assert "\n   TOPIC LIST\ntopic               : none\npublisher count     : 0\nsubscriber count    : 0\n" in report
    assert "compatibility status    : No publisher/subscriber pairs found" in report
    assert "without" not in check.stderr


def test_what_is_not_there_is_one_line_and_exit_code_2(live):
    done = ros2("doctor", "hello", env=live.env, check=False)
    assert done.returncode == 2 and done.stderr.startswith("ros2 doctor hello is not supported by the course's ros2")
    assert "usage: ros2 wtf" in ros2("wtf", "--help", env=live.env).stdout


def test_format_print_pads_as_ros2doctor(capsys):
    """api/format.py: at least 8, else the longest key plus 4."""
    report = doctor.Report("SHORT")
    report.add_to_report("a", 1)
    doctor.format_print(report)
    long = doctor.Report("LONG")
    long.add_to_report("eightchr", "x")
    doctor.format_print(long)
    assert capsys.readouterr().out == "\n   SHORT\na       : 1\n\n   LONG\neightchr    : x\n"


def test_a_second_fastdds_profile_file_is_a_warning_and_a_missing_one_an_error(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("SKIP_DEFAULT_XML", raising=False)
    monkeypatch.setenv("FASTRTPS_DEFAULT_PROFILES_FILE", str(rosenv.FASTDDS_PROFILE))
    assert doctor.fastdds_profile_files() == [rosenv.FASTDDS_PROFILE]
    result = doctor.check_fastdds_profiles()
    assert (result.error, result.warning) == (0, 0)
    (tmp_path / doctor.CWD_PROFILE).write_text("<dds/>")
    with pytest.warns(UserWarning, match="Fast DDS loads two profile files"):
        result = doctor.check_fastdds_profiles()
    assert (result.error, result.warning) == (0, 1)
    monkeypatch.setenv("SKIP_DEFAULT_XML", "1")  # Fast DDS then skips the working directory's file
    monkeypatch.setenv("FASTRTPS_DEFAULT_PROFILES_FILE", str(tmp_path / "gone.xml"))
    with pytest.warns(UserWarning, match="ERROR: FASTRTPS_DEFAULT_PROFILES_FILE=.*gone.xml does not exist"):
        assert doctor.check_fastdds_profiles().error == 1


def test_a_bad_domain_id_fails_the_network_module(monkeypatch):
    from course_lib.notebook import doctor as course_doctor

    monkeypatch.setenv("ROS_DOMAIN_ID", "300")
    with pytest.warns(UserWarning, match=r"ERROR: ROS_DOMAIN_ID: .*export ROS_DOMAIN_ID=<0\.\.101>"):
        assert doctor.course_check(course_doctor._check_network_settings).error == 1


def test_a_process_on_the_same_domain_with_another_discovery_range_is_named(monkeypatch):
    """Two terminals, one with ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET, one with LOCALHOST, same domain."""
    code = ("import rclpy, rclpy.node, time; rclpy.init(); n = rclpy.node.Node('subnet_here'); "
            "print('ready', flush=True); time.sleep(60)")
    with rosenv.reserve_domain_id() as reservation:
        env = {**rosenv.ros_environment(domain_id=reservation.domain_id), "ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET"}
        process = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True, env=env)
        try:
            ready, _, _ = select.select([process.stdout], [], [], 60)
            assert ready and process.stdout.readline().strip() == "ready"
            monkeypatch.setenv("ROS_DOMAIN_ID", str(reservation.domain_id))
            monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
            # Only this one is known to be there: a daemon of an earlier reservation of the domain may end late.
            assert (process.pid, "SUBNET") in [(pid, scope) for pid, _, scope in doctor.other_ranges()]
            with pytest.warns(UserWarning, match=f"process {process.pid} .* uses ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET "
                                                 f"in domain {reservation.domain_id}, this terminal LOCALHOST"):
                assert doctor.check_discovery_ranges().warning >= 1
            monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "SUBNET")
            assert process.pid not in [pid for pid, _, _ in doctor.other_ranges()]
        finally:
            process.send_signal(signal.SIGKILL)
            process.wait(timeout=10)
            process.stdout.close()
