"""Building and checking a submission while nbgrader runs its notebook.

The checks read only files: the package the notebook writes (``ros2_ws/src/...``) and what was
handed in beside it. Those files are predicted from the notebook without running it
(autograder.builds.notebook_writes: its ``%%writefile`` cells, ``!mkdir -p`` and ``!touch`` lines) and
written into a folder of the submission's own, a copy of the submitted folder; there the
submission is built and checked (the same build and checks as afterwards, in the same sandbox;
as root, as a student uid of their own that the kernel's code cannot reach) while nbgrader runs
the notebook. When the notebook has run, the grader compares the files of the folder it ran in
with the predicted ones
(notebook_writes.folder_digest): equal, the early build and verdicts are the submission's;
different (a cell wrote a file some other way, or failed), they are dropped and the grader builds
and checks the files the notebook wrote, as it would have without this.

On two cores the notebook's run (about 5 s of one core) and the build with the checks (about
10 s, partly on both) overlap instead of following each other.
"""

from __future__ import annotations

import shutil
import threading
import time
from pathlib import Path

from autograder.builds import notebook_writes
from autograder.grading import hidden_checks
from autograder.sandbox import kernel, run_as
from autograder.sandbox.namespaces import run_sandboxed
from course_lib import contract

#: The folder in the grader's work folder that the early build and checks run in.
FOLDER = "early"
#: How many times the grading's budget outcome_for waits for the early run at most: a backstop for
#: a hang of the thread itself, never reached while its steps keep their own limits.
EARLY_BACKSTOP = 2.0


class EarlyRun:
    """The early build and checks of one submission (see the module docstring), in a thread."""

    def __init__(self, g, names: list[str], build):
        """`g`: the grading (autograder.grading.pipeline.Grading); `names`: the checks to run; `build`:
        autograder.grading.pipeline.build_for_checks (it moves the grading's deadline back by a cold
        interface build, which the checks and outcome_for then see)."""
        self.g, self.names, self.build = g, names, build
        self.folder = g.work / FOLDER / kernel.WORK_SUBDIR
        self.digest = ""
        self.built: dict = {}
        self.verdicts: dict | None = None
        self.seconds = 0.0
        self._cancelled = threading.Event()
        self._current = None  # the sandboxed process of the current step
        self._lock = threading.Lock()
        self._thread = threading.Thread(target=self._run, name=f"early {g.sub.key}", daemon=True)

    def start(self) -> EarlyRun:
        """Write the predicted folder (a copy of the submitted one with the notebook's predicted
        files) and start building and checking it."""
        g = self.g
        shutil.copytree(g.submitted, self.folder, symlinks=True, ignore=shutil.ignore_patterns(".ipynb_checkpoints"))
        for notebook in sorted(g.submitted.glob("*.ipynb")):
            notebook_writes.predicted_writes(notebook).apply(self.folder)
        self.digest = notebook_writes.folder_digest(self.folder)
        if g.early_uid is not None:
            run_as.give_tree(self.folder, g.early_uid)
        self.folder.parent.chmod(0o711)
        self.folder.chmod(0o700)
        self._thread.start()
        return self

    def _sandboxed(self, *args, **kwargs):
        """autograder.sandbox.namespaces.run_sandboxed, its process kept so that cancel() can stop it."""
        def keep(proc):
            with self._lock:
                self._current = proc
            if self._cancelled.is_set():
                proc.stop(timeout=2)
        return run_sandboxed(*args, **kwargs, on_start=keep)

    def _run(self) -> None:
        g = self.g
        started = time.monotonic()
        try:
            self.built = self.build(g, self.folder, self._sandboxed, early=True)
            if self._cancelled.is_set():
                return
            env = {**g.env, **self.built}
            if g.early_uid is not None:
                env[contract.STUDENT_UID_ENV] = str(g.early_uid)
            self.verdicts = hidden_checks.run_checks(
                g.sub, self.names, g.work / f"{FOLDER}-checks", self.folder, g.domain_id, env,
                g.hide, g.seconds_left(), run=self._sandboxed)
        finally:
            self.seconds = round(time.monotonic() - started, 2)

    def cancel(self) -> None:
        """Stop the early run (its verdicts will not be used)."""
        self._cancelled.set()
        with self._lock:
            current = self._current
        if current is not None:
            current.stop(timeout=2)
        self._thread.join(10)

    def outcome_for(self, workdir: Path, names: list[str]):
        """The early (build variables, verdicts of `names`) when the notebook's run left `workdir`
        with exactly the predicted files, else None (the early run is then stopped).

        Waits for the early run to end, however long past the grading's deadline: its build and
        checks are bounded by their own limits, and the verdicts are the same ones the grader would
        get by building and checking now, with less of the budget left. (Giving up at the deadline
        made a busy machine's grading build and check again with a second left: the verdict then
        depended on the load.) EARLY_BACKSTOP only guards against a thread that hangs."""
        same = notebook_writes.folder_digest(workdir) == self.digest if Path(workdir).is_dir() else False
        if not same:
            self.cancel()
            return None
        self._thread.join(EARLY_BACKSTOP * self.g.budget)
        if self._thread.is_alive():
            self.cancel()
            return None
        if names and (self.verdicts is None or not set(names) <= set(self.verdicts)):
            return None
        return self.built, {name: self.verdicts[name] for name in names} if names else {}
