"""Where ROS 2 comes from, and the environment every ROS process of the course runs in.

The course runs on three kinds of ROS 2 Jazzy install, and this module is the one place that
tells them apart:

- ``pip``: the ros-jazzy-* wheels from PyPI inside the project's virtual environment;
- ``system``: the Debian packages under ``/opt/ros/jazzy`` (Ubuntu 24.04), sourced in the shell;
- ``conda``: RoboStack in a conda/mamba environment, activated in the shell.

Traffic isolation is also written once here: every process the course starts gets a
``ROS_DOMAIN_ID`` of its own and ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``. So is the Fast DDS
set-up for camera frames (:func:`large_data_environment`), which every ROS process the course
starts, the notebook's own session and ``make lab``'s terminals share.
"""

from __future__ import annotations

import dataclasses
import errno
import fcntl
import importlib.util
import os
import shlex
import shutil
import sys
import tempfile
import time
from pathlib import Path

from course_lib import contract

DISTRO = "jazzy"
SYSTEM_PREFIX = Path("/opt/ros") / DISTRO

#: Domain ids handed out to test runs and graders. Fast DDS maps a domain to UDP ports
#: 7400 + 250 * id, so ids above 232 do not fit; 0 stays free for the student's own session.
RESERVABLE_DOMAIN_IDS = range(1, 102)

#: The course's Fast DDS profile for camera frames: the default transports (shared memory, then
#: UDP) with 32 MB shared-memory segments instead of 512 KB. With the defaults a best-effort
#: subscriber in another process gets about half of the 640x480 frames and a fifth of the
#: 1920x1080 ones at 30 Hz; with it, all of them (benchmarks/bench_vision.py measures both).
FASTDDS_PROFILE = Path(__file__).resolve().with_name("fastdds_large_data.xml")

#: The variables by which a user picks Fast DDS transports; when one is set the course adds none.
FASTDDS_USER_SETTINGS = ("FASTRTPS_DEFAULT_PROFILES_FILE", "FASTDDS_BUILTIN_TRANSPORTS")

#: Every ROS process with FASTDDS_PROFILE keeps a 32 MB segment in /dev/shm. Where /dev/shm is
#: smaller than this (Docker's default is 64 MB), Fast DDS's defaults are kept: with the profile,
#: the fourth process would print errors and fall back to UDP.
SHARED_MEMORY_NEEDED_MB = 512

#: numpy's OpenBLAS starts a thread per core when numpy is imported, and those threads spin before
#: they sleep: about 0.1 s of processor time in every process that imports numpy (rclpy does),
#: for nothing, since ROS nodes and image code do no BLAS work worth threads. The course's ROS
#: processes run with one BLAS thread unless the user chose a number.
BLAS_THREADS = {"OPENBLAS_NUM_THREADS": "1"}


@dataclasses.dataclass(frozen=True)
class RosInstall:
    """What provides rclpy in this interpreter.

    Attributes:
        kind: "pip", "system", "conda" or "missing".
        rclpy_path: the directory rclpy is imported from (None when missing).
        prefixes: ament prefixes that hold the ament index (share/ament_index).
        distro: the ROS distribution name from ROS_DISTRO or the install layout.
    """

    kind: str
    rclpy_path: Path | None
    prefixes: tuple[Path, ...]
    distro: str | None

    def describe(self) -> str:
        if self.kind == "missing":
            return "rclpy is not importable"
        names = {"pip": "pip wheels (ros-jazzy-* from PyPI)", "system": "system install",
                 "conda": "conda environment (RoboStack)"}
        return f"{names[self.kind]} at {self.rclpy_path}"


def _has_ament_index(prefix: Path) -> bool:
    try:
        return (prefix / "share" / "ament_index" / "resource_index").is_dir()
    except PermissionError:  # a prefix on AMENT_PREFIX_PATH this user may not read: not an install of theirs
        return False


def _env_prefixes() -> list[Path]:
    return [Path(p) for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]


