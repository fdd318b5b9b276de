"""What a check function gets (:class:`Context`): the seed, the student's work directory, ways to
run the student's code in processes of its own, and the record of what passed."""

from __future__ import annotations

import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

from course_lib import waiting
from course_lib.checks import answers
from course_lib.checks.probe import RosProbe
from course_lib.checks.registry import Check
from course_lib.checks.student_calls import Outcome, last_lines, read_outcomes, write_calls
from course_lib.checks.student_processes import StudentProcesses

#: Seconds a student's module gets to import (rclpy alone needs one or two on a busy machine).
IMPORT_TIMEOUT = 25.0

#: Written into the work directory when the student's module did not import in time, so that
#: later checks fail at once with the same reason instead of waiting again.
IMPORT_HANG_MARK = ".autograder-import-hang"


class StudentError(Exception):
    """The student's code failed (raised, crashed, hung); str() says how, for the feedback."""



class Context:
    """What a check function gets: the seed, the student's work directory, and ways to run the
    student's code and to record what passed.

    Attributes:
        seed: this run's seed; rng: a numpy Generator seeded with it.
        workdir: the directory of the student's notebook and module files.
        domain_id: a ROS domain reserved for this check (student nodes and probes use it).
        students: how the student's processes start (StudentProcesses; the grader passes its own).
    """

    def __init__(self, spec: Check, seed: int, workdir: Path, out: Path, students: StudentProcesses | None = None):
        import numpy as np

        self.spec = spec
        self.seed = seed
        self.rng = np.random.default_rng(seed)
        self.workdir = workdir
        self.out = out
        self.students = students or StudentProcesses()
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
            write_calls(job, calls)
            timeout = min(timeout or self.remaining(), self.remaining())
            proc, call_seconds = self._run_student("call", function, job, timeout)
            return read_outcomes(job, len(calls), proc, call_seconds)
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
                                   f"{last_lines(proc.log, 6)}") from None
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
        if module is None:  # a module of a built package (env: its workspace) needs no source check
            self.require_module()
        module = module or self.module
        self.students.give(job)
        timeout = min(timeout, self.remaining())
        deadline = time.monotonic() + timeout
        proc = self.students.start([sys.executable, "-m", "course_lib.checks.student", command, module, target,
                                    str(job)], name=f"student-{target}",
                                   cwd=self.module_root if env is None else self.workdir, domain_id=self.domain_id,
                                   wall_seconds=timeout + 2, env=env)
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
                               f"{last_lines(proc.log, 6)}")
        return proc, call_seconds

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
        probe = RosProbe(self.domain_id)
        self.students.probe_started()
        return probe

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


def _mark(path: Path) -> None:
    """Create an empty file in the student's folder, never through a symlink planted there (the
    check may run as root)."""
    try:
        os.close(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_NOFOLLOW, 0o644))
    except OSError:
        pass


def clip(text: str, limit: int = 1500) -> str:
    """At most `limit` characters of a message: its start and its end (student output can be huge)."""
    if len(text) <= limit:
        return text
    return text[:limit // 3] + f" [... {len(text) - limit} characters ...] " + text[-(2 * limit) // 3:]


def _wait_for_file(path: Path, timeout: float, proc) -> bool:
    waiting.spin_until(lambda: path.exists() or not proc.running(), timeout, poll=0.02)
    return path.exists()
