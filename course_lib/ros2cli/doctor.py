"""``ros2 doctor [--report | --report-failed] [--include-warnings]`` and its alias ``ros2 wtf``.

As ros2doctor (Jazzy): each check counts once, its warnings and errors go to stderr as Python
warnings (``FILE: LINE: UserWarning: ...``), and the summary is ``All <n> checks passed`` or
``<f>/<n> check(s) failed`` with ``Failed modules: ...``; the exit code is 0 either way.
``--report`` prints ros2doctor's sections (``   PLATFORM INFORMATION``, ``key : value`` lines).

On the pip install: the platform check and ``ROS 2 INFORMATION`` read the course's copy of the
rosdistro index entry of its distribution (ros2doctor downloads the index; this works offline);
the package check and report (which compare with that index online) and the ``hello`` verb are
not here. The course's own checks (course_lib.notebook.doctor, and what breaks on this install:
a second Fast DDS profile file, another terminal on the same domain with another discovery
range) count as checks of the module they belong to.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import socket
import struct
import typing
import warnings
from pathlib import Path

from course_lib.ros2cli.common import DEFAULT_SPIN_TIME, FULL_INSTALL, VerbParser, unsupported

#: Topics ros2doctor's topic check and report leave out.
SKIP_TOPICS = ("/parameter_events", "/rosout")
#: What rosdistro's index says of the distributions the course knows (ros2doctor reads it online).
ROSDISTRO = {"jazzy": {"distribution_type": "ros2", "distribution_status": "active",
                       "release_platforms": {"debian": ["bookworm"], "rhel": ["9"], "ubuntu": ["noble"]}}}
#: The profile file Fast DDS loads from the working directory, besides FASTRTPS_DEFAULT_PROFILES_FILE's.
CWD_PROFILE = "DEFAULT_FASTRTPS_PROFILES.xml"


# --- ros2doctor's API: reports, results, warnings -----------------------------------------------

class Report:
    """One section of ``--report``: its name and (key, value) items."""

    def __init__(self, name: str):
        self.name = name
        self.items: list[tuple[str, object]] = []

    def add_to_report(self, item_name: str, item_info) -> None:
        self.items.append((item_name, item_info))


class Result:
    """How many errors and warnings one check found."""

    def __init__(self):
        self.error = 0
        self.warning = 0


def format_print(report: Report) -> None:
    """A section as ros2doctor prints it: a blank line, three spaces and the name, then the
    keys padded to the longest one plus 4 (8 at least)."""
    print("\n  ", report.name)
    padding = max([8] + [len(name) + 4 for name, _ in report.items if len(name) >= 8])
    for name, info in report.items:
        print(f"{name:{padding}}: {info}")


def _warning_format(message, category, filename, lineno, file=None, line=None):
    return f"{filename}: {lineno}: {category.__name__}: {message}\n"


def _warn(text: str) -> None:
    previous = warnings.formatwarning
    warnings.formatwarning = _warning_format
    try:
        warnings.warn(text, stacklevel=3)
    finally:
        warnings.formatwarning = previous


def doctor_warn(text: str) -> None:
    _warn(text)


def doctor_error(text: str) -> None:
    _warn(f"ERROR: {text}")


# --- platform -----------------------------------------------------------------------------------

def _distro() -> tuple[str, dict] | None:
    from course_lib.ros import rosenv

    name = (os.environ.get("ROS_DISTRO") or rosenv.detect_install().distro or "").lower()
    if not name:
        doctor_error("ROS_DISTRO is not set.")
        return None
    if name not in ROSDISTRO:
        doctor_warn(f"Distribution name {name} is not found")
        return None
    return name, ROSDISTRO[name]


def check_platform() -> Result:
    result = Result()
    distro = _distro()
    if distro is None:
        doctor_error("Missing rosdistro info. Unable to check platform.")
        result.error += 1
    elif distro[1]["distribution_status"] != "active":
        doctor_warn(f"Distribution {distro[0]} is no longer supported or deprecated. To get the latest "
                    "features, download the new versions at https://docs.ros.org")
        result.warning += 1
    return result


def report_platform() -> Report:
    report = Report("PLATFORM INFORMATION")
    report.add_to_report("system", platform.system())
    report.add_to_report("platform info", platform.platform())
    report.add_to_report("release", platform.release())
    report.add_to_report("processor", platform.processor())
    return report


def report_rosdistro() -> Report:
    report = Report("ROS 2 INFORMATION")
    distro = _distro()
    if distro is not None:
        report.add_to_report("distribution name", distro[0])
        for key in ("distribution_type", "distribution_status", "release_platforms"):
            report.add_to_report(key.replace("_", " "), distro[1][key])
    return report


# --- network ------------------------------------------------------------------------------------

#: The Linux interface flags ros2doctor names, by bit.
NET_FLAGS = ("UP", "BROADCAST", "DEBUG", "LOOPBACK", "PTP", "NOTRAILERS", "RUNNING", "NOARP", "PROMISC",
             "ALLMULTI", "MASTER", "SLAVE", "MULTICAST", "PORTSEL", "AUTOMEDIA", "DYNAMIC")


def interface_flags(name: str) -> tuple[int, list[str]]:
    """The SIOCGIFFLAGS flags of interface ``name`` and their names; (-1, []) when unknown."""
    import fcntl

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        try:
            answer = fcntl.ioctl(probe.fileno(), 0x8913, (name + "\0" * 256).encode())
        except OSError:
            return -1, []
    flags = struct.unpack("H", answer[16:18])[0]
    return flags, [flag for bit, flag in enumerate(NET_FLAGS) if flags & (1 << bit)]


def check_network() -> Result:
    import psutil

    result = Result()
    names = [set(interface_flags(interface)[1]) for interface in psutil.net_if_addrs()]
    if not any("LOOPBACK" in flags for flags in names):
        doctor_error("No loopback IP address is found.")
        result.error += 1
    if not any("LOOPBACK" not in flags for flags in names):
        doctor_warn("Only loopback IP address is found.")
        result.warning += 1
    if not any("MULTICAST" in flags for flags in names):
        doctor_warn("No multicast IP address is found.")
        result.warning += 1
    return result


def report_network() -> Report:
    import psutil

    report = Report("NETWORK CONFIGURATION")
    stats = psutil.net_if_stats()
    for interface, addresses in psutil.net_if_addrs().items():
        info = {"inet": None, "inet4": [], "ether": None, "inet6": [], "netmask": None, "device": interface,
                "flags": None, "mtu": None, "broadcast": None}
        for address in addresses:
            if address.family == socket.AF_INET:
                info.update(inet=address.address, netmask=address.netmask, broadcast=address.broadcast)
                info["inet4"].append(address.address)
            elif address.family == socket.AF_INET6:
                info["inet6"].append(address.address)
            elif address.family == getattr(socket, "AF_PACKET", None) and address.address != "00:00:00:00:00:00":
                info["ether"] = address.address
        if interface in stats:
            info["mtu"] = stats[interface].mtu
        flags, flag_names = interface_flags(interface)
        info["flags"] = f"{flags}<{','.join(flag_names)}>" if flags != -1 else ""
        for key, value in info.items():
            if value:
                report.add_to_report(key, value)
    return report


# --- middleware and topics ------------------------------------------------------------------------

def report_rmw() -> Report:
    from rclpy.utilities import get_rmw_implementation_identifier

    report = Report("RMW MIDDLEWARE")
    report.add_to_report("middleware name", get_rmw_implementation_identifier())
    return report


class Graph:
    """The topics and their endpoints, from the daemon as ros2doctor's NodeStrategy has them (else
    discovered in this process), asked once for all the checks and reports."""

    def __init__(self):
        self._infos = None

    def infos(self) -> list:
        """A graph_info.TopicInfo (verbose: endpoints with QoS) of every topic, hidden ones too."""
        if self._infos is None:
            from course_lib.ros2cli import topic

            args = argparse.Namespace(spin_time=DEFAULT_SPIN_TIME, no_daemon=False)
            names = [name for name, _ in topic._topic_pairs(args, include_hidden=True)]
            infos = [topic._topic_info(args, name, verbose=True, settled=True) for name in names]
            self._infos = [info for info in infos if info is not None]
        return self._infos

    def checked(self) -> list:
        return [info for info in self.infos() if info.name not in SKIP_TOPICS]


def check_topics(graph: Graph) -> Result:
    result = Result()
    for info in graph.checked():
        if info.publisher_count > 0 and info.subscription_count == 0:
            doctor_warn(f"Publisher without subscriber detected on {info.name}.")
            result.warning += 1
        elif info.subscription_count > 0 and info.publisher_count == 0:
            doctor_warn(f"Subscriber without publisher detected on {info.name}.")
            result.warning += 1
    return result


def report_topics(graph: Graph) -> Report:
    report = Report("TOPIC LIST")
    checked = graph.checked()
    if not checked:
        for key, value in (("topic", "none"), ("publisher count", 0), ("subscriber count", 0)):
            report.add_to_report(key, value)
    for info in checked:
        report.add_to_report("topic", info.name)
        report.add_to_report("publisher count", info.publisher_count)
        report.add_to_report("subscriber count", info.subscription_count)
    return report


def qos_profile(summary):
    """An rclpy QoSProfile from a graph_info.QosSummary (what discovery tells of an endpoint)."""
    from rclpy.duration import Duration, Infinite
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, LivelinessPolicy, QoSProfile, ReliabilityPolicy

    def duration(seconds: float):
        return Infinite if math.isinf(seconds) else Duration(nanoseconds=round(seconds * 1e9))

    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=max(1, summary.depth),
                      reliability=ReliabilityPolicy[summary.reliability],
                      durability=DurabilityPolicy[summary.durability],
                      deadline=duration(summary.deadline), lifespan=duration(summary.lifespan),
                      liveliness=LivelinessPolicy[summary.liveliness],
                      liveliness_lease_duration=duration(summary.liveliness_lease_duration))


def qos_pairs(graph: Graph) -> typing.Iterator[tuple]:
    """(topic info, publisher, subscription, compatibility, reason) of every pair on every topic."""
    from rclpy.qos import qos_check_compatible

    for info in graph.infos():
        for publisher in info.publishers:
            for subscription in info.subscriptions:
                compatibility, reason = qos_check_compatible(qos_profile(publisher.qos),
                                                             qos_profile(subscription.qos))
                yield info, publisher, subscription, compatibility, reason


def _without_level(reason: str) -> str:
    for level in ("warning: ", "error: "):
        if reason.lower().startswith(level):
            return reason[len(level):]
    return reason


def check_qos(graph: Graph) -> Result:
    from rclpy.qos import QoSCompatibility

    result = Result()
    for info, _, _, compatibility, reason in qos_pairs(graph):
        if compatibility == QoSCompatibility.WARNING:
            doctor_warn(f"QoS compatibility warning found on topic '{info.name}': {_without_level(reason)}")
            result.warning += 1
        elif compatibility == QoSCompatibility.ERROR:
            doctor_error(f"QoS compatibility error found on topic '{info.name}': {_without_level(reason)}")
            result.error += 1
    return result


def report_qos(graph: Graph) -> Report:
    from rclpy.qos import QoSCompatibility

    report = Report("QOS COMPATIBILITY LIST")
    for info, publisher, subscription, compatibility, reason in qos_pairs(graph):
        report.add_to_report("topic [type]", f"{info.name} [{publisher.topic_type}]")
        report.add_to_report("publisher node", publisher.node_name)
        report.add_to_report("subscriber node", subscription.node_name)
        report.add_to_report("compatibility status", "OK" if compatibility == QoSCompatibility.OK else reason)
    if not report.items:
        report.add_to_report("compatibility status", "No publisher/subscriber pairs found")
    return report


# --- the course's checks ------------------------------------------------------------------------

def course_check(check) -> Result:
    """A course_lib.notebook.doctor Check as ros2doctor counts it: a failure is an error, a
    warning a warning, each with its fix."""
    line = check()
    result = Result()
    text = f"{line.name}: {line.detail}" + (f" (fix: {line.fix})" if line.fix else "")
    if not line.ok:
        doctor_error(text)
        result.error += 1
    elif line.warning:
        doctor_warn(text)
        result.warning += 1
    return result


def fastdds_profile_files(environ=None, folder: Path | None = None) -> list[Path]:
    """The XML profile files Fast DDS loads in a process started in ``folder`` (the working
    directory) with ``environ``: FASTRTPS_DEFAULT_PROFILES_FILE's, and DEFAULT_FASTRTPS_PROFILES.xml
    in the working directory unless SKIP_DEFAULT_XML=1."""
    environ = os.environ if environ is None else environ
    files = [Path(environ["FASTRTPS_DEFAULT_PROFILES_FILE"])] if environ.get("FASTRTPS_DEFAULT_PROFILES_FILE") else []
    local = Path(folder or Path.cwd()) / CWD_PROFILE
    if environ.get("SKIP_DEFAULT_XML") != "1" and local.is_file():
        files.append(local)
    return files


def check_fastdds_profiles() -> Result:
    result = Result()
    files = fastdds_profile_files()
    for missing in [path for path in files if not path.is_file()]:
        doctor_error(f"FASTRTPS_DEFAULT_PROFILES_FILE={missing} does not exist: Fast DDS starts without it "
                     "(fix: export it with an existing file, or unset it)")
        result.error += 1
    if len(files) > 1:
        doctor_warn(f"Fast DDS loads two profile files, {files[0]} and {files[1]}: where both set a default "
                    f"participant, the last one loaded wins (fix: move {CWD_PROFILE} away, or unset "
                    "FASTRTPS_DEFAULT_PROFILES_FILE)")
        result.warning += 1
    return result


def _network_of(environ: dict) -> tuple[str, str]:
    """(ROS_DOMAIN_ID, discovery range) an environment sets, or "" for the range when it sets none."""
    scope = environ.get("ROS_AUTOMATIC_DISCOVERY_RANGE", "").strip().upper()
    if not scope and environ.get("ROS_LOCALHOST_ONLY") == "1":
        scope = "LOCALHOST"
    return environ.get("ROS_DOMAIN_ID", "").strip() or "0", scope


def other_ranges() -> list[tuple[int, str, str]]:
    """(process id, command, range) of this user's ROS processes (they loaded an RMW library) on
    this process's domain whose environment sets another discovery range. Only a range set in a
    process's environment counts: one that set none chose its own (course_lib: LOCALHOST)."""
    import psutil

    domain, scope = _network_of(os.environ)
    found = []
    for process in psutil.process_iter(["pid", "uids", "name"]):
        try:
            if process.info["pid"] == os.getpid() or process.info["uids"].real != os.getuid():
                continue
            theirs = _network_of(process.environ())
            if theirs[0] != domain or theirs[1] in ("", scope):
                continue
            if "librmw_" not in Path(f"/proc/{process.pid}/maps").read_text():
                continue
            found.append((process.pid, " ".join(process.cmdline())[:80], theirs[1]))
        except (psutil.Error, OSError):
            continue  # it ended meanwhile, or is not ours to read
    return found


