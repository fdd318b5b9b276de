"""What a graded check is, and how it runs: the same code for the self-check and the autograder.

A check is a function in ``course_lib/checks/<assignment>.py`` decorated with :func:`check`,
which gives it its points and its time limit; its docstring's first line says what it checks::

    @check(points=4, timeout=40)
    def values(ctx):
        \"\"\"average_brightness returns the floor of the mean byte for colour and grey images.\"\"\"
        for outcome, expected in ...:
            ctx.item(outcome.value == expected, "...")

Where things run:

- the notebook kernel only starts the check and prints its verdict (:func:`run_check`): the check
  runs in a process of its own (``python -m course_lib.checks.harness run ...``) with a wall-time bound,
  so nothing a check does can hang or crash the kernel, and nothing the kernel's state holds
  (a node the student left spinning, a patched module) changes the check;
- the student's code runs in a third process, started by the check (:meth:`Context.call` for
  plain functions, :meth:`Context.start_node` for nodes), with its own resource limits and, for
  ROS, a ROS_DOMAIN_ID reserved for the check. A student process that loops, crashes or exits
  costs the points of that check and nothing else.

At grading the course's grader (autograder.grading) runs the hidden checks itself, outside the
student's kernel (``python -m course_lib.checks.harness outside``): :func:`grade` in the notebook only
says so. As root the check stays root and the student's processes run as the grader's worker
uid (AUTOGRADER_STUDENT_UID), so the student's code can neither fake a check's result nor read
its seed (passed in the environment, not on the command line).

Seeds: a self-check uses fixed seeds (the same frames every time, so a student can debug);
grading draws a fresh seed per check (or takes AUTOGRADER_SEED to reproduce a grade) and
the verdict prints it, so that the feedback records it.

Expected answers (:meth:`Context.expected`, course_lib.checks.answers): graded, from the grader's
answer key (``autograder.answers``, instructor side only); in a self-check, the answers that key
gave for the self-check's inputs, recorded as data. Nothing a student can import or read holds
a reference solution, and nothing the student's process can read holds a graded answer.

Points: the check's items each pass or fail; the check earns ``points × passed weight / total
weight``. The value of the test cell is that number, which nbgrader 0.9 takes as partial credit
(an ``execute_result`` that converts to float; an error or anything on stderr gives 0).
"""

from __future__ import annotations

import argparse
import base64
import dataclasses
import importlib
import json
import os
import secrets
import shutil
import sys
import tempfile
import time
import traceback
from pathlib import Path

from course_lib.checks import answers

#: Seconds a student's module gets to import (rclpy alone needs one or two on a busy machine).
IMPORT_TIMEOUT = 25.0

#: Memory (address space, MB) of a student's process. rclpy with Fast DDS maps a few hundred MB.
STUDENT_MEMORY_MB = 2048

#: Largest file a student's process may write, MB.
STUDENT_FILE_MB = 128

#: Written into the work directory when the student's module did not import in time, so that
#: later checks fail at once with the same reason instead of waiting again.
IMPORT_HANG_MARK = ".autograder-import-hang"

#: The fixed seed of self-checks (what the student sees when running the notebook).
SELFCHECK_SEED = 2024


@dataclasses.dataclass(frozen=True)
class Check:
    """One graded check of an assignment.

    Attributes:
        assignment: the assignment's name (the checks module's name).
        name: the check's name, unique in the assignment (what selfcheck()/grade() take).
        points: the most it earns.
        timeout: seconds the check may take, student processes included.
        description: the docstring's first line: what the check checks.
        function: the check itself, called with a Context.
    """

    assignment: str
    name: str
    points: float
    timeout: float
    description: str
    function: object


_REGISTRY: dict[str, dict[str, Check]] = {}


def check(points: float, timeout: float):
    """Register a check function of a ``course_lib.checks`` module (see the module docstring)."""
    def register(function):
        assignment = function.__module__.rsplit(".", 1)[-1]
        doc = (function.__doc__ or "").strip().splitlines()
        if not doc:
            raise ValueError(f"Check {function.__name__} has no docstring: its first line says what it checks")
        spec = Check(assignment, function.__name__, float(points), float(timeout), doc[0], function)
        _REGISTRY.setdefault(assignment, {})[spec.name] = spec
        return function
    return register


