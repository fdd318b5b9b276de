"""Builds a submission's ROS 2 workspace with colcon, for the checks that run its executables.

A submission holds a colcon workspace beside its notebook (``ros2_ws/src/<package>/...``, written
by the notebook's ``%%writefile`` cells). After the notebook ran, the grader builds it
(:func:`build_workspace`), the way a student's ``colcon build`` would, but:

- inside the submission's sandbox and as the student's uid (a ``setup.py`` or ``CMakeLists.txt``
  is the student's code), with a wall time and memory bound (the caller's ``run``);
- interface packages (``rosidl_generate_interfaces``: ``.msg`` files) are built once per content
  and kept in a cache folder of the course (:class:`autograder.builds.caches.InterfaceCache`, keyed
  by the hash of the package's files and of this environment), so a class that hands in identical
  ``.msg`` files costs one CMake build; the workspace's other packages are built on top of the
  cached install (an underlay, as ``source other_ws/install/setup.bash`` before ``colcon build
  --packages-ignore <interface packages>``);
- the other packages are built as the assignment's build cell builds them (``colcon build
  --symlink-install``), and a successful build is kept too
  (:class:`autograder.builds.caches.WorkspaceBuilds`, keyed by its ``workspace_key``): with
  ``--symlink-install`` an ament_python build holds links to the package's modules, not copies,
  so it depends on every file of ``src/`` except the modules' contents (their names count). A
  class whose package.xml, setup.py and setup.cfg are the release's gets one build; every later
  identical workspace gets a copy of it, its paths moved to its own folder. (A setup.py that reads
  its package's modules while building, which ROS packages do not do, would get the build of the
  first such submission.)

The outcome is a :class:`BuildReport` (written as JSON for the checks, see
course_lib.checks.packages): when the build failed, its ``reason`` quotes the first error lines of
colcon, CMake or setup.py, and the checks that need the build give 0 with that reason while the
checks of plain functions still grade.
"""

from __future__ import annotations

import dataclasses
import json
import os
import shutil
import time
import xml.etree.ElementTree as ElementTree
from pathlib import Path

from autograder.builds.caches import (
    InterfaceCache,
    WorkspaceBuilds,
    builds_of,
    cache_of,
    content_key,
    local_cache,
    workspace_key,
)
from course_lib import contract
from course_lib.checks.assignments import ASSIGNMENTS
from course_lib.contract import WORKSPACE
from course_lib.ros import colcon, package_files, workspace

#: Seconds one colcon build may take (an interface package takes 10-40 s on a busy machine).
BUILD_SECONDS = 240.0

@dataclasses.dataclass
class BuildReport:
    """What building a submission's workspace gave.

    Attributes:
        ok: every package built.
        reason: for the student, when not ok: what failed, with the first error lines.
        workspace: the built workspace (its install/setup.bash chains the underlays).
        packages: the packages of the workspace's src/.
        cached: interface packages taken from the cache (not built again).
        built_interfaces: interface packages built now (and put in the cache).
        reused: the other packages were not built again: an identical workspace's build was
            copied (WorkspaceBuilds).
        seconds: wall time of the whole build.
        reference_underlays: install prefixes of the assignment's reference interface packages,
            built by the grader (the checks' own nodes use these, never code the student built).
        log: for the instructor: the end of the failed build's output.
    """

    ok: bool
    reason: str = ""
    workspace: str = ""
    packages: list[str] = dataclasses.field(default_factory=list)
    cached: list[str] = dataclasses.field(default_factory=list)
    built_interfaces: list[str] = dataclasses.field(default_factory=list)
    reused: bool = False
    seconds: float = 0.0
    reference_underlays: list[str] = dataclasses.field(default_factory=list)
    log: str = ""

    def write(self, path: Path) -> Path:
        path.write_text(json.dumps(dataclasses.asdict(self), indent=1))
        return path

    @classmethod
    def read(cls, path: Path) -> BuildReport:
        return cls(**json.loads(Path(path).read_text()))


# ---- the packages of a workspace -------------------------------------------------------------

