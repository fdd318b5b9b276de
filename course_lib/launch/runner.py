"""Run a launch file: start its processes, show their output like ``ros2 launch``, stop them all.

Each node, and each other program (``<executable>``), runs as a course_lib.ros.processes.NodeProcess
(own process group, bounded log, never an orphan). What the real tool prints, this prints the
same way::

    [INFO] [launch]: All log files can be found below /home/student/.ros/log/2025-...
    [INFO] [talker-1]: process started with pid [4242]
    [talker-1] [INFO] [1736942400.123456789] [talker]: Publishing: 'Hello World: 1'
    [INFO] [talker-1]: process has finished cleanly [pid 4242]

As with the real tool, ``output="screen"`` shows a node's stdout and stderr, the default
``output="log"`` shows only its stderr (where ROS log lines go) and keeps the rest in
``launch.log``, and ``output="both"`` does both.

In a notebook, ``launch.start(...)`` returns a Launch whose ``.log`` is what the terminal
would show; starting the same file again stops the previous run first, and every launch stops
when the kernel does.
"""

from __future__ import annotations

import atexit
import datetime
import itertools
import os
import signal
import socket
import threading
import time
from collections import deque
from collections.abc import Callable
from pathlib import Path

from course_lib.launch.actions import LaunchContext, run_launch_file
from course_lib.launch.entities import LaunchFileError
from course_lib.launch.executables import ProcessToStart
from course_lib.ros import processes

#: How a launch stops a process that still runs, as ros2/launch's ExecuteLocal does: SIGINT, then
#: SIGTERM after ``sigterm_timeout`` seconds, then SIGKILL after ``sigkill_timeout`` seconds more.
#: Both are launch configurations (``ros2 launch FILE sigterm_timeout:=2``); these are their
#: defaults, as text, the way the real tool prints them.
STOP_TIMEOUTS = {"sigterm_timeout": "5", "sigkill_timeout": "5"}

#: Seconds stop() waits at most, after SIGKILL, for the reports of the processes' ends.
_REPORT_BACKSTOP = 30.0

#: Lines of screen output a Launch keeps for ``.log`` (the oldest are dropped beyond it).
KEPT_LINES = 20000

#: Process numbers, as the real tool counts them: one count for the whole Python process.
_PROCESS_NUMBERS = itertools.count(1)


def log_root(environment=os.environ) -> Path:
    """Where ROS 2 keeps logs: ROS_LOG_DIR, else ROS_HOME/log, else ~/.ros/log."""
    folder = environment.get("ROS_LOG_DIR") or os.path.join(environment.get("ROS_HOME") or "~/.ros", "log")
    return Path(os.path.normpath(os.path.expanduser(folder)))


def _new_log_dir() -> Path:
    """A fresh launch log folder named like the real tool's, with the ``latest`` link renewed."""
    root = log_root()
    while True:
        stamp = datetime.datetime.now().strftime("%Y-%m-%d-%H-%M-%S-%f")
        folder = root / f"{stamp}-{socket.gethostname()}-{os.getpid()}"
        if not folder.exists():
            break
    folder.mkdir(parents=True)
    latest = root / "latest"
    try:
        if latest.is_symlink():
            latest.unlink()
        if not latest.exists():
            latest.symlink_to(folder, target_is_directory=True)
    except OSError:  # another launch renewed it at the same moment
        pass
    return folder