def checks_of(assignment: str) -> dict[str, Check]:
    """The checks of an assignment, in the order they are defined (imports the checks module)."""
    importlib.import_module(f"course_lib.checks.{assignment}")
    return dict(_REGISTRY.get(assignment, {}))


def get_check(assignment: str, name: str) -> Check:
    checks = checks_of(assignment)
    if name not in checks:
        raise KeyError(f"{assignment} has no check {name!r}; its checks are {sorted(checks)}")
    return checks[name]


# ---------------------------------------------------------------------------------------------
# Results
# ---------------------------------------------------------------------------------------------

@dataclasses.dataclass
class Result:
    """What a check found: its items, the points earned, and pictures to show."""

    assignment: str
    name: str
    points: float
    max_points: float
    seed: int
    items: list[dict] = dataclasses.field(default_factory=list)
    notes: list[str] = dataclasses.field(default_factory=list)
    images: list[dict] = dataclasses.field(default_factory=list)
    error: str | None = None
    seconds: float = 0.0

    def verdict_lines(self) -> list[str]:
        """The points, then what failed (each cause followed by its consequences), then what passed."""
        lines = [f"{self.name}: {_fmt(self.points)} of {_fmt(self.max_points)} points"]
        for item in self.items:
            if not item["ok"] and not item.get("consequence"):
                lines.append("  ✘ " + item["message"])
        for item in self.items:
            if item.get("consequence"):
                lines.append("    ↳ ✘ " + item["message"])
        for item in self.items:
            if item["ok"]:
                lines.append("  ✔ " + item["message"])
        lines.extend("  · " + note for note in self.notes)
        if self.error:
            lines.append("  ! " + self.error)
        return lines


def _fmt(value: float) -> str:
    return f"{value:g}"


# ---------------------------------------------------------------------------------------------
# In the kernel: start a check and show its verdict
# ---------------------------------------------------------------------------------------------

def selfcheck(assignment: str, name: str) -> None:
    """Run a check with the fixed self-check seed and print what passed and failed; when points
    were lost, also write what to fix to stderr, where nbgrader's Validate looks for a cell's
    errors (it then lists those lines instead of a bare "Partial credit"). Returns nothing, so that
    the cell does not end with a bare number.

    Under grading (COURSE_LIB_GRADING=1) it does nothing: the hidden test that follows it in the
    same cell runs the check with a fresh seed.
    """
    from course_lib import rosenv

    if rosenv.under_grading():
        return
    result = run_check(assignment, name, SELFCHECK_SEED)
    if result.points < result.max_points:
        lines = [line.strip() for line in result.verdict_lines() if line.lstrip().startswith(("✘", "↳", "!"))]
        sys.stderr.write(f"Self-check {name}: {_fmt(result.points)} of {_fmt(result.max_points)} points. "
                         "What to fix:\n" + "\n".join(lines) + "\n")
        sys.stderr.flush()


#: Set by the course's grader (autograder.grading) for the notebook run: the hidden tests do not
#: run in the student's kernel, where the student's code could fake their result; the grader
#: runs them afterwards in processes of its own (see :func:`grade_outside`) and writes the
#: verdicts into the graded notebook.
OUTSIDE_ENV = "AUTOGRADER_CHECKS_OUTSIDE"


def grade(assignment: str, name: str) -> float:
    """Run a check with a fresh seed (AUTOGRADER_SEED to reproduce one), print the seed and the
    verdict, return the points earned (the test cell's value is the partial credit).

    Under the course's grader (AUTOGRADER_CHECKS_OUTSIDE=1) it only says so and returns 0: the
    grader runs the check itself and replaces this cell's output and score.
    """
    if os.environ.get(OUTSIDE_ENV) == "1":
        print(f"[graded] {get_check(assignment, name).description}\n"
              "  The autograder runs this check outside the notebook; its verdict replaces this text.")
        return 0.0
    return round(run_check(assignment, name, fresh_seed(), graded=True).points, 3)


def fresh_seed() -> int:
    """A seed drawn now, or AUTOGRADER_SEED when set (to reproduce a grade)."""
    seed = os.environ.get("AUTOGRADER_SEED")
    return int(seed) if seed else secrets.randbelow(2**31)


