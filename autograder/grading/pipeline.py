"""Grading one submission with nbgrader in the sandbox (autograder.sandbox.namespaces).

One submission is graded like this (:func:`grade_submission`, run by a worker thread; its steps
are listed in :data:`STEPS`):

1. A private work directory gets a course root of its own: nbgrader_config.py, a copy of the
   gradebook (root-only, 0600: it holds the hidden tests) and a copy of the submission. The
   submitted files themselves are only read.
2. ``nbgrader autograde`` runs there, through course_lib.ros.processes (wall time per notebook,
   address space, file size; every descendant is killed at the end) and, as root, inside
   ``unshare --net --mount``: a network namespace with only loopback (no connection leaves the
   machine; DDS traffic stays in it), a private /dev/shm (Fast DDS shared memory), and the course
   directory and the repository's assignments/ and tests/ hidden under empty tmpfs mounts.
3. nbgrader starts the kernel through autograder.sandbox.kernel, which drops to a uid of this worker
   (61000 + its ROS domain id) with RLIMIT_NPROC, in a subfolder of its own. The notebook's
   hidden test cells only say that the grader runs them (AUTOGRADER_CHECKS_OUTSIDE=1): a check
   run in the student's kernel could be faked by the student's code (patch checks.grade and
   every test cell "passes").
4. The hidden checks run in a fresh sandbox of the same kind, as processes
   of the grader (``python -m autograder.grading.hidden_checks_process``, root), against the module the
   notebook wrote; the student's code they start runs as the worker's uid, with the same limits
   but fewer processes and threads (checks_max_processes).
   Their points replace nbgrader's scores of those cells, and their verdicts (seed, what passed
   and failed, pictures) replace the cells' outputs in the autograded notebook. The workspace is
   built and checked while nbgrader runs the notebook, from the files the notebook is predicted
   to write, as a uid of its own (the worker's + EARLY_UID_OFFSET: the kernel cannot reach those
   files; autograder.grading.early_checks); when it wrote other files, again after it, from those. A
   build of an identical workspace is copied instead (autograder.builds.caches.WorkspaceBuilds).
5. The trusted grader reads the other cells' scores from the private gradebook, copies the
   autograded notebook to COURSE_DIR/autograded/ (without the grader's temporary paths), and
   records the scores in the course gradebook as nbgrader's autograde would (autograder.results.gradebook:
   graded cells are not "needs manual grading", the submission time and late penalty are kept).
"""

from __future__ import annotations

import dataclasses
import json
import os
import shutil
import sys
import time
from pathlib import Path

from autograder import config
from autograder.builds import workspace_build
from autograder.grading import early_checks, fork_server, intake, work_folders
from autograder.grading.hidden_checks import apply_verdicts, grade_outside, graded_checks
from autograder.grading.outputs import keep_autograded, keep_log, scrub_paths
from autograder.grading.staging import private_copy, stage_grader
from autograder.nbgrader_cli import env_for_tools
from autograder.results import gradebook
from autograder.results.grade_result import GradeResult
from autograder.results.submissions import Submission, submission_digest
from autograder.sandbox import kernel
from autograder.sandbox.namespaces import HIDDEN_FROM_STUDENTS, interpreter_exposure, isolation, run_sandboxed
from course_lib import contract
from course_lib.checks import context
from course_lib.checks.result import round_points
from course_lib.ros import rosenv
from course_lib.supervision import process_tree

