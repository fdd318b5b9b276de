"""Release, parallel sandboxed autograding with nbgrader, the grading report.

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
   of the grader (``python -m autograder.checks_outside``, root), against the module the
   notebook wrote; the student's code they start runs as the worker's uid, with the same limits.
   Their points replace nbgrader's scores of those cells, and their verdicts (seed, what passed
   and failed, pictures) replace the cells' outputs in the autograded notebook.
5. The trusted grader reads the other cells' scores from the private gradebook, copies the
   autograded notebook to COURSE_DIR/autograded/ (without the grader's temporary paths), and
   records the scores in the course gradebook as nbgrader's autograde would (autograder.gradebook:
   graded cells are not "needs manual grading", the submission time and late penalty are kept).

A submission whose notebook is not named as released, or whose timestamp.txt holds no date, is
not run at all: it gets 0 and a reason that says so (autograder.intake). After a run, the grading
report (autograder.report) and the LMS export grades.csv (autograder.export) are written again
from everything graded so far, so a partial run (one student, one assignment) drops no row.

Not root: steps 2-4 fall back to ``unshare --user --map-root-user --net --mount`` when
unprivileged user namespaces are allowed (network and mounts isolated, but one uid for all
workers: RLIMIT_NPROC is then shared by the workers, and the student's processes run as the
same user as the checks, which a determined student could tamper with), else to no
namespaces at all (no network isolation; the run says so on stderr and in the grading report's
``isolation`` column).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from autograder import config, gradebook, intake, kernel, student_uid
from course_lib.checks import registry, runner
from course_lib.checks.result import Result, images_html, verdict_text

REPO = Path(__file__).resolve().parent.parent
REPO_SOURCE = REPO / "assignments" / "source"

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


def _env_for_tools() -> dict:
    env = dict(os.environ)
    path = [str(REPO)] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p and p != str(REPO)]
    env["PYTHONPATH"] = os.pathsep.join(path)
    env["PATH"] = gradebook.with_this_python(env.get("PATH", ""))
    return env


def run_nbgrader(args: list[str], course: Path, timeout: float = 300) -> str:
    """Run the nbgrader CLI on a course directory; raise RuntimeError with its output on failure."""
    command = [sys.executable, "-m", "nbgrader", *args, f"--CourseDirectory.root={course}"]
    done = subprocess.run(command, cwd=course, env=_env_for_tools(), capture_output=True, text=True,
                          timeout=timeout)
    if done.returncode != 0:
        raise RuntimeError(f"nbgrader {' '.join(args)} failed (exit code {done.returncode}):\n"
                           f"{(done.stdout + done.stderr)[-3000:]}")
    return done.stdout + done.stderr


def assignments_in(course: Path) -> list[str]:
    source = course / "source"
    return sorted(p.name for p in source.iterdir() if p.is_dir() and any(p.glob("*.ipynb"))) if source.is_dir() else []


def prepare_course(course_dir) -> Path:
    """Create the course root: config, and source/ from the repository when it has none."""
    course = Path(course_dir).resolve()
    course.mkdir(parents=True, exist_ok=True)
    config.write_config(course)
    if not (course / "source").is_dir():
        shutil.copytree(REPO_SOURCE, course / "source",
                        ignore=shutil.ignore_patterns(".ipynb_checkpoints", "__pycache__", "*.py"))
    return course


def release(course_dir, assignments: list[str] | None = None, duedate: str | None = None) -> list[Path]:
    """Write the student versions to COURSE_DIR/release/<assignment>/ (nbgrader generate_assignment).

    This also records each assignment, its cells and its hidden tests in the gradebook, and the
    due date when one is given (autograder.late.set_duedate; kept when released again without one).
    """
    from autograder import late

    course = prepare_course(course_dir)
    written = []
    for name in assignments or assignments_in(course):
        run_nbgrader(["generate_assignment", name, "--force"], course)
        if duedate:
            late.set_duedate(course, name, duedate)
        written.append(course / "release" / name)
    return written


# ---------------------------------------------------------------------------------------------
# Submissions
# ---------------------------------------------------------------------------------------------

@dataclasses.dataclass
class Submission:
    student: str
    assignment: str
    path: Path

    @property
    def key(self) -> str:
        return f"{self.student}/{self.assignment}"


def find_submissions(course: Path, assignment: str | None = None, student: str | None = None) -> list[Submission]:
    """COURSE_DIR/submitted/<student>/<assignment>/ holding at least one notebook, sorted (only one
    assignment's, one student's, when given)."""
    found = []
    submitted = course / "submitted"
    if not submitted.is_dir():
        return found
    for folder_of_student in sorted(p for p in submitted.iterdir() if p.is_dir()):
        if student is not None and folder_of_student.name != student:
            continue
        for folder in sorted(p for p in folder_of_student.iterdir() if p.is_dir()):
            if (assignment is None or folder.name == assignment) and any(folder.glob("*.ipynb")):
                found.append(Submission(folder_of_student.name, folder.name, folder))
    return found


def _tree_digest(paths: list[Path], digest) -> None:
    for base in paths:
        files = [base] if base.is_file() else sorted(p for p in base.rglob("*") if p.is_file())
        for path in files:
            digest.update(str(path.relative_to(base.parent)).encode() + b"\0" + path.read_bytes() + b"\0")


#: The modules of course_lib.checks that run every assignment's checks (a change regrades).
CHECK_MODULES = ["registry", "result", "runner", "check_process", "context", "student_calls", "student_processes",
                 "probe", "student", "answers"]


def submission_digest(sub: Submission, course: Path) -> str:
    """Changes when the submission, the assignment's source or the grading code changes."""
    digest = hashlib.sha256()
    _tree_digest([sub.path, course / "source" / sub.assignment], digest)
    here, checks = Path(__file__).resolve().parent, Path(registry.__file__).resolve().parent
    code = [here / "kernel.py", here / "config.py", here / "checks_outside.py", here / "student_uid.py", here / "run_as.py",
            here / "answers" / f"{sub.assignment}.py",
            *(checks / f"{name}.py" for name in CHECK_MODULES), checks / f"{sub.assignment}.py"]
    _tree_digest([path for path in code if path.exists()], digest)
    return digest.hexdigest()