def check_discovery_ranges() -> Result:
    result = Result()
    domain, scope = _network_of(os.environ)
    for pid, command, theirs in other_ranges():
        doctor_warn(f"process {pid} ({command}) uses ROS_AUTOMATIC_DISCOVERY_RANGE={theirs} in domain {domain}, "
                    f"this terminal {scope or 'SUBNET'}: their nodes may not see each other (fix: export "
                    f"ROS_AUTOMATIC_DISCOVERY_RANGE={scope or 'SUBNET'} there, or {theirs} here)")
        result.warning += 1
    return result


# --- the command ----------------------------------------------------------------------------------

def checks(graph: Graph) -> list[tuple[str, typing.Callable[[], Result]]]:
    """(module, check) in ros2doctor's order, each module's course checks after its own."""
    from course_lib.notebook import doctor

    return [("platform", check_platform),
            ("platform", lambda: course_check(doctor._check_python)),
            ("platform", lambda: course_check(doctor._check_install)),
            ("network", check_network),
            ("network", lambda: course_check(doctor._check_network_settings)),
            ("network", check_discovery_ranges),
            ("topic", lambda: check_topics(graph)),
            ("middleware", lambda: check_qos(graph)),
            ("middleware", lambda: course_check(doctor._check_rmw)),
            ("middleware", check_fastdds_profiles),
            ("middleware", lambda: course_check(doctor._check_large_data)),
            ("middleware", lambda: course_check(doctor._check_shared_memory))]