#: Seconds one submission's grading may take on an idle machine, every step included (issue #14:
#: a hostile submission must not stall the class). Each step gets at most what is left of it.
GRADING_SECONDS = 60.0
#: On a machine busier than its cores, the budget grows with the load (grading_budget), at most
#: this many times (the checks' backstops grow alike): the bound is on the share of the machine a
#: submission gets, and a reference submission that takes 6 s on an idle machine took 40 s with a
#: load of 20 on 2 cores.
MAX_LOAD_FACTOR = context.MAX_LOAD_FACTOR
#: Seconds one notebook may take under grading, everything included (also bounded by what is left
#: of GRADING_SECONDS less KEPT_FOR_CHECKS).
NOTEBOOK_TIMEOUT = 420.0
#: Seconds of the budget the notebook run and the build leave for the hidden checks.
KEPT_FOR_CHECKS = 20.0
#: Set to 0 to build and check only after the notebook ran (autograder.grading.early_checks), e.g. on a
#: one-core machine, where overlapping them gains nothing.
#: Largest file a submission may write (MB).
FILE_MB = 256
#: Base of the per-worker uids (root only): uid = KERNEL_UID_BASE + reserved ROS domain id.
KERNEL_UID_BASE = 61000
#: The early build and checks run as the worker's uid + EARLY_UID_OFFSET: the kernel, which runs
#: beside them, cannot change their files (a build kept for identical workspaces among them).
EARLY_UID_OFFSET = 1000


def _cell_scores(root: Path, sub: Submission) -> list[dict]:
    """The scores nbgrader gave the submission's cells in the gradebook of the course root `root`."""
    with gradebook.open_gradebook(root) as gb:
        submission = gb.find_submission(sub.assignment, sub.student)
        cells = []
        for notebook in submission.notebooks:
            for grade in notebook.grades:
                cells.append({"notebook": notebook.name, "cell": grade.name,
                              "auto_score": grade.auto_score, "max_score": grade.max_score})
        return cells


@dataclasses.dataclass
class Grading:
    """One submission's grading while the steps run: what they share."""
    sub: Submission
    course: Path
    domain_id: int
    result: GradeResult
    work: Path                 # the private work folder (autograder.grading.work_folders), removed at the end
    env: dict = dataclasses.field(default_factory=dict)  # for every sandboxed process
    notebook_run: object = None  # the nbgrader autograde process (course_lib.ros.processes.NodeProcess)
    deadline: float = 0.0      # time.monotonic() by which the grading must end (grading_budget)
    budget: float = GRADING_SECONDS  # the seconds the grading was given
    notebook_seconds: float = 0.0  # the wall time the notebook run was given
    early: early_checks.EarlyRun | None = None  # the build and checks of the predicted files
    early_verdicts: dict | None = None  # their verdicts, when the notebook wrote the predicted files

    def seconds_left(self, keep: float = 0.0) -> float:
        """Seconds of the submission's budget left, less `keep` for later steps (at least 1)."""
        return max(1.0, self.deadline - time.monotonic() - keep)

    @property
    def root(self) -> Path:
        """The private course root nbgrader grades in."""
        return self.work / "course"

    @property
    def submitted(self) -> Path:
        """The private copy of the submission that nbgrader grades."""
        return self.root / "submitted" / self.sub.student / self.sub.assignment

    @property
    def early_uid(self) -> int | None:
        """The uid of the early build and checks (root only; autograder.grading.early_checks)."""
        return None if self.result.kernel_uid is None else self.result.kernel_uid + EARLY_UID_OFFSET

    @property
    def autograded(self) -> Path:
        return self.root / "autograded" / self.sub.student / self.sub.assignment

    @property
    def workdir(self) -> Path:
        """Where the notebook wrote the student's files: as root the kernel ran in a subfolder of
        its own uid (autograder.sandbox.kernel)."""
        return self.autograded / kernel.WORK_SUBDIR if self.result.kernel_uid is not None else self.autograded

    @property
    def hide(self) -> list[Path]:
        """What the sandbox hides: the course directory and the repository's instructor folders."""
        return [self.course, *HIDDEN_FROM_STUDENTS]

    @property
    def failed(self) -> bool:
        return self.result.status == "failed"


def stage_course_root(g: Grading) -> None:
    """A course root of its own in the work folder (config, a root-only copy of the
    gradebook and of the submission) and the sandbox's kernelspec."""
    os.chmod(g.work, 0o711)
    root = g.root
    root.mkdir(mode=0o711)
    config.write_config(root)
    shutil.copyfile(g.course / "gradebook.db", root / "gradebook.db")
    os.chmod(root / "gradebook.db", 0o600)
    private_copy(g.sub.path, g.submitted)
    os.chmod(root / "submitted", 0o711)
    os.chmod(g.submitted.parent, 0o711)
    kernels = g.work / "jupyter" / "kernels" / "python3"
    kernels.mkdir(parents=True)
    (kernels / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "autograder.sandbox.kernel", "{connection_file}"],
        "display_name": "Python 3 (autograder sandbox)", "language": "python"}))
    for folder in (g.work / "jupyter", g.work / "runtime", g.work / "kernel-tmp"):
        folder.mkdir(exist_ok=True)
        os.chmod(folder, 0o711)