def text_argument(value) -> str:
    """A Python value as a launch argument's text (True becomes "true", like YAML writes it)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


class Launch:
    """One run of a launch file: its processes, its output and its log.

    Args:
        path: the launch file.
        arguments: its arguments, as ``name:=value`` on the command line.
        screen: called with each line the terminal shows (None keeps them in ``.log`` only).
        force_output: "both" makes every node show all its output (``ros2 launch -a``).

    Attributes:
        path: the launch file.
        processes: the NodeProcess of every process started (nodes and others), in order.
        names: their process names (``talker-1``), in the same order.
        log_dir: the folder of this launch's ``launch.log``.
    """

    def __init__(self, path, arguments: dict | None = None, *, screen: Callable[[str], None] | None = None,
                 force_output: str | None = None):
        self.path = Path(os.path.abspath(path))
        self.arguments = {name: text_argument(value) for name, value in (arguments or {}).items()}
        self.processes: list[processes.NodeProcess] = []
        self.names: list[str] = []
        self._screen = screen
        self._force_output = force_output
        self._lines: deque[str] = deque(maxlen=KEPT_LINES)
        self._lock = threading.RLock()  # the Ctrl-C handler may log while a line is written
        self._pending: dict[tuple[int, str], bytes] = {}
        self._to_start: list[ProcessToStart] = []
        self._context: LaunchContext | None = None
        self._done = threading.Event()
        self._monitor: threading.Thread | None = None
        self._stopping = False
        self.log_dir = _new_log_dir()
        self._log_file = open(self.log_dir / "launch.log", "a", buffering=1)
        self.info("launch", f"All log files can be found below {self.log_dir}")
        self.info("launch", "Default logging verbosity is set to INFO")

    def __repr__(self) -> str:
        states = []
        # strict=False: start() in another thread may have appended a name but not yet its process.
        for name, process in zip(self.names, self.processes, strict=False):
            state = f"running (pid {process.pid})" if process.running() else process.describe_exit()
            states.append(f"{name} {state}")
        return f"<Launch {self.path.name}: {', '.join(states) or 'no processes'}>"

    # -- what the terminal shows --------------------------------------------------------------

    @property
    def log(self) -> str:
        """Everything this launch showed (or would show) in the terminal, one line each."""
        with self._lock:
            return "".join(line + "\n" for line in self._lines)

    def _emit(self, line: str, *, screen: bool = True, logged: bool = True) -> None:
        with self._lock:
            if screen:
                self._lines.append(line)
                if self._screen is not None:
                    self._screen(line)
            if logged and not self._log_file.closed:
                self._log_file.write(f"{time.time():.7f} {line}\n")

    def info(self, logger: str, message: str) -> None:
        self._emit(f"[INFO] [{logger}]: {message}")

    def warning(self, logger: str, message: str) -> None:
        self._emit(f"[WARNING] [{logger}]: {message}")

    def error(self, logger: str, message: str) -> None:
        self._emit(f"[ERROR] [{logger}]: {message}")

    def _output(self, index: int, output: str, stream: str, data: bytes) -> None:
        """A node's output, split into lines prefixed with its process name."""
        key = (index, stream)
        text = self._pending.pop(key, b"") + data
        *lines, rest = text.split(b"\n")
        if rest:
            self._pending[key] = rest
        for line in lines:
            self._node_line(index, output, stream, line)

    def _node_line(self, index: int, output: str, stream: str, line: bytes) -> None:
        output = self._force_output or output
        on_screen = output in ("screen", "both") or (output == "log" and stream == "stderr")
        self._emit(f"[{self.names[index]}] {line.decode(errors='replace')}", screen=on_screen,
                   logged=output in ("log", "both"))

    # -- running ------------------------------------------------------------------------------

    def prepare(self) -> list[ProcessToStart]:
        """Run the launch file's actions (arguments, includes, groups...) into the processes to start.

        Raises:
            LaunchFileError: the file cannot run as written (the message has its line).
        """
        context = run_launch_file(self.path, self.arguments)
        self._context, self._to_start = context, context.processes
        try:
            self.stop_timeouts()  # a bad one shows now, not when the launch stops
        except LaunchFileError:
            context.remove_files()
            raise
        for logger, message in context.warnings:
            self.warning(logger, message)
        return self._to_start

    def start(self) -> Launch:
        """Start every process (prepare() first if it was not called) and return self."""
        if self._context is None:
            self.prepare()
        for to_start in self._to_start:
            self._start_process(to_start)
        self._monitor = threading.Thread(target=self._watch, name=f"course_lib-launch-{self.path.name}",
                                         daemon=True)
        self._monitor.start()
        return self

    def _start_process(self, to_start: ProcessToStart) -> None:
        index = len(self.processes)
        name = f"{to_start.label}-{next(_PROCESS_NUMBERS)}"
        process = processes.NodeProcess(
            to_start.command, name=name, env=to_start.environment, cwd=to_start.cwd,
            on_output=lambda stream, data: self._output(index, to_start.output, stream, data))
        self.names.append(name)
        self.processes.append(process)
        try:
            process.start()
        except OSError as error:
            self.error(name, f"exception occurred while executing process:\n{error}")
            return
        self.info(name, f"process started with pid [{process.pid}]")

    def _watch(self) -> None:
        """Report each process's end as it happens; finish when all have ended."""
        reported = set()
        while len(reported) < len(self.processes):
            for index, process in enumerate(self.processes):
                if index not in reported and process.returncode is not None:
                    reported.add(index)
                    self._report_exit(index, process)
            time.sleep(0.05)
        self._finish()

    def _report_exit(self, index: int, process: processes.NodeProcess) -> None:
        for stream in ("stdout", "stderr"):
            rest = self._pending.pop((index, stream), None)
            if rest:
                self._node_line(index, self._to_start[index].output, stream, rest)
        name, code = self.names[index], process.returncode
        if process.pid is None:
            return  # it never started; that was reported already
        if code == 0:
            self.info(name, f"process has finished cleanly [pid {process.pid}]")
        else:
            command = " ".join(part for part in process.command if part.strip())
            self.error(name, f"process has died [pid {process.pid}, exit code {code}, cmd '{command}'].")

    def _finish(self) -> None:
        with self._lock:
            self._log_file.close()
        if self._context is not None:
            self._context.remove_files()
        self._done.set()

    def running(self) -> bool:
        """True while any of its processes runs."""
        return any(process.running() for process in self.processes)

    def wait(self, timeout: float | None = None) -> bool:
        """Wait until every process has ended (and been reported); False on timeout."""
        if self._monitor is None:
            return True
        return self._done.wait(timeout)

    def wait_for_nodes(self, timeout: float = 10.0) -> None:
        """Wait until every node the launch file names is in the ROS graph.

        Raises:
            TimeoutError, RuntimeError: as NodeProcess.wait_for_node (with the node's log tail).
        """
        deadline = time.monotonic() + timeout
        # strict=False: before start() (or while it runs) there are fewer processes than nodes to start.
        for node, process in zip(self._to_start, self.processes, strict=False):
            if node.node_name is not None and process.pid is not None:
                process.wait_for_node(node.node_name, timeout=max(0.1, deadline - time.monotonic()),
                                      namespace=node.namespace)

    def stop_timeouts(self) -> tuple[str, str]:
        """(sigterm_timeout, sigkill_timeout) of this launch, as text: its launch configurations
        (arguments such as ``sigterm_timeout:=2``), else STOP_TIMEOUTS.

        Raises:
            LaunchFileError: one is not a number of seconds.
        """
        configured = self._context.configurations if self._context is not None else {}
        texts = []
        for name, default in STOP_TIMEOUTS.items():
            text = configured.get(name, default)
            try:
                if not float(text) >= 0:
                    raise ValueError(text)
            except ValueError:
                raise LaunchFileError(f"{name} is {text!r}: give it in seconds, e.g. {name}:={default}",
                                      self.path) from None
            texts.append(text)
        return texts[0], texts[1]

    def stop(self, *, announce_sigint: bool = True) -> None:
        """Stop every process that still runs, as ros2 launch does, each step in its log lines:
        SIGINT; SIGTERM to those still running after sigterm_timeout seconds; SIGKILL to those
        still running sigkill_timeout seconds later. Then wait for every process's report.
        Calling it again does nothing.

        Args:
            announce_sigint: log "sending signal 'SIGINT'"; ros2 launch does not after Ctrl-C in
                its terminal, where the terminal itself sent SIGINT to every process.
        """
        with self._lock:
            stopping, self._stopping = self._stopping, True
        if not stopping and self._monitor is not None:
            self._escalate(announce_sigint)
        processes.stop_together(self.processes, 0)  # a backstop: they have all ended by now
        if self._monitor is None:
            self._finish()
        else:
            self._done.wait(_REPORT_BACKSTOP)
        with _LAUNCHES_LOCK:
            if _LAUNCHES.get(self.path) is self:
                del _LAUNCHES[self.path]

    def _escalate(self, announce_sigint: bool) -> None:
        term_text, kill_text = self.stop_timeouts()
        kill_text = str(float(term_text) + float(kill_text))  # launch prints the sum, as a float
        steps = [("SIGINT", None, None), ("SIGTERM", "SIGINT", term_text), ("SIGKILL", "SIGTERM", kill_text)]
        started = time.monotonic()
        for sent, before, after_text in steps:
            if after_text is not None and self._done.wait(max(0.0, started + float(after_text) - time.monotonic())):
                return
            # strict=False: a stop() from another thread may come while start() appends a name and its process.
            for name, process in zip(self.names, self.processes, strict=False):
                if not process.running():
                    continue
                if before is not None:
                    self.error(name, f"process[{name}] failed to terminate '{after_text}' seconds after receiving "
                                     f"'{before}', escalating to '{sent}'")
                if before is not None or announce_sigint:
                    self.info(name, f"sending signal '{sent}' to process[{name}]")
                process.send_signal(getattr(signal, sent))

    def __enter__(self) -> Launch:
        return self

    def __exit__(self, *exc) -> None:
        self.stop()


