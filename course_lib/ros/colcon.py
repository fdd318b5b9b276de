"""Build a workspace with the real ``colcon build``, in the course's environment.

Custom messages need the CMake files of the pip wheels repaired once per environment
(``python -m course_lib repair-wheels``, run by ``make setup``); see ``course_lib.ros.wheelfix``
for that and for the recipe to run colcon by hand. In a terminal::

    python -m course_lib build ws              # colcon build with the environment set up
"""

from __future__ import annotations

import dataclasses
import re
import subprocess
import sys
import threading
import time
from pathlib import Path

from course_lib import progress
from course_lib.ros import rosenv, wheelfix
from course_lib.supervision import process_tree


class BuildError(RuntimeError):
    """colcon build failed; ``result`` holds the whole output, the message its useful tail."""

    def __init__(self, message: str, result: BuildResult):
        super().__init__(message)
        self.result = result


@dataclasses.dataclass
class BuildResult:
    """The outcome of one ``colcon build``.

    Attributes:
        ws_dir: the workspace that was built.
        command: the colcon command line.
        returncode: colcon's exit code (None when it was stopped after the timeout).
        output: everything colcon printed (stdout and stderr).
        seconds: wall-clock time of the build.
        finished: packages colcon reported as finished.
        failed: packages colcon reported as failed.
    """

    ws_dir: Path
    command: list[str]
    returncode: int | None
    output: str
    seconds: float
    finished: list[str]
    failed: list[str]

    @property
    def ok(self) -> bool:
        return self.returncode == 0

    def log_path(self, package: str) -> Path:
        """colcon's full log of one package in this build."""
        return package_log_path(self.ws_dir, package)


def package_log_path(ws_dir, package: str) -> Path:
    """colcon's full log of one package in the workspace's latest build."""
    return Path(ws_dir) / "log" / "latest_build" / package / "stdout_stderr.log"


#: colcon's line for a package that starts, finishes, fails or is aborted.
PACKAGE_LINE = re.compile(r"^(Starting >>>|Finished <<<|Failed\s+<<<|Aborted\s+<<<) ")


def failed_packages(output: str) -> list[str]:
    """The packages colcon's output reports as failed ("Failed   <<< name"), in its order."""
    return re.findall(r"^Failed\s+<<< (\S+)", output, re.MULTILINE)


# --- building ----------------------------------------------------------------------------------

def colcon_executable() -> Path:
    """The colcon of this environment.

    Raises:
        FileNotFoundError: colcon is not installed here.
    """
    found = rosenv.environment_tool("colcon")
    if found is not None:
        return found
    raise FileNotFoundError("colcon is not installed in this environment: run `make setup` "
                            "(it installs colcon-common-extensions from environment.txt)")


def build_environment(base: dict[str, str] | None = None) -> dict[str, str]:
    """The environment colcon runs in: the course's ROS environment plus what interface builds need."""
    return wheelfix.build_environment(rosenv.ros_environment(base=base))


def build(ws_dir, packages=None, *, extra_args=(), timeout: float = 600,
          echo=None) -> BuildResult:
    """Run the real ``colcon build`` in ws_dir.

    Args:
        ws_dir: the workspace (holding src/).
        packages: names for ``--packages-select``; None builds all.
        extra_args: more colcon build arguments, e.g. ["--symlink-install"].
        timeout: seconds before the build is stopped.
        echo: called with each output line as it arrives (e.g. print) to show progress live. In a
            notebook a progress line follows the packages in any case (course_lib.progress).

    Returns:
        A BuildResult (``finished`` lists the built packages).

    Raises:
        FileNotFoundError: no src/ folder, or colcon missing.
        BuildError: colcon failed or timed out; the message names the failing package and
            ends with the tail of its log.
    """
    ws_dir = Path(ws_dir).absolute()
    if not (ws_dir / "src").is_dir():
        raise FileNotFoundError(f"{ws_dir} has no src/ folder: create a package first, e.g. "
                                f"pkg_create.create_package({str(ws_dir)!r}, 'my_package')")
    command = [str(colcon_executable()), "build"]
    if packages:
        command += ["--packages-select", *([packages] if isinstance(packages, str) else packages)]
    command += [str(arg) for arg in extra_args]
    env = build_environment()
    # In a notebook a line under the cell follows colcon's package lines ("Starting >>> name").
    with progress.Progress(f"colcon build in {ws_dir.name}") as shown:
        result = _run(command, ws_dir, env, timeout, echo, shown)
        if result.returncode is None:
            raise BuildError(f"colcon build in {ws_dir} did not finish within {timeout:g} s and was stopped; "
                             f"pass a larger timeout or build fewer packages.\n{_tail(result.output)}", result)
        if result.returncode != 0:
            raise BuildError(_failure_message(result), result)
    return result