def choose_environment(g: Grading) -> None:
    """A root-only copy of the grader (autograder.grading.staging) and the sandboxed processes'
    environment: grading flags, Jupyter's folders, that copy first on PYTHONPATH; as root the
    worker's uid and process limit for the student's code."""
    work = g.work
    grader = stage_grader(work)
    g.env = {contract.GRADING_ENV: "1", contract.UNDER_TEST_ENV: None, contract.SEED_ENV: None,
             contract.CHECKS_OUTSIDE_ENV: "1",
             "JUPYTER_PATH": str(work / "jupyter"), "JUPYTER_RUNTIME_DIR": str(work / "runtime"),
             "JUPYTER_CONFIG_DIR": str(work / "jupyter-config"), contract.KERNEL_TMP_ENV: str(work / "kernel-tmp"),
             "PYTHONPATH": os.pathsep.join([str(grader), env_for_tools()["PYTHONPATH"]]), "HOME": str(work),
             contract.LOAD_FACTOR_ENV: f"{g.budget / GRADING_SECONDS:.2f}"}
    if g.result.isolation == "root":
        g.result.kernel_uid = KERNEL_UID_BASE + g.domain_id
        uid = str(g.result.kernel_uid)
        g.env.update({contract.KERNEL_UID_ENV: uid, contract.KERNEL_NPROC_ENV: str(contract.MAX_PROCESSES)})
        g.env.update({contract.STUDENT_UID_ENV: uid, contract.STUDENT_NPROC_ENV: str(checks_max_processes())})
        exposure = interpreter_exposure()
        if exposure:
            (work / "stage").mkdir()
            g.env.update(exposure, **{contract.STAGE_ENV: str(work / "stage")})


def checks_max_processes(cores: int | None = None) -> int:
    """Processes and threads the student's uid may have while the checks run its code (RLIMIT_NPROC):
    contract.CHECKS_PROCESSES_BASE plus CHECKS_PROCESSES_PER_CORE per core of this machine (default:
    the cores this process may run on), at most contract.MAX_PROCESSES."""
    cores = len(os.sched_getaffinity(0)) if cores is None else cores
    return min(contract.MAX_PROCESSES, contract.CHECKS_PROCESSES_BASE + contract.CHECKS_PROCESSES_PER_CORE * cores)


def start_early_checks(g: Grading) -> None:
    """Build and check the files the notebook is predicted to write while it runs
    (autograder.grading.early_checks); build_workspace decides afterwards whether they count."""
    names = graded_checks(g.sub)
    wanted = os.environ.get(contract.EARLY_CHECKS_ENV, "1") != "0"
    if wanted and names and workspace_build.needed(g.sub.assignment, g.submitted):
        g.early = early_checks.EarlyRun(g, names, build_for_checks).start()


def run_notebook(g: Grading) -> None:
    """``nbgrader autograde`` in the sandbox (autograder.grading.sandboxed_autograde), within the notebook's limits."""
    from course_lib.ros import processes

    command = fork_server.program(fork_server.NOTEBOOK_RUN, [str(g.root), g.sub.assignment, g.sub.student], g.env)
    g.notebook_seconds = round(min(NOTEBOOK_TIMEOUT, g.seconds_left(keep=KEPT_FOR_CHECKS)), 1)
    limits = processes.Limits(wall_seconds=g.notebook_seconds, memory_mb=contract.MEMORY_MB, file_size_mb=FILE_MB,
                              grace_seconds=2.0)
    g.notebook_run = run_sandboxed(command, g.hide, f"autograde {g.sub.key}", g.domain_id, g.env, g.root, limits)