def run_check(assignment: str, name: str, seed: int, graded: bool = False, workdir=None) -> Result:
    """Run one check in a separate process, print its verdict, display its pictures, return its Result."""
    result = execute(assignment, name, seed, workdir=workdir, mode="graded" if graded else "selfcheck")
    print(verdict_text(result, graded))
    _display_images(result)
    return result


def verdict_text(result: Result, graded: bool) -> str:
    """What a check cell shows: the seed, the check's description, and what passed and failed."""
    header = (f"[{'graded' if graded else 'self-check'} · seed {result.seed}] "
              f"{get_check(result.assignment, result.name).description}")
    lines = [header, *result.verdict_lines()]
    if graded:
        lines.append(f"  (reproduce with AUTOGRADER_SEED={result.seed})")
    return "\n".join(lines)


def execute(assignment: str, name: str, seed: int, workdir=None, mode: str = "selfcheck") -> Result:
    """Run a check in its own process and return its Result (0 points when it failed to finish).

    `mode` says where its expected answers come from (course_lib.checks.answers): "selfcheck"
    (recorded answers; only the self-check seed's inputs are recorded), "graded" (the grader's
    answer key) or "record" (graded, and the answers written to $AUTOGRADER_RECORD_TO).
    """
    from course_lib import processes

    spec = get_check(assignment, name)
    workdir = Path(workdir or os.getcwd()).resolve()
    out = Path(tempfile.mkdtemp(prefix="autograder-check-"))
    started = time.monotonic()
    # The seed goes in the environment, which other uids cannot read (a command line they can).
    # The working directory is the check's own: a student's file next to the notebook (json.py,
    # numpy.py) must not shadow a module the checker imports.
    command = [sys.executable, "-m", "course_lib.checks.harness", "run", assignment, name,
               "--workdir", str(workdir), "--out", str(out)]
    limits = processes.Limits(wall_seconds=spec.timeout + 10, grace_seconds=2.0)
    proc = processes.NodeProcess(command, name=f"autograder-check-{name}", cwd=out, limits=limits,
                                 env={"PYTHONPATH": _pythonpath(), SEED_ENV: str(seed), answers.MODE_ENV: mode})
    try:
        proc.start()
        try:
            proc.wait(spec.timeout + 20)
        except TimeoutError:
            pass
        proc.stop(timeout=3)
        try:
            data = json.loads((out / "result.json").read_text())
            result = Result(**data)
        except (OSError, ValueError, TypeError):
            result = Result(assignment, name, 0.0, spec.points, seed,
                            error=f"The check did not finish ({proc.describe_exit()}); "
                                  f"its last output:\n{proc.log_tail(8)}")
        _embed_images(result, out)
    finally:
        proc.stop(timeout=3)
        shutil.rmtree(out, ignore_errors=True)
    result.points = max(0.0, min(result.points, spec.points))
    result.seconds = round(time.monotonic() - started, 2)
    return result


def _embed_images(result: Result, out: Path) -> None:
    """Replace the file names of the result's pictures (written to `out`) by their PNG bytes."""
    for image in result.images:
        path = out / image.pop("file", "")
        if path.is_file():
            image["png"] = base64.b64encode(path.read_bytes()).decode()


def run_outside(assignment: str, names: list[str], workdir, out: Path) -> None:
    """The grader's run of a graded notebook's checks: each with a fresh seed and the answer key,
    one after the other in this process (one interpreter start-up for all of them; the student's
    code they call runs in processes of its own, bounded in time), each result in out/<name>.json."""
    os.environ[answers.MODE_ENV] = "graded"
    for name in names:
        spec = get_check(assignment, name)
        scratch = Path(tempfile.mkdtemp(prefix=f"autograder-{name}-"))
        started = time.monotonic()
        try:
            result = run_in_this_process(assignment, name, fresh_seed(), Path(workdir).resolve(), scratch)
            _embed_images(result, scratch)
        finally:
            shutil.rmtree(scratch, ignore_errors=True)
        result.points = max(0.0, min(result.points, spec.points))
        result.seconds = round(time.monotonic() - started, 2)
        _write_json(out / f"{name}.json", dataclasses.asdict(result))