def _run(command: list[str], ws_dir: Path, env: dict[str, str], timeout: float, echo, shown) -> BuildResult:
    """Run colcon, pass each output line to echo and its package lines to shown.step; stop it after
    timeout seconds (returncode None)."""
    started = time.monotonic()
    process = subprocess.Popen(command, cwd=ws_dir, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               stdin=subprocess.DEVNULL, text=True, errors="replace", start_new_session=True)
    lines: list[str] = []

    def pump():
        for line in process.stdout:
            lines.append(line)
            if echo is not None:
                echo(line.rstrip("\n"))
            if PACKAGE_LINE.match(line):
                shown.step(line)

    reader = threading.Thread(target=pump, daemon=True)
    reader.start()
    timed_out = False
    try:
        process.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        timed_out = True
        process_tree.stop_group(process)
    except BaseException:  # KeyboardInterrupt in a notebook: never leave compilers behind
        process_tree.stop_group(process)
        raise
    reader.join(timeout=10)
    output = "".join(lines)
    return BuildResult(ws_dir, command, None if timed_out else process.returncode, output,
                       time.monotonic() - started,
                       re.findall(r"^Finished <<< (\S+)", output, re.MULTILINE), failed_packages(output))


def _tail(text: str, lines: int = 30) -> str:
    return "\n".join(text.rstrip("\n").splitlines()[-lines:])


#: Lines that start an error in colcon's, CMake's, the compiler's or setup.py's output.
_ERROR_LINE = re.compile(r"(CMake Error|error:|Error:|Traceback \(most recent call last\)|SyntaxError|"
                         r"ModuleNotFoundError|No module named|Failed\s+<<<|ERROR|not found:)")


def first_error_lines(output: str, lines: int = 8) -> str:
    """The first error of a build log and the lines after it (or the log's end when no line
    looks like an error), without colcon's progress lines."""
    text = [line for line in output.splitlines() if line.strip() and not line.startswith((
        "Starting >>>", "Finished <<<", "Failed   <<<", "[Processing:", "Summary:"))]
    for index, line in enumerate(text):
        if line.startswith("Traceback (most recent call last)"):
            # colcon's own frames first: the exception (a SyntaxError in setup.py, say) is at the
            # end of the traceback, with the student's file and line just above it.
            end = next((i for i in range(index + 1, len(text)) if not text[i].startswith((" ", "\t"))), len(text) - 1)
            return "\n".join(text[max(index + 1, end - 3):end + 1])
        if _ERROR_LINE.search(line):
            return "\n".join(text[index:index + lines])
    return "\n".join(text[-lines:])


def _failure_message(result: BuildResult) -> str:
    """What failed, where the whole story is (colcon's log), then the cause: the cause comes last,
    where a notebook cell's output and a terminal end."""
    if result.failed:
        package = result.failed[0]
        log = result.log_path(package)
        details = log.read_text(errors="replace") if log.is_file() else result.output
        failed = f"colcon build failed in package {package!r} (exit code {result.returncode}); its full log: {log}"
        setup_error = _setup_py_error(result.ws_dir, package, details)
        if setup_error is not None:
            if log.is_file():  # colcon ran setup.py outside its logging: its log has colcon's traceback only
                with log.open("a") as stream:
                    stream.write(f"--- {SETUP_PY_ERROR_TITLE}:\n{setup_error}\n---\n")
            return f"{failed}\nMend setup.py and build again. {SETUP_PY_ERROR_TITLE}:\n{setup_error}"
        return f"{failed}\n{_hint(details)}The first error in it:\n{first_error_lines(details)}"
    return (f"colcon build failed (exit code {result.returncode}) before building a package; colcon's log: "
            f"{result.ws_dir / 'log' / 'latest_build'}\nThe first error in its output:\n"
            f"{first_error_lines(result.output)}")


#: How a build error introduces what Python printed when colcon ran a package's setup.py.
SETUP_PY_ERROR_TITLE = "colcon runs setup.py to read the package (name, version, entry points), and Python stopped it"