def detect_install() -> RosInstall:
    """Find out where rclpy comes from without importing it (importing it can be slow)."""
    spec = importlib.util.find_spec("rclpy")
    if spec is None or not spec.submodule_search_locations:
        return RosInstall("missing", None, tuple(_env_prefixes()), os.environ.get("ROS_DISTRO"))
    rclpy_path = Path(next(iter(spec.submodule_search_locations))).resolve()
    prefixes = _env_prefixes()
    conda_prefix = os.environ.get("CONDA_PREFIX")
    if rclpy_path.is_relative_to(SYSTEM_PREFIX.resolve() if SYSTEM_PREFIX.exists() else SYSTEM_PREFIX):
        kind = "system"
    elif conda_prefix and rclpy_path.is_relative_to(Path(conda_prefix).resolve()):
        kind = "conda"
        prefixes.append(Path(conda_prefix))
    elif _pip_wheels_installed(rclpy_path):
        kind = "pip"
        prefixes.insert(0, Path(sys.prefix))
    else:
        # Some other prefix (a source build, a colcon overlay): treat it like a sourced install.
        kind = "system"
    distro = os.environ.get("ROS_DISTRO") or (DISTRO if kind == "pip" else None)
    return RosInstall(kind, rclpy_path, tuple(unique(p for p in prefixes if _has_ament_index(p))), distro)


def _pip_wheels_installed(rclpy_path: Path) -> bool:
    """True when this rclpy is the ros-jazzy-rclpy wheel's: the wheel's metadata lies beside it.
    (A look at one folder: importlib.metadata would cost every process that imports course_lib
    about 50 ms of imports and a scan of every installed distribution.)"""
    return any(rclpy_path.parent.glob("ros_jazzy_rclpy-*.dist-info"))


def environment_tool(name: str) -> Path | None:
    """The command `name` of this environment: beside this interpreter (the venv's bin/, where
    `make setup` and the pip wheels put colcon, fastdds and ros2), else on PATH (a sourced ROS
    install); None when neither has it."""
    candidate = Path(sys.executable).parent / name
    if candidate.is_file():
        return candidate
    found = shutil.which(name)
    return Path(found) if found else None


def load_factor(maximum: float) -> float:
    """The machine's load per core over the last minute, kept between 1 and `maximum`: how many
    times longer than on an idle machine a wait on other processes may take (each of them gets
    that fraction of a core)."""
    return min(maximum, max(1.0, os.getloadavg()[0] / (os.cpu_count() or 1)))


def unique(items) -> list:
    """The items in their first order, each once (for PATH-like lists)."""
    return list(dict.fromkeys(items))


def ros_environment(domain_id: int | None = None, base: dict[str, str] | None = None,
                    install: RosInstall | None = None) -> dict[str, str]:
    """The environment for a ROS child process (a node, colcon, a kernel).

    Args:
        domain_id: ROS_DOMAIN_ID for the child; None keeps the caller's (or 0).
        base: the environment to start from; defaults to os.environ.
        install: the detected install; detected when None.

    Returns:
        A new dict: discovery limited to this machine, the ament index of the install
        reachable through AMENT_PREFIX_PATH, this interpreter's bin/ first on PATH,
        unbuffered Python output so that logs arrive while the node runs, and one BLAS
        thread (BLAS_THREADS) unless the base environment chose a number.
    """
    env = dict(os.environ if base is None else base)
    install = install or detect_install()
    if domain_id is not None:
        check_domain_id(domain_id)
        env["ROS_DOMAIN_ID"] = str(domain_id)
    env.setdefault("ROS_DOMAIN_ID", "0")
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    env.pop("ROS_LOCALHOST_ONLY", None)  # deprecated in Jazzy; warns when set
    prefixes = unique([str(p) for p in install.prefixes]
                       + [p for p in env.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p])
    if prefixes:
        env["AMENT_PREFIX_PATH"] = os.pathsep.join(prefixes)
    bindir = str(Path(sys.executable).parent)
    path = env.get("PATH", "").split(os.pathsep)
    env["PATH"] = os.pathsep.join([bindir] + [p for p in path if p and p != bindir])
    env["PYTHONUNBUFFERED"] = "1"
    keep_blas_to_one_thread(env)
    env.update(large_data_environment(env))
    return env