# ---------------------------------------------------------------------------------------------
# The sandbox
# ---------------------------------------------------------------------------------------------

_ISOLATION: str | None = None


def isolation() -> str:
    """"root" (namespaces and per-worker uids), "userns" (namespaces, one uid) or "none"."""
    global _ISOLATION
    if _ISOLATION is None:
        if os.geteuid() == 0 and shutil.which("unshare") and shutil.which("ip"):
            _ISOLATION = "root"
        elif shutil.which("unshare") and subprocess.run(
                ["unshare", "--user", "--map-root-user", "--net", "--mount", "true"],
                capture_output=True).returncode == 0:
            _ISOLATION = "userns"
        else:
            _ISOLATION = "none"
            print("autograder: no namespaces available (not root, no user namespaces): submissions run "
                  "WITHOUT network isolation and can see the course directory", file=sys.stderr)
    return _ISOLATION


_SANDBOX_SCRIPT = r'''
set -e
ip link set lo up
mount --make-rprivate /
# No sticky bit: Fast DDS replaces a dead participant's shared-memory port by unlinking it, and
# the student's uid must be able to do so for ports a (root) check process left behind.
mount -t tmpfs -o size=2g,mode=0777 autograder-shm /dev/shm
if [ -n "$AUTOGRADER_EXPOSE" ]; then
  # The interpreter lives under a directory the kernel's uid cannot enter (a pyenv under /root):
  # hide that directory under a tmpfs and put the interpreter's prefix back at the same path.
  mount --bind "$AUTOGRADER_EXPOSE" "$AUTOGRADER_STAGE"
  mount -t tmpfs -o size=1m,mode=755 autograder-home "$AUTOGRADER_BLOCKED"
  mkdir -p "$AUTOGRADER_EXPOSE"
  mount --move "$AUTOGRADER_STAGE" "$AUTOGRADER_EXPOSE"
fi
for hidden in "$@"; do
  case "$hidden" in --) shift; break;; esac
  [ -d "$hidden" ] && mount -t tmpfs -o size=1m,mode=755 autograder-hidden "$hidden"
  shift
done
exec "$@"
'''