def _setup_py_error(ws_dir: Path, package: str, log: str) -> str | None:
    """What Python prints for the package's setup.py when colcon failed to read it (colcon's log then
    holds only its own CalledProcessError; the error went to the console, with the file shown as
    "<string>"); None when the failure was another one. setup.py runs again as a script, in its
    folder, so that the error names the file and line."""
    if "get_setup_information" not in log:
        return None
    folder = package_dir(ws_dir, package)
    if folder is None or not (folder / "setup.py").is_file():
        return None
    try:
        done = subprocess.run([sys.executable, "setup.py", "--name"], cwd=folder, env=build_environment(),
                              capture_output=True, text=True, errors="replace", stdin=subprocess.DEVNULL, timeout=60)
    except subprocess.TimeoutExpired:
        return f"{folder / 'setup.py'} did not finish within 60 s when run as a script"
    return done.stderr.lstrip("\n").rstrip() or None if done.returncode else None


def package_dir(ws_dir, name: str) -> Path | None:
    """The folder below the workspace's src/ whose package.xml names the package `name`, as colcon
    finds it (folders with a COLCON_IGNORE file are left out); None when there is none."""
    import xml.etree.ElementTree as ElementTree

    for package_xml in sorted(Path(ws_dir, "src").rglob("package.xml")):
        if any((parent / "COLCON_IGNORE").exists() for parent in package_xml.parents):
            continue
        try:
            found = ElementTree.parse(package_xml).findtext("name")
        except ElementTree.ParseError:
            continue
        if found is not None and found.strip() == name:
            return package_xml.parent
    return None


def _hint(log: str) -> str:
    if "/opt/python/" in log and "non-existent path" in log:
        return "The wheels' CMake files are not repaired yet: run `python -m course_lib repair-wheels`.\n"
    missing = re.search(r'package configuration file provided by\s+"(\w+)"', log)
    if missing:
        name = missing.group(1)
        requirement = wheelfix.BUILD_PACKAGES.get(name, f"ros-jazzy-{name.replace('_', '-')}")
        return (f"CMake cannot find the package {name!r}: add it to package.xml if it is yours, or "
                f"install it into the environment (`pip install {requirement}`).\n")
    return ""


# --- command line ------------------------------------------------------------------------------

#: colcon's last line when it could not read a setup.py: the ten-line ``python -c`` it ran, once more.
_COMMAND_FAILED = re.compile(r"^(subprocess\.CalledProcessError: )?Command '\[.*\]' returned non-zero exit status")


class QuietEcho:
    """Passes colcon's output on line by line, without what only retells a failure in colcon's words:
    a traceback through colcon's own code or through the setup.py it runs as ``python -c`` (shown as
    "<string>"), colcon's "Command '[...]' returned non-zero exit status" line and the stderr
    section left empty without them. The build error printed after it gives the cause, last."""

    def __init__(self, echo=print):
        self.echo = echo
        self.traceback: list[str] = []
        self.section: str | None = None  # a "--- stderr: name" line not shown yet

    def __call__(self, line: str) -> None:
        if self.traceback:
            self.traceback.append(line)
            if not line.startswith((" ", "\t")):  # the exception's line ends the traceback
                told, self.traceback = self.traceback, []
                if not any('File "<string>"' in told_line or "/colcon_" in told_line for told_line in told):
                    for told_line in told:
                        self._show(told_line)
        elif line.startswith("Traceback (most recent call last)"):
            self.traceback = [line]
        elif line.startswith("--- stderr: "):
            self.section = line
        elif line == "---" and self.section is not None:
            self.section = None  # nothing was left in it
        elif not _COMMAND_FAILED.match(line):
            self._show(line)

    def _show(self, line: str) -> None:
        if self.section is not None:
            self.echo(self.section)
            self.section = None
        self.echo(line)


def main_build(argv: list[str] | None = None) -> int:
    """``python -m course_lib build WS_DIR [colcon build args...]``: build and say how to use it."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv or argv[0] in ("-h", "--help"):
        print("usage: python -m course_lib build WS_DIR [colcon build arguments...]\n\n"
              "Runs `colcon build` in WS_DIR with the course's environment (custom messages work on the\n"
              "pip install); e.g. python -m course_lib build ws --packages-select my_package")
        return 0 if argv else 2
    ws_dir, extra = Path(argv[0]), argv[1:]
    try:
        result = build(ws_dir, extra_args=extra, timeout=3600, echo=QuietEcho(print))
    except (BuildError, FileNotFoundError) as error:
        sys.stdout.flush()  # colcon's lines first, the cause last
        print(f"\nbuild: {error}", file=sys.stderr)
        return 1
    activate = Path(sys.prefix) / "bin" / "activate"
    print(f"\nBuilt {len(result.finished)} package(s) in {result.seconds:.1f} s. To use them in a terminal:\n"
          + (f"  source {activate}\n" if activate.is_file() else "")
          + f"  source {result.ws_dir / 'install' / 'setup.bash'}\n"
          f"In a notebook: workspace.use_workspace({str(result.ws_dir)!r})")
    return 0
