"""Grading one submission with nbgrader in the sandbox (autograder.sandbox).

One submission is graded like this (:func:`grade_submission`, run by a worker thread):

1. A private work directory gets a course root of its own: nbgrader_config.py, a copy of the
   gradebook (root-only, 0600: it holds the hidden tests) and a copy of the submission. The
   submitted files themselves are only read.
2. ``nbgrader autograde`` runs there, through course_lib.processes (wall time per notebook,
   address space, file size; every descendant is killed at the end) and, as root, inside
   ``unshare --net --mount``: a network namespace with only loopback (no connection leaves the
   machine; DDS traffic stays in it), a private /dev/shm (Fast DDS shared memory), and the course
   directory and the repository's assignments/ and tests/ hidden under empty tmpfs mounts.
3. nbgrader starts the kernel through autograder.kernel, which drops to a uid of this worker
   (61000 + its ROS domain id) with RLIMIT_NPROC, in a subfolder of its own. The notebook's
   hidden test cells only say that the grader runs them (AUTOGRADER_CHECKS_OUTSIDE=1): a check
   run in the student's kernel could be faked by the student's code (patch checks.grade and
   every test cell "passes").
4. The hidden checks run after the notebook, in a fresh sandbox of the same kind, as processes
   of the grader (``python -m course_lib.checks.harness outside``, root), against the module the
   notebook wrote; the student's code they start runs as the worker's uid, with the same limits.
   Their points replace nbgrader's scores of those cells, and their verdicts (seed, what passed
   and failed, pictures) replace the cells' outputs in the autograded notebook.
5. The trusted grader reads the other cells' scores from the private gradebook, copies the
   autograded notebook to COURSE_DIR/autograded/ (without the grader's temporary paths), and
   records the scores in the course gradebook as nbgrader's autograde would (autograder.gradebook:
   graded cells are not "needs manual grading", the submission time and late penalty are kept).
"""

from __future__ import annotations

import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

from autograder import config, gradebook, intake, kernel
from autograder.nbgrader_cli import env_for_tools
from autograder.outputs import keep_autograded, keep_log, scrub_paths
from autograder.outside_checks import grade_outside
from autograder.result import GradeResult
from autograder.sandbox import HIDDEN_FROM_STUDENTS, interpreter_exposure, isolation, run_sandboxed
from autograder.staging import private_copy, stage_grader
from autograder.submissions import Submission, submission_digest
from course_lib.checks import harness


#: Seconds one notebook may take under grading, everything included.
NOTEBOOK_TIMEOUT = 420.0
#: Address space of each process of a submission (MB). Fast DDS + numpy + OpenCV need ~1 GB.
MEMORY_MB = 4096
#: Largest file a submission may write (MB).
FILE_MB = 256
#: Processes and threads of one worker's uid (root only). A kernel, a check and a node need ~100.
NPROC = 384
#: Base of the per-worker uids (root only): uid = KERNEL_UID_BASE + reserved ROS domain id.
KERNEL_UID_BASE = 61000


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