def _pythonpath() -> str:
    """The directory holding course_lib (in a course checkout also the autograder), first on the
    path of child processes."""
    root = str(Path(__file__).resolve().parents[2])
    rest = [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p and p != root]
    return os.pathsep.join([root] + rest)


def images_html(result: Result) -> str:
    """The check's pictures as one HTML block ("" when it has none)."""
    cells = "".join(
        f"<figure style='display:inline-block;margin:4px'><img src='data:image/png;base64,{image['png']}'/>"
        f"<figcaption style='font-size:small'>{_escape(image['label'])}</figcaption></figure>"
        for image in result.images if "png" in image)
    return f"<div class='autograder-images'>{cells}</div>" if cells else ""


def _display_images(result: Result) -> None:
    html = images_html(result)
    if not html:
        return
    try:
        from IPython import get_ipython
        from IPython.display import HTML, display
    except ImportError:
        return
    if get_ipython() is not None:
        display(HTML(html))


def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


# ---------------------------------------------------------------------------------------------
# In the check process
# ---------------------------------------------------------------------------------------------

class StudentError(Exception):
    """The student's code failed (raised, crashed, hung); str() says how, for the feedback."""


@dataclasses.dataclass
class Outcome:
    """What one call of a student's function gave: a value, or the error that prevented one.

    Attributes:
        value: the returned value (numpy arrays, Python scalars of the returned type, dicts).
        pytype: the name of the returned value's type ("int", "float", "ndarray", ...).
        error: None, or how the call failed ("NotImplementedError: ...", "the process was killed ...").
    """

    value: object = None
    pytype: str = "NoneType"
    error: str | None = None

    @property
    def ok(self) -> bool:
        return self.error is None