def keep_blas_to_one_thread(environ) -> None:
    """Give an environment (a dict, or os.environ for this process's children) BLAS_THREADS
    where the user has not chosen a number of threads."""
    for name, value in BLAS_THREADS.items():
        environ.setdefault(name, value)


def large_data_environment(environ: dict[str, str] | None = None) -> dict[str, str]:
    """The course's Fast DDS set-up for camera frames, as the variables to add to an environment.

    Only the sending process needs it, but the course gives it to every ROS process it starts
    (ros_environment), to the notebook's session (prepare_current_process) and to JupyterLab's
    terminals (``make lab``), so that a node a student writes sends full frames too.

    Args:
        environ: the environment to complete; defaults to os.environ.

    Returns:
        ``{"FASTRTPS_DEFAULT_PROFILES_FILE": FASTDDS_PROFILE}``, or nothing when the environment
        already picks its transports (FASTDDS_USER_SETTINGS: the user's choice is kept) or when
        /dev/shm is smaller than SHARED_MEMORY_NEEDED_MB.
    """
    environ = os.environ if environ is None else environ
    if any(environ.get(name) for name in FASTDDS_USER_SETTINGS):
        return {}
    if shared_memory_mb() < SHARED_MEMORY_NEEDED_MB:
        return {}
    return {"FASTRTPS_DEFAULT_PROFILES_FILE": str(FASTDDS_PROFILE)}


def shared_memory_mb() -> int:
    """The size of /dev/shm in MB (0 when there is none), where Fast DDS keeps its segments."""
    try:
        stats = os.statvfs("/dev/shm")
    except OSError:
        return 0
    return stats.f_blocks * stats.f_frsize // (1024 * 1024)


#: Environment variables that prepare_current_process() set because the user had not.
DEFAULTS_APPLIED: set[str] = set()


def prepare_current_process() -> None:
    """Give this interpreter what sourcing a ROS setup file would: the ament index, the course's
    discovery range and its Fast DDS set-up (each kept when the user set one). Called when
    course_lib is imported, so before the notebook's session creates its first node (Fast DDS
    reads the variable then; a kernel that called rclpy.init() first keeps the defaults).

    Only the pip install needs this: the wheels register their packages in sys.prefix's ament
    index, but nothing puts sys.prefix on AMENT_PREFIX_PATH, so ament_index_python (and every
    tool built on it) finds nothing; and the venv's bin/, where the course's ``ros2`` lives,
    goes on PATH as activating the venv would put it.
    """
    install = detect_install()
    paths = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    missing = [str(p) for p in install.prefixes if str(p) not in paths]
    if missing:
        os.environ["AMENT_PREFIX_PATH"] = os.pathsep.join(paths + missing)
    bindir = str(Path(sys.executable).parent)
    if install.kind == "pip" and bindir not in os.environ.get("PATH", "").split(os.pathsep):
        # The course's `ros2` lives next to this interpreter: `!ros2 ...` in a kernel that was
        # not started from an activated venv finds it only so.
        os.environ["PATH"] = os.pathsep.join([bindir] + [p for p in os.environ.get("PATH", "").split(os.pathsep) if p])
    if "ROS_LOCALHOST_ONLY" not in os.environ and "ROS_AUTOMATIC_DISCOVERY_RANGE" not in os.environ:
        os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
        DEFAULTS_APPLIED.add("ROS_AUTOMATIC_DISCOVERY_RANGE")
    for name, value in large_data_environment().items():
        os.environ[name] = value
        DEFAULTS_APPLIED.add(name)


#: What prepare_current_process() may set, in the order `python -m course_lib env` prints them.
SESSION_VARIABLES = ("AMENT_PREFIX_PATH", "ROS_AUTOMATIC_DISCOVERY_RANGE") + FASTDDS_USER_SETTINGS