def sandbox_command(command: list[str], hide: list[Path]) -> list[str]:
    """Wrap a command so that it runs in a network + mount namespace (see the module docstring)."""
    mode = isolation()
    if mode == "none":
        return command
    prefix = ["unshare", "--net", "--mount"] if mode == "root" else \
        ["unshare", "--user", "--map-root-user", "--net", "--mount"]
    return prefix + ["sh", "-c", _SANDBOX_SCRIPT, "autograder-sandbox",
                     *[str(p) for p in hide], "--", *command]


def interpreter_exposure() -> dict:
    """When this interpreter's prefix sits below a directory others cannot enter (e.g. /root),
    the sandbox variables that make it reachable for the kernel's uid; else {}."""
    prefix = Path(sys.base_prefix).resolve()
    for ancestor in reversed(prefix.parents):
        if ancestor != Path("/") and not os.stat(ancestor).st_mode & 0o001:
            return {"AUTOGRADER_EXPOSE": str(prefix), "AUTOGRADER_BLOCKED": str(ancestor)}
    return {}


def _run_sandboxed(command: list[str], hide: list[Path], name: str, domain_id: int, env: dict, cwd: Path, limits):
    """Run a command in the sandbox (sandbox_command) to its end or its wall time; return the
    stopped course_lib.processes.NodeProcess (its log, returncode, describe_exit())."""
    from course_lib import processes

    proc = processes.NodeProcess(sandbox_command(command, hide), name=name, domain_id=domain_id, env=env, cwd=cwd,
                                 limits=limits)
    proc.start()
    try:
        proc.wait(limits.wall_seconds + 30)
    except TimeoutError:
        pass
    finally:
        proc.stop(timeout=5)
    return proc


#: Folders of the repository that a submission's processes never see (empty tmpfs over each):
#: the reference solutions and the instructor's side (the grader, its answer keys, the tests).
HIDDEN_FROM_STUDENTS = [REPO / "assignments", REPO / "autograder", REPO / "tests", REPO / "benchmarks"]


def stage_grader(work: Path) -> Path:
    """Copy the autograder package into `work`/grader, readable by root only, and return that
    folder (first on the sandbox's PYTHONPATH). The sandbox hides the repository's autograder/;
    the grader's own processes (nbgrader's config, the kernel launcher, the checks' answer keys)
    import this copy, while the student's uid cannot enter it."""
    folder = work / "grader"
    shutil.copytree(Path(__file__).resolve().parent, folder / "autograder",
                    ignore=shutil.ignore_patterns("__pycache__"))
    os.chmod(folder, 0o700)
    return folder


def _private_copy(source: Path, target: Path) -> None:
    """Copy a directory tree readable by root only (other workers' uids cannot read it)."""
    shutil.copytree(source, target, ignore=shutil.ignore_patterns(".ipynb_checkpoints"))
    for directory, dirs, files in os.walk(target):
        os.chmod(directory, 0o711)
        for name in files:
            os.chmod(os.path.join(directory, name), 0o600)


# ---------------------------------------------------------------------------------------------
# Grading one submission
# ---------------------------------------------------------------------------------------------