def source_packages(ws: Path) -> dict[str, Path]:
    """{package name: folder} of every package.xml under ws/src (as colcon finds them)."""
    found = {}
    for xml in sorted((Path(ws) / "src").rglob("package.xml")):
        if any(part in ("build", "install", "log") or part.startswith(".") for part in xml.relative_to(ws).parts[:-1]):
            continue
        try:
            name = ElementTree.parse(xml).getroot().findtext("name", "").strip()
        except ElementTree.ParseError:
            name = xml.parent.name  # colcon reports the broken file when it builds
        found.setdefault(name or xml.parent.name, xml.parent)
    return found


def is_interface_package(folder: Path) -> bool:
    """An ament_cmake package that generates interfaces (rosidl_generate_interfaces)."""
    cmake = folder / "CMakeLists.txt"
    try:
        return "rosidl_generate_interfaces" in cmake.read_text(errors="replace")
    except OSError:
        return False


def _depends(folder: Path) -> set[str]:
    try:
        return package_files.dependencies(folder / "package.xml")
    except (ElementTree.ParseError, OSError):
        return set()


# ---- building ----------------------------------------------------------------------------------

#: The first error of a build log (shared with the notebook's colcon build).
first_error_lines = colcon.first_error_lines


def _package_log(ws: Path, output: str) -> str:
    """The log of the package colcon reported as failed (CMake's and the compiler's messages are
    there, not in colcon's summary), else colcon's output."""
    failed = colcon.failed_packages(output)
    if failed:
        log = colcon.package_log_path(ws, failed[0])
        if log.is_file():
            return f"Failed   <<< {failed[0]}\n" + log.read_text(errors="replace")
    return output


def _colcon(ws: Path, args: list[str], env: dict, run) -> tuple[bool, str]:
    """Run ``colcon build ARGS`` in ws through `run`; (succeeded, the failing package's log)."""
    command = [str(colcon.colcon_executable()), "build", *args]
    returncode, output = run(command, ws, env, BUILD_SECONDS)
    if returncode == 0:
        return True, output
    if returncode is None:
        given = getattr(run, "seconds_given", BUILD_SECONDS)
        return False, (f"colcon build did not finish within the {given:g} s it was given (a setup.py that "
                       f"loops or waits?).\n{output[-2000:]}")
    log = _package_log(ws, output)
    return False, log if log.strip() else f"colcon build ended with exit code {returncode} and printed nothing"


def _underlay_env(base: dict, underlays: list[Path]) -> dict:
    """The environment after sourcing each underlay's setup.bash, in order."""
    env = base
    for install in underlays:
        env = workspace.workspace_environment(install.parent, base=env)
    return env


def _readable(path: Path) -> None:
    """Let every uid read (and enter) a tree the grader wrote: the student's build reads it."""
    for directory, _dirs, files in os.walk(path):
        os.chmod(directory, 0o755)
        for name in files:
            file = os.path.join(directory, name)
            if not os.path.islink(file):
                os.chmod(file, os.stat(file).st_mode | 0o444)