def read_scores(g: Grading) -> None:
    """The cells' scores from the private gradebook; a run that did not finish fails the
    submission with a reason for the student and nbgrader's log for the instructor."""
    proc, result = g.notebook_run, g.result
    try:
        result.cells = _cell_scores(g.root, g.sub)
    except Exception as error:  # no submission in the gradebook: nbgrader did not get that far
        result.cells = []
        result.status = "failed"
        result.reason = f"nbgrader autograde did not finish ({proc.describe_exit()}): {error}"
    if proc.returncode != 0 and result.status != "failed":
        result.status = "failed"
        result.reason = f"nbgrader autograde ended with {proc.describe_exit()}"
    if result.status == "failed":
        # The student reads the first line; nbgrader's log is for the instructor.
        result.detail = result.reason.strip() + "\n" + "\n".join(proc.log.strip().splitlines()[-15:])
        result.reason = _explain_failure(proc.log, proc, g.notebook_seconds, g.budget)


def build_workspace(g: Grading) -> None:
    """The student's ROS 2 workspace built with colcon in the sandbox, interface packages from the
    course's cache (autograder.builds.workspace_build); the checks read its report."""
    if g.early is not None:
        early, g.early = g.early, None
        if g.failed:  # nothing to check: its reason is the notebook's
            early.cancel()
            return
        outcome = early.outcome_for(g.workdir, graded_checks(g.sub, g.result))
        g.result.steps["early_build_and_checks"] = early.seconds
        g.result.checked_early = outcome is not None
        if outcome is not None:
            built, g.early_verdicts = outcome
            _use_build(g, built)
            return
    if g.failed or not workspace_build.needed(g.sub.assignment, g.workdir):
        return
    _use_build(g, build_for_checks(g, g.workdir))


def _use_build(g: Grading, built: dict) -> None:
    """The checks' variables of a build (build_for_checks), and what the report says of it."""
    g.env.update(built)
    report = workspace_build.read_report(built)
    g.result.build_reused = bool(report and report.reused)
    g.result.detail += workspace_build.instructor_note(report)


def build_for_checks(g: Grading, workdir: Path, run=run_sandboxed, early: bool = False) -> dict:
    """Build workdir's workspace for the checks (autograder.builds.workspace_build.build_for_checks) within what
    is left of the budget less half of KEPT_FOR_CHECKS; return the checks' variables. Building an
    interface package the cache did not have is the course's cost, not the student's: the
    deadline moves back by its time (also when the early run builds, in its thread).

    `early`: the build runs beside the notebook (autograder.grading.early_checks), as Grading.early_uid,
    with folders of its own; it is kept (for identical workspaces, and a new message package in
    the course's cache) only when that uid is not the kernel's (as root)."""
    uid = g.early_uid if early else g.result.kernel_uid
    built, interface_seconds = workspace_build.build_for_checks(
        g.sub.assignment, g.course, g.work, workdir, uid, g.domain_id, g.env, g.hide, run,
        seconds=g.seconds_left(keep=KEPT_FOR_CHECKS / 2), prefix=f"{early_checks.FOLDER}-" if early else "",
        store=not early or uid is not None)
    g.deadline += interface_seconds
    return built


def run_hidden_checks(g: Grading) -> None:
    """The hidden checks, outside the kernel (autograder.grading.hidden_checks)."""
    if g.failed:
        return
    if g.early_verdicts is not None:
        apply_verdicts(g.result, g.autograded, g.early_verdicts)
        return
    grade_outside(g.sub, g.result, g.work, g.autograded, g.workdir, g.domain_id, g.env, g.hide,
                  seconds=g.seconds_left())


def remove_grader_paths(g: Grading) -> None:
    """The grader's folders out of the graded notebooks (autograder.grading.outputs.scrub_paths)."""
    if not g.failed:
        scrub_paths(g.autograded, g.work)


def note_manual_grading(g: Grading) -> None:
    """Tell the instructor when cells are left to grade by hand."""
    if any(c["auto_score"] is None for c in g.result.cells):
        g.result.detail += "\nSome cells need manual grading (the formgrader lists them)."