class Context:
    """What a check function gets: the seed, the student's work directory, and ways to run the
    student's code and to record what passed.

    Attributes:
        seed: this run's seed; rng: a numpy Generator seeded with it.
        workdir: the directory of the student's notebook and module files.
        domain_id: a ROS domain reserved for this check (student nodes and probes use it).
    """

    def __init__(self, spec: Check, seed: int, workdir: Path, out: Path):
        import numpy as np

        self.spec = spec
        self.seed = seed
        self.rng = np.random.default_rng(seed)
        self.workdir = workdir
        self.out = out
        self.items: list[dict] = []
        self.notes: list[str] = []
        self.images: list[dict] = []
        self._reservation = None
        self._started = time.monotonic()
        self._answers = answers.AnswerKey(spec.assignment)

    # -- recording -----------------------------------------------------------------------------

    def item(self, ok: bool, message: str, weight: float = 1.0) -> bool:
        """Record one checked claim; `message` says what was found (and the fix when it failed)."""
        self.items.append({"ok": bool(ok), "message": clip(message), "weight": float(weight)})
        return bool(ok)

    def consequence(self, message: str, weight: float = 1.0) -> bool:
        """Record a claim that fails because of a failure recorded before it (not a mistake of its
        own): it loses its weight, and the verdict lists it under the causes, marked ↳."""
        self.items.append({"ok": False, "message": clip(message), "weight": float(weight), "consequence": True})
        return False

    def precondition(self, ok: bool, message: str) -> bool:
        """Record a claim that later items depend on but that earns nothing by itself (a node that
        starts, then fails at its job, must not score): shown like an item, weight 0."""
        return self.item(ok, message, weight=0.0)

    def expected(self, question: str, *args):
        """The right answer of the contract's function `question` for these arguments (see
        course_lib.checks.answers: the grader's key when graded, recorded answers in a self-check)."""
        return self._answers.expected(question, *args)

    def note(self, text: str) -> None:
        """Record an informative line (no points)."""
        self.notes.append(clip(text))

    def image(self, label: str, image) -> None:
        """Attach a picture (BGR or grey uint8) to the verdict, shown in the notebook and the feedback."""
        import cv2
        import numpy as np

        image = np.asarray(image)
        if image.dtype != np.uint8 or image.ndim not in (2, 3) or image.size == 0:
            return
        if image.shape[1] > 320:
            scale = 320 / image.shape[1]
            image = cv2.resize(image, (320, max(1, round(image.shape[0] * scale))), interpolation=cv2.INTER_AREA)
        name = f"image{len(self.images)}.png"
        cv2.imwrite(str(self.out / name), image)
        self.images.append({"label": label, "file": name})

    def remaining(self) -> float:
        """Seconds left of this check's timeout (never below 1)."""
        return max(1.0, self.spec.timeout - (time.monotonic() - self._started))

    # -- the student's code --------------------------------------------------------------------

    @property
    def module(self) -> str:
        """The dotted name of the student's module of plain functions (course_lib.checks.packages)."""
        from course_lib.checks import packages

        return packages.FUNCTION_MODULES[self.spec.assignment][1]

    @property
    def module_root(self) -> Path:
        """The folder the student's module is imported from: its package's source, ros2_ws/src/<package>."""
        from course_lib.checks import packages

        return packages.package_dir(self, packages.FUNCTION_MODULES[self.spec.assignment][0])

    def require_module(self) -> None:
        """Raise StudentError with the fix when the student's module file does not exist."""
        path = self.module_root / (self.module.replace(".", "/") + ".py")
        if not path.is_file():
            shown = path.relative_to(self.workdir)
            raise StudentError(f"{shown} does not exist: run the cell that starts with %%writefile {shown} "
                               "(it writes your module)")
        if (self.workdir / IMPORT_HANG_MARK).exists():
            raise StudentError(f"importing {self.module} did not finish within {IMPORT_TIMEOUT:g} s in an "
                               "earlier check: remove code that runs forever at import (loops, spin()) "
                               "from the top level of the module; put it in main()")

    def call(self, function: str, calls: list[tuple], timeout: float | None = None) -> list[Outcome]:
        """Call the student's `function` once per entry of `calls` in one student process.

        Args:
            function: the name of a function of the student's module.
            calls: (args, kwargs) per call; args may hold numpy arrays, kwargs plain JSON values.
            timeout: seconds for the import and all calls together; default (and at most): what is
                left of the check's time, so the check always has time to report.

        Returns:
            One Outcome per call. Calls that did not run because the process died or ran out of
            time get an Outcome whose error says so.
        """
        job = Path(tempfile.mkdtemp(prefix="autograder-call-"))
        try:
            _write_calls(job, calls)
            timeout = min(timeout or self.remaining(), self.remaining())
            proc, call_seconds = self._run_student("call", function, job, timeout)
            return _read_outcomes(job, len(calls), proc, call_seconds)
        finally:
            shutil.rmtree(job, ignore_errors=True)

    def endpoints(self, class_name: str, timeout: float = 20.0, module: str | None = None,
                  env: dict | None = None) -> dict:
        """Construct the student's node class (not spun) in a student process and return the QoS of
        its publishers and subscriptions: {"publishers"|"subscriptions": [{"topic", "type",
        "depth", "history", "reliability", "durability"}]}. Raises StudentError when it fails."""
        job = Path(tempfile.mkdtemp(prefix="autograder-endpoints-"))
        try:
            timeout = min(timeout, self.remaining())
            proc, _seconds = self._run_student("endpoints", class_name, job, timeout, module=module, env=env)
            try:
                return json.loads((job / "endpoints.json").read_text())
            except (OSError, ValueError):
                raise StudentError(f"{class_name}() could not be constructed ({proc.describe_exit()}):\n"
                                   f"{_tail(proc.log, 6)}") from None
        finally:
            shutil.rmtree(job, ignore_errors=True)

    def _run_student(self, command: str, target: str, job: Path, timeout: float, module: str | None = None,
                     env: dict | None = None):
        """Run ``python -m course_lib.checks.student COMMAND MODULE TARGET JOB`` to its end, or until
        `timeout` seconds (import included, never past the check's own time) have passed.

        Returns:
            (the stopped process, the seconds its calls had after the import).

        Raises:
            StudentError: the module did not import.
        """
        from course_lib import processes

        if module is None:  # a module of a built package (env: its workspace) needs no source check
            self.require_module()
        module = module or self.module
        _give_to_student(job)
        timeout = min(timeout, self.remaining())
        deadline = time.monotonic() + timeout
        proc = processes.NodeProcess([sys.executable, "-m", "course_lib.checks.student", command, module, target, str(job)],
                                     name=f"student-{target}", cwd=self.module_root if env is None else self.workdir,
                                     domain_id=self.domain_id, limits=_student_limits(timeout + 2),
                                     env=env or _student_env())
        proc.start()
        import_wait = min(IMPORT_TIMEOUT, timeout)
        call_seconds = 0.0
        try:
            imported = _wait_for_file(job / "imported", import_wait, proc)
            if not imported and proc.running():
                if import_wait < IMPORT_TIMEOUT:
                    raise StudentError(f"importing {module} did not finish within the {import_wait:.0f} s "
                                       "this check had left (the machine may be busy; the import itself took long)")
                _mark(self.workdir / IMPORT_HANG_MARK)
                raise StudentError(f"importing {module} did not finish within {IMPORT_TIMEOUT:g} s: "
                                   "remove code that runs forever at import (loops, spin()) from the "
                                   "top level of the module; put it in main()")
            if imported:
                call_seconds = max(0.0, deadline - time.monotonic())
                try:
                    proc.wait(call_seconds)
                except TimeoutError:
                    pass
        finally:
            proc.stop(timeout=1)
        if not (job / "imported").exists():
            raise StudentError(f"{module} could not be imported ({proc.describe_exit()}):\n"
                               f"{_tail(proc.log, 6)}")
        return proc, call_seconds

    def start_node(self, *ros_args: str, entry: str = "main", tag: str = ""):
        """Start the student's node (``<module>:main``) in this check's ROS domain; stopped at the end.
        Nodes started at the same time need different `tag`s (a process of the same name is replaced).

        Returns:
            The running course_lib.processes.NodeProcess (see its log, running(), describe_exit()).
        """
        from course_lib import processes

        self.require_module()
        limits = _student_limits(self.remaining() + 5)
        return processes.python_node(f"{self.module}:{entry}", *ros_args, name=f"student-{self.module}-{entry}{tag}",
                                     cwd=self.workdir, domain_id=self.domain_id, limits=limits, env=_student_env())

    @property
    def domain_id(self) -> int:
        if self._reservation is None:
            from course_lib import rosenv

            if rosenv.under_grading() and os.environ.get("ROS_DOMAIN_ID"):
                # The grader reserved this domain for the whole submission, in a network
                # namespace (and /dev/shm) of its own: nothing else can be in it.
                self._reservation = _Fixed(int(os.environ["ROS_DOMAIN_ID"]))
            else:
                self._reservation = rosenv.reserve_domain_id()
        return self._reservation.domain_id

    def probe(self):
        """A ROS node of the checker in this check's domain (see RosProbe); close() it or use `with`."""
        return RosProbe(self.domain_id)

    def close(self) -> None:
        from course_lib import processes

        processes.stop_all(timeout=1.0)
        if self._reservation is not None:
            self._reservation.release()