def build_workspace(ws: Path, cache: InterfaceCache, scratch: Path, run, give=None,
                    builds: WorkspaceBuilds | None = None, store: bool = True) -> BuildReport:
    """Build the workspace `ws` (interface packages from `cache`, the others' build from `builds`
    when an identical workspace was built before); see the module docstring.

    Args:
        ws: the submission's workspace (``<notebook folder>/ros2_ws``), writable by the student's uid.
        cache: where built interface packages are kept.
        scratch: a folder of the grader's for this submission (interface builds, underlays).
        run: ``run(command, cwd, env, wall_seconds) -> (returncode or None, output)``: runs a
            command sandboxed as the student's uid (autograder.term.grade); a plain subprocess in tests.
        give: ``give(path)``, hands a folder the grader created to the student's uid (None: nothing).
        builds: where successful builds are kept (None: always run colcon).
        store: keep this build in `builds`, and new interface packages in `cache` (only when no
            other code of the student's ran beside the build).

    Returns:
        The BuildReport (never raises for the student's faults).
    """
    started = time.monotonic()
    ws = Path(ws)
    report = BuildReport(ok=False, workspace=str(ws))
    if not (ws / "src").is_dir():
        report.reason = (f"there is no {WORKSPACE}/src folder beside the notebook: run the cells that write your "
                         f"package files (%%writefile {WORKSPACE}/src/...)")
        return report
    packages = source_packages(ws)
    report.packages = sorted(packages)
    interfaces = {name: folder for name, folder in packages.items() if is_interface_package(folder)}
    base = colcon.build_environment()
    underlays: list[Path] = []
    keys: dict[str, str] = {}
    for name in _in_dependency_order(interfaces):
        folder = interfaces[name]
        key = content_key(folder, [keys[d] for d in sorted(_depends(folder)) if d in keys])
        keys[name] = key
        install, failure = cache.lookup(key)
        if install is None and failure is None:
            install, failure = _build_interface(name, folder, key, cache, scratch, _underlay_env(base, underlays),
                                                run, give, store)
            if install is not None:
                report.built_interfaces.append(name)
        else:
            report.cached.append(name)
        if failure is not None:
            report.reason = f"colcon build failed in package {name!r}:\n{failure}"
            report.seconds = round(time.monotonic() - started, 1)
            return report
        # The course's folder is hidden in the sandbox: the checks use a copy of their own.
        underlay = scratch / "underlays" / key / "install"
        if not underlay.exists():
            shutil.copytree(install, underlay, symlinks=True)
            _readable(underlay.parent)
        underlays.append(underlay)
    skip = ["--packages-ignore", *interfaces] if interfaces else []
    key = None
    if builds is not None and os.environ.get(contract.REUSE_BUILDS_ENV, "1") != "0" \
            and not (ws / "build").exists() and not (ws / "install").exists():
        key = workspace_key(ws / "src", list(keys.values()))
        if builds.restore(key, ws, scratch):
            if give is not None:
                give(ws / "build")
                give(ws / "install")
            report.ok = report.reused = True
            report.seconds = round(time.monotonic() - started, 1)
            return report
    ok, output = _colcon(ws, ["--symlink-install", *skip], _underlay_env(base, underlays), run)
    if ok:
        report.ok = True
        if key is not None and store:
            builds.store(key, ws, scratch)
    else:
        report.reason = _reason(output)
        report.log = output[-4000:]
    report.seconds = round(time.monotonic() - started, 1)
    return report


def _reason(log: str) -> str:
    failed = colcon.failed_packages(log)
    where = f" in package {failed[0]!r}" if failed else ""
    return f"colcon build failed{where}:\n{first_error_lines(log)}"


def _build_interface(name: str, folder: Path, key: str, cache: InterfaceCache, scratch: Path, env: dict, run, give,
                     store: bool = True):
    """Build one interface package alone in a scratch workspace and store the outcome in the cache
    (unless not `store`: then it serves this workspace only)."""
    build_ws = scratch / "interfaces" / key
    if build_ws.exists():
        shutil.rmtree(build_ws)
    shutil.copytree(folder, build_ws / "src" / name, symlinks=True)  # root follows no student link
    if give is not None:
        give(build_ws)
    ok, output = _colcon(build_ws, [], env, run)
    if ok and (build_ws / "install" / "setup.bash").is_file():
        if not store:
            return build_ws / "install", None
        cache.store(key, build_ws / "install")
        install, _ = cache.lookup(key)
        return install or build_ws / "install", None
    # A failure is not kept: it may be the machine's (a timeout, a full disk, the grader's own
    # fault) rather than the package's, and a cached failure would fail every later submission.
    return None, first_error_lines(output)


def _in_dependency_order(interfaces: dict[str, Path]) -> list[str]:
    ordered, pending = [], dict(interfaces)
    while pending:
        ready = [n for n in sorted(pending) if not (_depends(pending[n]) & set(pending) - {n})]
        for name in ready or sorted(pending):  # a cycle: colcon will say so
            ordered.append(name)
            pending.pop(name)
    return ordered