def main_env(argv: list[str] | None = None) -> int:
    """``python -m course_lib env``: print the session's variables as shell ``export`` lines.

    ``eval "$(python -m course_lib env)"`` gives a shell (``make lab`` gives JupyterLab, and so
    its terminals and ``!`` commands) the same ROS environment as a notebook that imported
    course_lib.
    """
    if argv:
        print(f"python -m course_lib env takes no arguments, got {' '.join(argv)}", file=sys.stderr)
        return 2
    for name in SESSION_VARIABLES:
        if os.environ.get(name):
            print(f"export {name}={shlex.quote(os.environ[name])}")
    return 0


def check_domain_id(domain_id: int) -> int:
    """Raise ValueError with the valid range unless domain_id works with Fast DDS on Linux."""
    if not isinstance(domain_id, int) or not 0 <= domain_id <= 232:
        raise ValueError(f"ROS_DOMAIN_ID {domain_id!r} is out of range: use an integer from 0 to 232 "
                         "(0-101 is the safe range on Linux)")
    return domain_id


class DomainReservation:
    """A ROS_DOMAIN_ID held for this process through a lock file, so parallel runs never share one.

    Use as a context manager or call release(). The lock is an flock, so it is released by
    the kernel when the holder dies, even on SIGKILL.
    """

    def __init__(self, domain_id: int, handle):
        self.domain_id = domain_id
        self._handle = handle

    def release(self) -> None:
        if self._handle is not None:
            self._handle.close()
            self._handle = None

    def __enter__(self) -> DomainReservation:
        return self

    def __exit__(self, *exc) -> None:
        self.release()

    def __repr__(self) -> str:
        return f"DomainReservation({self.domain_id})"


def reservation_token(domain_id: int) -> str | None:
    """The token of the current reservation of `domain_id` (reserve_domain_id), None when nobody
    holds it."""
    path = reservation_dir() / f"{domain_id}.lock"
    try:
        with open(path) as handle:
            try:
                fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as error:
                if error.errno in (errno.EAGAIN, errno.EACCES):
                    return handle.read().strip() or None
                raise
            fcntl.flock(handle, fcntl.LOCK_UN)
            return None
    except FileNotFoundError:
        return None


def reservation_dir() -> Path:
    """The folder of this user's domain reservations (one lock file per reserved domain id)."""
    path = Path(tempfile.gettempdir()) / f"course_lib-domains-{os.getuid()}"
    path.mkdir(mode=0o700, exist_ok=True)
    return path


def reserve_domain_id(candidates=RESERVABLE_DOMAIN_IDS) -> DomainReservation:
    """Reserve a domain id no other process on this machine holds through this function.

    Raises:
        RuntimeError: every candidate is taken (stop other test or grading runs).
    """
    lock_dir = reservation_dir()
    start = os.getpid() % len(candidates)  # spread parallel callers over the range
    ordered = list(candidates)[start:] + list(candidates)[:start]
    for domain_id in ordered:
        handle = open(lock_dir / f"{domain_id}.lock", "a+")
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as error:
            handle.close()
            if error.errno in (errno.EAGAIN, errno.EACCES):
                continue
            raise
        # Each reservation writes a token of its own into the file: what outlives one reservation
        # (a ros2 daemon) tells it from the next one of the same id (reservation_token).
        handle.seek(0)
        handle.truncate()
        handle.write(f"{os.getpid()} {time.monotonic_ns()}\n")
        handle.flush()
        return DomainReservation(domain_id, handle)
    raise RuntimeError(f"All ROS domain ids {candidates.start}-{candidates.stop - 1} are reserved by "
                       f"other processes (locks in {lock_dir}); wait for other test or grading runs to end")


#: Who runs (contract.under_test, contract.under_grading), where notebooks ask it:
#: ``if not rosenv.under_grading(): ...``.
under_test = contract.under_test
under_grading = contract.under_grading