@dataclasses.dataclass
class GradeResult:
    student: str
    assignment: str
    digest: str
    score: float = 0.0
    max_score: float = 0.0
    cells: list[dict] = dataclasses.field(default_factory=list)
    status: str = "graded"       # graded | failed (the notebook could not be run to the end)
    reason: str = ""             # for the student (the feedback shows it)
    detail: str = ""             # for the instructor only (the fix, nbgrader's log): the grading report
    seconds: float = 0.0
    isolation: str = ""
    from_cache: bool = False     # True: an earlier run's result (the submission did not change)
    kernel_uid: int | None = None  # the uid the student's code ran as (root isolation only)

    @classmethod
    def from_dict(cls, data: dict) -> "GradeResult":
        """A result as recorded (autograder.json), also one written by an older grader."""
        names = {field.name for field in dataclasses.fields(cls)}
        return cls(**{key: value for key, value in data.items() if key in names})


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
        _keep_autograded(course, sub, None)
        _keep_log(course, sub, problem.fix + "\n")
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
        _private_copy(sub.path, root / "submitted" / sub.student / sub.assignment)
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
               runner.OUTSIDE_ENV: "1",
               "JUPYTER_PATH": str(work / "jupyter"), "JUPYTER_RUNTIME_DIR": str(work / "runtime"),
               "JUPYTER_CONFIG_DIR": str(work / "jupyter-config"), "AUTOGRADER_KERNEL_TMP": str(work / "kernel-tmp"),
               "PYTHONPATH": os.pathsep.join([str(grader), _env_for_tools()["PYTHONPATH"]]), "HOME": str(work),
               "PYDEVD_DISABLE_FILE_VALIDATION": "1"}
        if result.isolation == "root":
            result.kernel_uid = KERNEL_UID_BASE + domain_id
            env.update(AUTOGRADER_KERNEL_UID=str(result.kernel_uid), AUTOGRADER_KERNEL_NPROC=str(NPROC))
            env.update({student_uid.STUDENT_UID_ENV: str(result.kernel_uid), student_uid.STUDENT_NPROC_ENV: str(NPROC)})
            exposure = interpreter_exposure()
            if exposure:
                (work / "stage").mkdir()
                env.update(exposure, AUTOGRADER_STAGE=str(work / "stage"))
        command = [sys.executable, "-m", "nbgrader", "autograde", sub.assignment, "--student", sub.student,
                   "--force", f"--CourseDirectory.root={root}"]
        hide = [course, *HIDDEN_FROM_STUDENTS]
        limits = processes.Limits(wall_seconds=NOTEBOOK_TIMEOUT, memory_mb=MEMORY_MB, file_size_mb=FILE_MB,
                                  grace_seconds=5.0)
        proc = _run_sandboxed(command, hide, f"autograde {sub.key}", domain_id, env, root, limits)
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
            _grade_outside(sub, result, work, autograded, workdir, domain_id, env, hide)
            _scrub_paths(autograded, work)
        if any(c["auto_score"] is None for c in result.cells):
            result.detail += "\nSome cells need manual grading (the formgrader lists them)."
        _keep_autograded(course, sub, autograded if result.status != "failed" else None)
        _keep_log(course, sub, log)
    finally:
        _remove_tree(work)
    result.score = round(sum(c["auto_score"] or 0 for c in result.cells), 3) if result.status != "failed" else 0.0
    result.seconds = round(time.monotonic() - started, 1)
    return result


def _grade_outside(sub: Submission, result: GradeResult, work: Path, autograded: Path, workdir: Path,
                   domain_id: int, env: dict, hide: list[Path]) -> None:
    """Run the hidden checks of the graded cells in processes of the grader, not in the student's
    kernel, against the module the notebook wrote in `workdir`; their points replace the cells'
    scores and their verdicts replace the outputs of the cells of the notebooks in `autograded`
    (runner.grade only said "graded outside").

    The check runs as root in a fresh sandbox (network and mount namespaces); the student's
    processes it starts run as the worker's uid, so they cannot touch the check or its results.
    """
    from course_lib import processes

    try:
        checks = registry.checks_of(sub.assignment)
    except ModuleNotFoundError:  # an assignment of the instructor's own, graded by nbgrader alone
        return
    names = [name for name in (_check_of(c["cell"]) for c in result.cells) if name in checks]
    if not names:
        return
    out = work / "checks"
    out.mkdir(mode=0o700)
    command = [sys.executable, "-m", "autograder.checks_outside", sub.assignment, *names,
               "--workdir", str(workdir), "--out", str(out)]
    wall = sum(checks[name].timeout + 30 for name in names)
    env = {**env, runner.SEED_ENV: None, "AUTOGRADER_SEED": os.environ.get("AUTOGRADER_SEED")}
    proc = _run_sandboxed(command, hide, f"checks {sub.key}", domain_id, env, out,
                          processes.Limits(wall_seconds=wall, grace_seconds=5.0))
    verdicts = {}
    for name in names:
        try:
            verdicts[name] = Result(**json.loads((out / f"{name}.json").read_text()))
        except (OSError, ValueError, TypeError):
            verdicts[name] = Result(sub.assignment, name, 0.0, checks[name].points, 0,
                                            error=f"The grader could not run this check ({proc.describe_exit()}):\n"
                                                  f"{proc.log_tail(8)}")
    for cell in result.cells:
        if _check_of(cell["cell"]) in verdicts:
            cell["auto_score"] = min(verdicts[_check_of(cell["cell"])].points, cell["max_score"])
    _write_verdicts(autograded, verdicts)