# ---- in the grader -----------------------------------------------------------------------------

#: The checks find the build report here (course_lib.checks.packages reads it).

#: The sandbox variables of the grader's environment that a build needs too (autograder.term.grade).
_SANDBOX_VARIABLES = (contract.EXPOSE_ENV, contract.BLOCKED_ENV, contract.STAGE_ENV)


def build_for_checks(assignment: str, course: Path, work: Path, workdir: Path, uid: int | None, domain_id: int,
                     grader_env: dict, hide: list[Path], run_sandboxed,
                     seconds: float = BUILD_SECONDS, prefix: str = "", store: bool = True) -> tuple[dict, float]:
    """Build the submission's workspace (``workdir/ros2_ws``) in the sandbox as the student's uid
    (autograder.sandbox.run_as),
    write the report into the grader's `work` folder, and return the variables that tell the
    checks where it is ({contract.BUILD_REPORT_ENV: path}) and the seconds spent building interface packages the
    cache did not have.

    Args:
        run_sandboxed: autograder.term.grade's ``_run_sandboxed(command, hide, name, domain_id, env, cwd, limits)``.
        seconds: wall time for the student's own packages (at most BUILD_SECONDS each colcon run);
            an interface package missing from the course's cache is the course's cost and gets
            BUILD_SECONDS of its own, outside this budget.
        prefix: of the names of the grader's folder and report in `work` (a second build of the
            same submission keeps apart: autograder.grading.early_checks).
        store: keep a successful build for identical workspaces (builds_of), and new interface
            packages in the course's cache: only when no other code runs as `uid` meanwhile (a
            kernel of the same uid could change the build).
    """
    from autograder.sandbox import run_as
    from course_lib.ros import processes

    scratch = work / f"{prefix}colcon"
    scratch.mkdir(mode=0o711, exist_ok=True)
    home = scratch / "home"
    home.mkdir(exist_ok=True)
    give = None
    if uid is not None:
        def give(path: Path) -> None:
            run_as.give_tree(path, uid)
        give(home)
    sandbox = {name: grader_env[name] for name in _SANDBOX_VARIABLES if grader_env.get(name)}

    deadline = time.monotonic() + seconds
    interface_seconds = 0.0

    def run(command, cwd, env, wall_seconds):
        nonlocal interface_seconds
        started = time.monotonic()
        interface = Path(cwd).is_relative_to(scratch / "interfaces")
        if not interface:
            wall_seconds = max(1.0, min(wall_seconds, deadline + interface_seconds - started))
        run.seconds_given = round(wall_seconds, 1)
        if uid is not None:
            command = run_as.command(uid, command, max_processes=contract.MAX_PROCESSES)
            # The sandbox hides the repository's autograder/: the wrapper runs from the grader's
            # staged copy (autograder.grading.staging), as the checks' do.
            staged = work / "grader" / "autograder" / "sandbox" / "run_as.py"
            command = [str(staged) if part == os.path.abspath(run_as.__file__) else part for part in command]
        limits = processes.Limits(wall_seconds=wall_seconds, memory_mb=contract.MEMORY_MB, file_size_mb=256,
                                  grace_seconds=3.0)
        # A name of its own: a process started under the name of a running one replaces it (stops
        # it), and another worker builds its own ros2_ws at the same time.
        proc = run_sandboxed(command, hide, f"colcon build {cwd}", domain_id,
                             {**env, **sandbox, "HOME": str(home), "PYTHONDONTWRITEBYTECODE": "1"}, cwd, limits)
        if interface:
            interface_seconds += time.monotonic() - started
        return (None if proc.exit_reason == "wall_seconds" else proc.returncode), proc.log

    cache = cache_of(course)
    report = build_workspace(Path(workdir) / WORKSPACE, cache, scratch, run, give, builds_of(course), store)
    try:
        report.reference_underlays = [str(p) for p in reference_interfaces(assignment, cache, scratch)]
    except RuntimeError as error:  # the course's fault: the checks that need messages say so
        report.log += f"\n{error}"
    path = report.write(work / f"{prefix}build-report.json")
    return {contract.BUILD_REPORT_ENV: str(path)}, interface_seconds