def grade_submission(sub: Submission, course: Path, domain_id: int) -> GradeResult:
    """Autograde one submission in a sandbox; see the module docstring. Never raises for the
    student's faults: a submission that breaks its notebook run gets 0 and the reason."""
    from course_lib import processes

    started = time.monotonic()
    result = GradeResult(sub.student, sub.assignment, submission_digest(sub, course), isolation=isolation())
    problem = intake.check(course, sub.student, sub.assignment, sub.path)
    if problem is not None:  # nothing to run: say why and how to fix it
        result.status, result.reason, result.detail = "failed", problem.reason, problem.fix
        keep_autograded(course, sub, None)
        keep_log(course, sub, problem.fix + "\n")
        result.seconds = round(time.monotonic() - started, 1)
        return result
    work = Path(tempfile.mkdtemp(prefix="autograder-work-"))
    try:
        os.chmod(work, 0o711)
        root = work / "course"
        root.mkdir(mode=0o711)
        config.write_config(root)
        shutil.copyfile(course / "gradebook.db", root / "gradebook.db")
        os.chmod(root / "gradebook.db", 0o600)
        private_copy(sub.path, root / "submitted" / sub.student / sub.assignment)
        os.chmod(root / "submitted", 0o711)
        os.chmod(root / "submitted" / sub.student, 0o711)
        kernels = work / "jupyter" / "kernels" / "python3"
        kernels.mkdir(parents=True)
        (kernels / "kernel.json").write_text(json.dumps({
            "argv": [sys.executable, "-m", "autograder.kernel", "{connection_file}"],
            "display_name": "Python 3 (autograder sandbox)", "language": "python"}))
        for folder in (work / "jupyter", work / "runtime", work / "kernel-tmp"):
            folder.mkdir(exist_ok=True)
            os.chmod(folder, 0o711)
        grader = stage_grader(work)
        env = {"COURSE_LIB_GRADING": "1", "COURSE_LIB_UNDER_TEST": None, "AUTOGRADER_SEED": None,
               harness.OUTSIDE_ENV: "1",
               "JUPYTER_PATH": str(work / "jupyter"), "JUPYTER_RUNTIME_DIR": str(work / "runtime"),
               "JUPYTER_CONFIG_DIR": str(work / "jupyter-config"), "AUTOGRADER_KERNEL_TMP": str(work / "kernel-tmp"),
               "PYTHONPATH": os.pathsep.join([str(grader), env_for_tools()["PYTHONPATH"]]), "HOME": str(work),
               "PYDEVD_DISABLE_FILE_VALIDATION": "1"}
        if result.isolation == "root":
            result.kernel_uid = KERNEL_UID_BASE + domain_id
            env.update(AUTOGRADER_KERNEL_UID=str(result.kernel_uid), AUTOGRADER_KERNEL_NPROC=str(NPROC))
            env.update({harness.STUDENT_UID_ENV: str(result.kernel_uid), harness.STUDENT_NPROC_ENV: str(NPROC)})
            exposure = interpreter_exposure()
            if exposure:
                (work / "stage").mkdir()
                env.update(exposure, AUTOGRADER_STAGE=str(work / "stage"))
        command = [sys.executable, "-m", "nbgrader", "autograde", sub.assignment, "--student", sub.student,
                   "--force", f"--CourseDirectory.root={root}"]
        hide = [course, *HIDDEN_FROM_STUDENTS]
        limits = processes.Limits(wall_seconds=NOTEBOOK_TIMEOUT, memory_mb=MEMORY_MB, file_size_mb=FILE_MB,
                                  grace_seconds=5.0)
        proc = run_sandboxed(command, hide, f"autograde {sub.key}", domain_id, env, root, limits)
        log = proc.log
        autograded = root / "autograded" / sub.student / sub.assignment
        try:
            result.cells = _cell_scores(root, sub)
        except Exception as error:  # no submission in the gradebook: nbgrader did not get that far
            result.cells = []
            result.status = "failed"
            result.reason = f"nbgrader autograde did not finish ({proc.describe_exit()}): {error}"
        if proc.returncode != 0 and result.status != "failed":
            result.status = "failed"
            result.reason = f"nbgrader autograde ended with {proc.describe_exit()}"
        if result.status == "failed":
            # The student reads the first line; nbgrader's log is for the instructor.
            result.detail = result.reason.strip() + "\n" + "\n".join(log.strip().splitlines()[-15:])
            result.reason = _explain_failure(log, proc)
        if result.status != "failed":
            # As root the kernel ran in a subfolder of its own uid (autograder.kernel), where the
            # notebook wrote the student's module.
            workdir = autograded / kernel.WORK_SUBDIR if result.kernel_uid is not None else autograded
            grade_outside(sub, result, work, autograded, workdir, domain_id, env, hide)
            scrub_paths(autograded, work)
        if any(c["auto_score"] is None for c in result.cells):
            result.detail += "\nSome cells need manual grading (the formgrader lists them)."
        keep_autograded(course, sub, autograded if result.status != "failed" else None)
        keep_log(course, sub, log)
    finally:
        _remove_tree(work)
    result.score = round(sum(c["auto_score"] or 0 for c in result.cells), 3) if result.status != "failed" else 0.0
    result.seconds = round(time.monotonic() - started, 1)
    return result



def _explain_failure(log: str, proc) -> str:
    """A failed submission's reason, in the student's terms."""
    if "Kernel died" in log or "DeadKernelError" in log:
        return ("The notebook's Python kernel died while running your code (a crash such as a segfault, "
                "os._exit() or sys.exit() at the top level, or being killed for using too much memory): "
                "no cell after it could run, so every check scores 0.")
    if proc.exit_reason == "wall_seconds":
        return (f"The notebook did not finish within {NOTEBOOK_TIMEOUT:g} s: something in it runs forever "
                "or waits for input.")
    return (f"The grader could not run your notebook to its end ({proc.describe_exit()}); your instructor has "
            "the details.")


def _remove_tree(path: Path) -> None:
    def retry(function, name, _exc):
        try:
            os.chmod(os.path.dirname(name), 0o700)
            function(name)
        except OSError:
            pass
    shutil.rmtree(path, onerror=retry)