class _Fixed:
    def __init__(self, domain_id: int):
        self.domain_id = domain_id

    def release(self) -> None:
        pass


def _student_env() -> dict:
    # Fast DDS's set-up for camera frames comes, as for every course process, from
    # course_lib.rosenv.ros_environment (its shared-memory segments need RLIMIT_FSIZE above 32 MB).
    return {"PYTHONPATH": _pythonpath(), "AUTOGRADER_SEED": None, SEED_ENV: None, STUDENT_UID_ENV: None,
            answers.MODE_ENV: None, answers.RECORD_ENV: None, "PYTHONDONTWRITEBYTECODE": "1"}


#: Set by the grader (as root) for the checks it runs: the uid (and its RLIMIT_NPROC) that the
#: student's processes run as, while the check itself stays root. The student's code can then
#: neither read nor signal nor trace the check, nor write its results.
STUDENT_UID_ENV = "AUTOGRADER_STUDENT_UID"
STUDENT_NPROC_ENV = "AUTOGRADER_STUDENT_NPROC"

#: How execute() hands the seed to the check process.
SEED_ENV = "AUTOGRADER_CHECK_SEED"


def _mark(path: Path) -> None:
    """Create an empty file in the student's folder, never through a symlink planted there (the
    check may run as root)."""
    try:
        os.close(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_NOFOLLOW, 0o644))
    except OSError:
        pass