def needed(assignment: str, workdir: Path) -> bool:
    """Whether a submission's workspace is built: the assignment's checks run packages (its spec
    names some), or the notebook wrote a workspace."""
    has_packages = assignment in ASSIGNMENTS and bool(ASSIGNMENTS[assignment].packages)
    return has_packages or (Path(workdir) / WORKSPACE).exists()


def run_here(command, cwd, env, wall_seconds):
    """A build runner without a sandbox (the grader's own reference packages, and tests)."""
    import subprocess

    try:
        done = subprocess.run(command, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                              stdin=subprocess.DEVNULL, text=True, errors="replace", timeout=wall_seconds)
    except subprocess.TimeoutExpired as error:
        return None, (error.stdout or "") if isinstance(error.stdout, str) else ""
    return done.returncode, done.stdout


def reference_interfaces(assignment: str, cache: InterfaceCache, scratch: Path) -> list[Path]:
    """The assignment's reference interface packages (assignments/reference_ws/src), from the cache
    or built by the grader itself, copied into `scratch`: the checks' probes load these, so no
    package a student wrote runs in a check process.

    Raises:
        RuntimeError: a reference package does not build (the course's fault, not the student's).
    """
    from autograder.builds.reference import REFERENCE_SRC

    found = []
    env = colcon.build_environment()
    for name in ASSIGNMENTS[assignment].packages if assignment in ASSIGNMENTS else ():
        folder = REFERENCE_SRC / name
        if not is_interface_package(folder):
            continue
        # The same key as a student's identical package: an entry depends on the package's files
        # and this environment only (the build runs alone, in a fresh sandbox), so a class that
        # hands in the reference .msg files and the checks share one build.
        key = content_key(folder)
        install, failure = cache.lookup(key)
        if install is None:
            install, failure = _build_interface(name, folder, key, cache, scratch, env, run_here, None)
        if install is None:
            raise RuntimeError(f"the reference package {name} does not build:\n{failure}")
        copy = scratch / "reference" / key / "install"
        if not copy.exists():
            shutil.copytree(install, copy, symlinks=True)
        found.append(copy)
    return found


def build_here(assignment: str, workdir: Path, cache: InterfaceCache | None = None) -> BuildReport:
    """Build workdir/ros2_ws as the grader does, without a sandbox (reference solutions, tests,
    benchmarks), a build of an identical workspace reused (kept beside `cache`). The report goes
    to workdir/.colcon/build-report.json; checks run with contract.BUILD_REPORT_ENV set to it use this build
    (see course_lib.checks.packages)."""
    scratch = Path(workdir) / ".colcon"
    scratch.mkdir(exist_ok=True)
    cache = cache or local_cache()
    builds = WorkspaceBuilds(cache.root.with_name(cache.root.name + "-workspaces"))
    report = build_workspace(Path(workdir) / WORKSPACE, cache, scratch, run_here, builds=builds)
    report.reference_underlays = [str(p) for p in reference_interfaces(assignment, cache, scratch)]
    report.write(scratch / "build-report.json")
    return report


def report_path(workdir: Path) -> Path:
    """Where build_here wrote its report."""
    return Path(workdir) / ".colcon" / "build-report.json"


def read_report(variables: dict) -> BuildReport | None:
    """The report of the build whose variables (build_for_checks) name it; None when unreadable."""
    try:
        return BuildReport.read(Path(variables[contract.BUILD_REPORT_ENV]))
    except (KeyError, OSError, ValueError, TypeError):
        return None


def instructor_note(report: BuildReport | None) -> str:
    """For the grading report: what failed in the build, with the end of its output ("" when it built)."""
    if report is None or report.ok:
        return ""
    return f"\nThe workspace did not build: {report.reason}\n{report.log[-1500:]}"