# --- the notebook's entry point ---------------------------------------------------------------

_LAUNCHES: dict[Path, Launch] = {}
_LAUNCHES_LOCK = threading.Lock()


def start(file_or_package, launch_file: str | None = None, /, **arguments) -> Launch:
    """Start a launch file from a notebook, like ``ros2 launch`` in a terminal.

    ``start("talk.launch.xml", rate=5)`` runs a file; ``start("demo", "talk.launch.xml")``
    finds the file in package demo's share folder. Running the cell again stops the previous
    run of the same file first; the kernel stopping stops everything.

    Args:
        file_or_package: a launch file's path, or a package name (with launch_file).
        launch_file: the file's name inside the package's share folder.
        **arguments: the launch arguments (``rate=5`` is ``rate:=5``).

    Returns:
        The running Launch: ``.processes``, ``.log``, ``.wait_for_nodes()``, ``.stop()``.

    Raises:
        LaunchFileError: the file cannot run as written (with its line).
        LookupError, FileNotFoundError: the package or file is not there.
    """
    path = Path(os.path.abspath(file_or_package if launch_file is None
                                else find_in_package(file_or_package, launch_file)))
    with _LAUNCHES_LOCK:
        previous = _LAUNCHES.pop(path, None)
    if previous is not None:
        previous.stop()
    launch = Launch(path, arguments)
    try:
        launch.prepare()
    except BaseException:
        launch.stop()
        raise
    with _LAUNCHES_LOCK:
        _LAUNCHES[path] = launch
    return launch.start()


def stop_all() -> None:
    """Stop every launch started with start() (run when the interpreter exits)."""
    with _LAUNCHES_LOCK:
        launches = list(_LAUNCHES.values())
    for launch in launches:
        launch.stop()


atexit.register(stop_all)


def find_in_package(package: str, file_name: str) -> Path:
    """The one file of this name below a package's share folder (how ``ros2 launch PKG FILE``
    finds it).

    Raises:
        LookupError: no such package (the message says how to make it visible).
        FileNotFoundError: no such file, or more than one.
    """
    from course_lib.ros import ament

    share = ament.share(package)
    found = sorted(Path(root) / name for root, _, names in os.walk(share) for name in names if name == file_name)
    if not found:
        raise FileNotFoundError(f"file '{file_name}' was not found in the share directory of package "
                                f"'{package}' which is at '{share}' (install it there with data_files in "
                                "setup.py, or install(DIRECTORY launch ...) in CMakeLists.txt, and build again)")
    if len(found) > 1:
        raise FileNotFoundError(f"file '{file_name}' was found more than once in the share directory of package "
                                f"'{package}': [{', '.join(repr(str(p)) for p in found)}]")
    return found[0]