def keep_outputs(g: Grading) -> None:
    """The graded notebooks into COURSE_DIR/autograded/ (an empty folder when failed) and
    nbgrader's log beside the recorded result."""
    keep_autograded(g.course, g.sub, g.autograded if not g.failed else None)
    keep_log(g.course, g.sub, g.notebook_run.log)


#: Grading one submission, in order (each step sees what the earlier ones left in Grading).
STEPS = (stage_course_root, choose_environment, start_early_checks, run_notebook, read_scores, build_workspace,
         run_hidden_checks, remove_grader_paths, note_manual_grading, keep_outputs)


def grade_submission(sub: Submission, course: Path, domain_id: int) -> GradeResult:
    """Autograde one submission in a sandbox, step by step (STEPS; see the module docstring). Never
    raises for the student's faults: a submission that breaks its notebook run gets 0 and the reason."""
    started = time.monotonic()
    result = GradeResult(sub.student, sub.assignment, submission_digest(sub, course), isolation=isolation())
    problem = intake.check(course, sub.student, sub.assignment, sub.path)
    if problem is not None:  # nothing to run: say why and how to fix it
        result.status, result.reason, result.detail = "failed", problem.reason, problem.fix
        keep_autograded(course, sub, None)
        keep_log(course, sub, problem.fix + "\n")
        result.seconds = round(time.monotonic() - started, 1)
        return result
    budget = grading_budget()
    grading = Grading(sub, course, domain_id, result, work_folders.make(),
                      deadline=started + budget, budget=budget)
    try:
        for step in STEPS:
            step_started = time.monotonic()
            step(grading)
            result.steps[step.__name__] = round(time.monotonic() - step_started, 2)
    finally:
        if grading.early is not None:  # a step raised: stop it before its folder goes
            grading.early.cancel()
        _end_student_processes(grading)
        work_folders.remove(grading.work)
    result.score = round_points(sum(c["auto_score"] or 0 for c in result.cells)) if result.status != "failed" else 0.0
    result.seconds = round(time.monotonic() - started, 1)
    return result


def _end_student_processes(g: Grading) -> None:
    """Kill whatever still runs as the submission's uids (root only), before its domain, and so its
    uids, go to another submission. Every process of the student's is stopped with the process
    that started it (course_lib.supervision.supervisor); this is the grader's guarantee all the
    same, and the instructor's report names what it found."""
    if g.result.kernel_uid is None:
        return
    left = sum(process_tree.kill_uid(uid) for uid in (g.result.kernel_uid, g.early_uid))
    if left:
        g.result.detail += (f"\n{left} process(es) of the student's uid still ran when the grading of this submission "
                            "ended; the grader killed them.")


def grading_budget() -> float:
    """GRADING_SECONDS, times the machine's load per core over the last minute when that is above 1
    (at most MAX_LOAD_FACTOR): the steps' limits are wall time, and a loaded machine gives each
    process a fraction of a core."""
    return round(GRADING_SECONDS * rosenv.load_factor(MAX_LOAD_FACTOR), 1)


def _explain_failure(log: str, proc, seconds: float, budget: float) -> str:
    """A failed submission's reason, in the student's terms."""
    if "Kernel died" in log or "DeadKernelError" in log:
        return ("The notebook's Python kernel died while running your code (a crash such as a segfault, "
                "os._exit() or sys.exit() at the top level, or being killed for using too much memory): "
                "no cell after it could run, so every check scores 0.")
    if proc.exit_reason == "wall_seconds":
        cell = _cells_timed_out(log)
        return (f"The notebook did not finish within the {seconds:g} s its run was given (of "
                f"{budget:g} s for grading one submission): something in it runs forever or waits "
                f"for input{cell}.")
    return (f"The grader could not run your notebook to its end ({proc.describe_exit()}); your instructor has "
            "the details.")


def _cells_timed_out(log: str) -> str:
    """What nbgrader's log says of cells stopped at their time limit (validate.cell_timeout):
    ", and N cell(s) ran past their limit of S s", or ""."""
    import re

    limits = re.findall(r"Timeout waiting for execute reply \((\d+)s\)", log)
    if not limits:
        return ""
    return f"; {len(limits)} cell(s) ran past their limit of {', '.join(sorted(set(limits)))} s and were interrupted"