def _keep_autograded(course: Path, sub: Submission, autograded: Path | None) -> None:
    """Replace COURSE_DIR/autograded/<student>/<assignment>/ by the graded copy (None: an empty
    folder, so that the formgrader lists the submission as autograded, with its score 0)."""
    target = course / "autograded" / sub.student / sub.assignment
    if target.exists():
        shutil.rmtree(target)
    if autograded is not None and autograded.is_dir():
        shutil.copytree(autograded, target, symlinks=True, ignore=shutil.ignore_patterns("__pycache__", ".autograder-*"))
    else:
        target.mkdir(parents=True, exist_ok=True)


def _keep_log(course: Path, sub: Submission, log: str) -> None:
    folder = state_dir(course, sub.student, sub.assignment)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "autograder.log").write_text(log[-200000:])


def _scrub_paths(folder: Path, work: Path) -> None:
    """Remove the grader's folders from the notebooks in `folder`: a traceback of the student's
    module names it as pubsub_nodes.py, not /tmp/autograder-work-.../.autograder-cwd/pubsub_nodes.py,
    and the grader's own files by their place in the repository (autograder/student.py)."""
    prefixes = [f"{folder / kernel.WORK_SUBDIR}{os.sep}", f"{folder}{os.sep}", f"{REPO}{os.sep}"]
    for path in sorted(folder.glob("*.ipynb")):
        text = original = path.read_text()
        for prefix in prefixes:
            text = text.replace(prefix, "")
        text = text.replace(str(work), "<grader's work folder>")
        if text != original:
            path.write_text(text)


def _check_of(grade_id: str) -> str | None:
    """The check a graded cell runs: grade id "check_<name>" (assignments/build.py names them so)."""
    return grade_id.removeprefix("check_") if grade_id.startswith("check_") else None


def _write_verdicts(folder: Path, verdicts: dict) -> None:
    """Replace the outputs of the graded cells of the notebooks in `folder` by the verdicts."""
    import nbformat

    for path in sorted(folder.glob("*.ipynb")):
        nb = nbformat.read(path, as_version=4)
        for cell in nb.cells:
            name = _check_of(cell.get("metadata", {}).get("nbgrader", {}).get("grade_id", ""))
            if cell.cell_type != "code" or name not in verdicts:
                continue
            verdict = verdicts[name]
            cell.outputs = [nbformat.v4.new_output("stream", name="stdout", text=verdict_text(verdict, True))]
            html = images_html(verdict)
            if html:
                cell.outputs.append(nbformat.v4.new_output("display_data", data={"text/html": html}))
        nbformat.write(nb, path)


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


# ---------------------------------------------------------------------------------------------
# The course gradebook and the recorded results
# ---------------------------------------------------------------------------------------------

STATE_FILE = "autograder.json"


def state_dir(course: Path, student: str, assignment: str) -> Path:
    """Where the grader keeps a submission's result and log: COURSE_DIR/autograder/<student>/<assignment>/
    (not in autograded/, whose files nbgrader copies into the student's feedback)."""
    return Path(course) / "autograder" / student / assignment


def _store(course: Path, result: GradeResult, course_config) -> None:
    """Record a result in the course gradebook (autograder.gradebook) and beside the notebook."""
    _record(course, result, course_config)
    target = state_dir(course, result.student, result.assignment)
    target.mkdir(parents=True, exist_ok=True)
    (target / STATE_FILE).write_text(json.dumps(dataclasses.asdict(result), indent=1))


def _record(course: Path, result: GradeResult, course_config) -> None:
    """The result's scores, the submission time and the late penalty, in the course gradebook (a
    result from an earlier run: the time and penalty only, when the gradebook has its scores)."""
    scores = {} if result.status == "failed" else {(c["notebook"], c["cell"]): c["auto_score"] for c in result.cells}
    try:
        timestamp = gradebook.submitted_timestamp(course / "submitted" / result.student / result.assignment)
    except ValueError:  # intake.check failed the submission for it, with the fix
        timestamp = None
    result.max_score = gradebook.record(course, result.student, result.assignment, scores, timestamp, course_config,
                                        earlier=result.from_cache)