def _student_uid() -> int | None:
    uid = os.environ.get(STUDENT_UID_ENV)
    return int(uid) if uid and os.geteuid() == 0 else None


def _student_limits(wall_seconds: float):
    """Bounds of a student process: time, memory, file size, and the grader's uid when given."""
    from course_lib import processes

    uid = _student_uid()
    nproc = int(os.environ.get(STUDENT_NPROC_ENV, "384")) if uid is not None else None
    return processes.Limits(wall_seconds=wall_seconds, memory_mb=STUDENT_MEMORY_MB, file_size_mb=STUDENT_FILE_MB,
                            user=uid, max_processes=nproc, grace_seconds=1.0)


def _give_to_student(path: Path) -> None:
    """Let the student's uid (if any) write the results of its calls into `path`."""
    uid = _student_uid()
    if uid is not None:
        os.chown(path, uid, uid)


def clip(text: str, limit: int = 1500) -> str:
    """At most `limit` characters of a message: its start and its end (student output can be huge)."""
    if len(text) <= limit:
        return text
    return text[:limit // 3] + f" [... {len(text) - limit} characters ...] " + text[-(2 * limit) // 3:]


def _tail(text: str, lines: int) -> str:
    text = text.strip()
    return "\n".join(text.splitlines()[-lines:]) if text else "(no output)"


def _wait_for_file(path: Path, timeout: float, proc) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if path.exists():
            return True
        if not proc.running():
            return path.exists()
        time.sleep(0.02)
    return path.exists()


def _write_calls(job: Path, calls: list[tuple]) -> None:
    import numpy as np

    arrays, manifest = {}, []
    for index, (args, kwargs) in enumerate(calls):
        entry = []
        for position, arg in enumerate(args):
            key = f"c{index}_a{position}"
            arrays[key] = np.asarray(arg)
            entry.append(key)
        manifest.append({"args": entry, "kwargs": kwargs})
    np.savez(job / "inputs.npz", **arrays)
    (job / "calls.json").write_text(json.dumps(manifest))


def _read_outcomes(job: Path, count: int, proc, timeout: float) -> list[Outcome]:
    import numpy as np

    outcomes = []
    for index in range(count):
        meta_path = job / f"{index}.json"
        if not meta_path.exists():
            if proc.exit_reason == "wall_seconds" or proc.returncode is None or proc.exit_reason == "stopped":
                why = f"did not return within {timeout:.0f} s (an endless loop?)"
            else:
                why = f"ended the process ({proc.describe_exit()}) before returning"
            log = _tail(proc.log, 4)
            outcomes.append(Outcome(error=f"the call {why}. Last output:\n{log}"))
            outcomes.extend(Outcome(error="not run: an earlier call did not return") for _ in range(count - index - 1))
            break
        try:
            meta = json.loads(meta_path.read_text())
            arrays = np.load(job / f"{index}.npz", allow_pickle=False) if (job / f"{index}.npz").exists() else {}
            outcomes.append(Outcome(value=_decode(meta["value"], arrays), pytype=meta["value"].get("pytype", "?"),
                                    error=meta.get("error")))
        except (OSError, ValueError, KeyError, TypeError) as error:
            outcomes.append(Outcome(error=f"its result could not be read back ({error})"))
    return outcomes


def _decode(encoded: dict, arrays):
    kind = encoded["type"]
    if kind == "array":
        return arrays[encoded["key"]]
    if kind == "scalar":
        return encoded["value"]
    if kind == "dict":
        return {key: _decode(value, arrays) for key, value in encoded["items"].items()}
    if kind == "none":
        return None
    return encoded.get("repr")


class RosProbe:
    """The checker's side of a ROS exchange: a node in its own context, spun in bounded steps."""

    def __init__(self, domain_id: int):
        import rclpy
        from rclpy.context import Context as RclContext
        from rclpy.executors import SingleThreadedExecutor

        self.context = RclContext()
        rclpy.init(context=self.context, domain_id=domain_id)
        self.node = rclpy.create_node(f"autograder_probe_{os.getpid()}", context=self.context,
                                      enable_rosout=False, start_parameter_services=False)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        if _student_uid() is not None:
            _share_shared_memory()

    def spin_until(self, condition, timeout: float) -> bool:
        """Process callbacks until condition() is true or `timeout` seconds pass; returns condition()."""
        deadline = time.monotonic() + timeout
        while not condition():
            left = deadline - time.monotonic()
            if left <= 0:
                return bool(condition())
            self.executor.spin_once(timeout_sec=min(0.05, left))
        return True

    def spin_for(self, seconds: float) -> None:
        self.spin_until(lambda: False, seconds)

    def wait_for_subscriber(self, publisher, timeout: float) -> bool:
        return self.spin_until(lambda: publisher.get_subscription_count() > 0, timeout)

    def wait_for_publisher(self, subscription, timeout: float) -> bool:
        return self.spin_until(lambda: subscription.get_publisher_count() > 0, timeout)

    def close(self) -> None:
        try:
            self.executor.shutdown(timeout_sec=1.0)
            self.node.destroy_node()
        finally:
            self.context.try_shutdown()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _share_shared_memory() -> None:
    """Let the student's uid use this (root) process's Fast DDS shared-memory files.

    Fast DDS creates its segments, ports and port mutexes 0644, so a node of another uid can
    neither deliver into a root participant's port nor release buffers in its segment: root and
    student nodes would not even discover each other. The grader's /dev/shm is a private tmpfs of
    the submission's sandbox, so opening this process's files to "others" opens them to that
    student's processes only.
    """
    me = os.geteuid()
    for path in Path("/dev/shm").glob("*fastrtps_*"):
        try:
            if path.stat().st_uid == me:
                os.chmod(path, 0o666)
        except OSError:  # another participant's file went away meanwhile
            pass


def run_in_this_process(assignment: str, name: str, seed: int, workdir: Path, out: Path) -> Result:
    """Run a check here (the check process) and return its Result."""
    spec = get_check(assignment, name)
    ctx = Context(spec, seed, workdir, out)
    error = None
    try:
        spec.function(ctx)
    except StudentError as failure:
        error = str(failure)
    except Exception:  # a bug in the check, not the student's fault: say so plainly
        error = "The checker itself failed (tell your instructor):\n" + traceback.format_exc(limit=4)
    finally:
        ctx.close()
    total = sum(item["weight"] for item in ctx.items)
    if error and not any(item["ok"] for item in ctx.items):
        points = 0.0
    else:
        passed = sum(item["weight"] for item in ctx.items if item["ok"])
        points = spec.points * passed / total if total else 0.0
    return Result(assignment, name, round(points, 3), spec.points, seed, ctx.items, ctx.notes, ctx.images, error)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m course_lib.checks.harness", description="Run one graded check.")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run")
    run.add_argument("assignment")
    run.add_argument("check")
    run.add_argument("--seed", type=int, default=None, help=f"default: ${SEED_ENV}, else {SELFCHECK_SEED}")
    run.add_argument("--workdir", default=".")
    run.add_argument("--out", required=True)
    outside = sub.add_parser("outside", help="run the hidden checks of a graded notebook's module (the grader)")
    outside.add_argument("assignment")
    outside.add_argument("checks", nargs="+")
    outside.add_argument("--workdir", required=True)
    outside.add_argument("--out", required=True)
    args = parser.parse_args(argv)
    out = Path(args.out)
    if args.command == "outside":
        run_outside(args.assignment, args.checks, args.workdir, out)
        return 0
    seed = args.seed if args.seed is not None else int(os.environ.get(SEED_ENV, SELFCHECK_SEED))
    result = run_in_this_process(args.assignment, args.check, seed, Path(args.workdir).resolve(), out)
    _write_json(out / "result.json", dataclasses.asdict(result))
    return 0


def _write_json(path: Path, data) -> None:
    path.with_suffix(".tmp").write_text(json.dumps(data))
    os.replace(path.with_suffix(".tmp"), path)


if __name__ == "__main__":
    # Run through the imported module, so that the checks register where they are looked up.
    from course_lib.checks.harness import main as _main

    sys.exit(_main())