def reports(graph: Graph) -> list[tuple[str, typing.Callable[[], Report]]]:
    return [("platform", report_platform), ("platform", report_rosdistro), ("network", report_network),
            ("middleware", report_rmw), ("topic", lambda: report_topics(graph)),
            ("middleware", lambda: report_qos(graph))]


def run_checks(graph: Graph, include_warnings: bool = False) -> tuple[list[str], int, int]:
    """(failed modules in check order, failed checks, checks run), as ros2doctor's run_checks."""
    failed, fail, total = [], 0, 0
    for module, check in checks(graph):
        try:
            result = check()
        except Exception as error:  # as ros2doctor: a check that breaks is not counted
            doctor_warn(f"Fail to call {module} check functions: {error}")
            continue
        total += 1
        if result.error or (include_warnings and result.warning):
            fail += 1
            if module not in failed:
                failed.append(module)
    return failed, fail, total


def print_reports(graph: Graph, modules: list[str] | None = None) -> None:
    for module, report in reports(graph):
        if modules is None or module in modules:
            try:
                format_print(report())
            except Exception as error:
                doctor_warn(f"Fail to call {module} report functions: {error}")


def parser(prog: str) -> VerbParser:
    top = VerbParser(prog=prog, description="Check ROS setup and other potential issues",
                     epilog=f"Not here: the package check and report, the hello verb; {FULL_INSTALL}.")
    group = top.add_mutually_exclusive_group(required=False)
    group.add_argument("--report", "-r", action="store_true", help="Print all reports.")
    group.add_argument("--report-failed", "-rf", action="store_true", help="Print reports of failed checks only.")
    top.add_argument("--exclude-packages", "-ep", action="store_true",
                     help="Exclude package checks or report (the course's ros2 has none).")
    top.add_argument("--include-warnings", "-iw", action="store_true",
                     help="Include warnings as failed checks. Warnings are ignored by default.")
    return top


def main(argv: list[str], prog: str = "ros2 doctor") -> None:
    verbs = [word for word in argv if not word.startswith("-")]
    if verbs:
        raise unsupported(f"{prog} {verbs[0]}", ["--report", "--report-failed", "--include-warnings",
                                                  "--exclude-packages"])
    args = parser(prog).parse_args(argv)
    graph = Graph()
    if args.report:
        print_reports(graph)
        return None
    failed, fail, total = run_checks(graph, include_warnings=args.include_warnings)
    if fail:
        print(f"\n{fail}/{total} check(s) failed\n")
        print("Failed modules:", *failed)
    else:
        print(f"\nAll {total} checks passed\n")
    if args.report_failed and fail:
        print_reports(graph, failed)
    return None