def _cached(course: Path, sub: Submission) -> GradeResult | None:
    path = state_dir(course, sub.student, sub.assignment) / STATE_FILE
    try:
        result = GradeResult.from_dict(json.loads(path.read_text()))
        if result.digest == submission_digest(sub, course):
            result.from_cache = True
            return result
    except (OSError, ValueError, KeyError, TypeError):
        pass
    return None


def recorded_results(course, assignment: str | None = None, student: str | None = None) -> list[GradeResult]:
    """Every result recorded so far (COURSE_DIR/autograder/<student>/<assignment>/autograder.json),
    or one assignment's, one student's; sorted by student and assignment."""
    import glob

    pattern = f"{glob.escape(student) if student else '*'}/{glob.escape(assignment) if assignment else '*'}/{STATE_FILE}"
    results = []
    for path in sorted((Path(course) / "autograder").glob(pattern)):
        try:
            results.append(GradeResult.from_dict(json.loads(path.read_text())))
        except (OSError, ValueError, TypeError) as error:
            raise ValueError(f"{path} cannot be read ({error}): delete it and grade that submission again "
                             f"(python -m autograder grade COURSE_DIR --student {path.parent.parent.name} "
                             f"--assignment {path.parent.name} --force)") from None
    return results


class _Progress:
    def __init__(self, total: int, stream=sys.stderr):
        self.total, self.done, self.stream, self.lock = total, 0, stream, threading.Lock()
        self.started = time.monotonic()

    def update(self, result: GradeResult) -> None:
        with self.lock:
            self.done += 1
            width = 30
            filled = int(width * self.done / max(1, self.total))
            bar = "#" * filled + "." * (width - filled)
            self.stream.write(f"[{bar}] {self.done}/{self.total} {result.student}/{result.assignment}: "
                              f"{result.score:g}/{result.max_score:g} {result.status} ({result.seconds:g} s, "
                              f"{time.monotonic() - self.started:.0f} s elapsed)\n")
            self.stream.flush()


def grade(course_dir, assignment: str | None = None, workers: int = 1, force: bool = False,
          progress: bool = True, student: str | None = None) -> list[GradeResult]:
    """Autograde every submission (or one assignment's, one student's), then write the grading
    report and grades.csv again from everything graded so far.

    Unchanged submissions that were graded before are not graded again unless force=True; their
    recorded scores go into the gradebook again with the late penalty of today's due dates.
    Returns the results of the submissions found, in (student, assignment) order.
    """
    from course_lib import rosenv

    from autograder import export, late, report

    course = prepare_course(course_dir)
    course_config = config.load(course)
    late.check_settings(course_config, assignments_in(course))
    subs = find_submissions(course, assignment, student)
    if not subs and (assignment or student):
        raise ValueError(f"No submission in {course / 'submitted'} matches --student {student or '(any)'} "
                         f"--assignment {assignment or '(any)'}; the submissions there: "
                         f"{', '.join(s.key for s in find_submissions(course)) or 'none'}")
    known = set()
    if (course / "gradebook.db").exists():
        with gradebook.open_gradebook(course) as gb:
            known = {a.name for a in gb.assignments}
    missing = sorted({s.assignment for s in subs} - known)
    if missing:
        release(course, missing)  # records the assignments (and their hidden tests) in the gradebook
    results: dict[str, GradeResult] = {}
    todo = []
    for sub in subs:
        cached = None if force else _cached(course, sub)
        if cached is not None:
            _record(course, cached, course_config)
            results[sub.key] = cached
        else:
            todo.append(sub)
    bar = _Progress(len(todo)) if progress and todo else None
    store_lock = threading.Lock()

    def work(sub: Submission) -> GradeResult:
        with rosenv.reserve_domain_id() as reservation:
            result = grade_submission(sub, course, reservation.domain_id)
        with store_lock:
            _store(course, result, course_config)
        if bar:
            bar.update(result)
        return result

    with ThreadPoolExecutor(max_workers=max(1, workers)) as pool:
        for sub, result in zip(todo, pool.map(work, todo)):
            results[sub.key] = result
    ordered = [results[s.key] for s in subs]
    report.write_report(course, ordered)
    export.export(course)
    return ordered
