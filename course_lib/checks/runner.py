"""How a graded check runs: the same code for the self-check and the autograder.

Where things run:

- the notebook kernel only starts the check and prints its verdict (:func:`run_check`): the check
  runs in a process of its own (``python -m course_lib.checks.check_process run ...``) with a wall-time bound,
  so nothing a check does can hang or crash the kernel, and nothing the kernel's state holds
  (a node the student left spinning, a patched module) changes the check;
- the student's code runs in a third process, started by the check (:meth:`Context.call` for
  plain functions, course_lib.checks.packages.run for nodes, as `ros2 run`), with its own limits and, for
  ROS, a ROS_DOMAIN_ID reserved for the check. A student process that loops, crashes or exits
  costs the points of that check and nothing else.

At grading the course's grader (autograder.term.grade) runs the hidden checks itself, outside the
student's kernel (``python -m autograder.grading.hidden_checks_process``): :func:`grade` in the notebook only
says so. As root the check stays root and the student's processes run as the grader's worker
uid (AUTOGRADER_STUDENT_UID), so the student's code can neither fake a check's result nor read
its seed (passed in the environment, not on the command line).

Seeds: a self-check uses fixed seeds (the same frames every time, so a student can debug);
grading draws a fresh seed per check (or takes AUTOGRADER_SEED to reproduce a grade) and
the verdict prints it, so that the feedback records it.

Expected answers (:meth:`Context.expected`, course_lib.checks.answers): graded, from the grader's
answer key (instructor side only: the grader hands its checks ``autograder/answers/`` as
contract.ANSWER_KEYS_ENV); in a self-check, the answers that key
gave for the self-check's inputs, recorded as data. Nothing a student can import or read holds
a reference solution, and nothing the student's process can read holds a graded answer.

Points: the check's items each pass or fail; the check earns ``points × passed weight / total
weight``, to two decimals (course_lib.checks.result.round_points). The value of the test cell is
that number, which nbgrader 0.9 takes as partial credit
(an ``execute_result`` that converts to float; an error or anything on stderr gives 0).
"""

from __future__ import annotations

import base64
import json
import os
import secrets
import shutil
import sys
import tempfile
import time
from pathlib import Path

from course_lib import contract
from course_lib.checks.registry import get_check
from course_lib.checks.result import Result, images_html, round_points, verdict_text

#: The fixed seed of self-checks (what the student sees when running the notebook).
SELFCHECK_SEED = 2024


def selfcheck(assignment: str, name: str) -> None:
    """Run a check with the fixed self-check seed and print its verdict once: what passed and what
    failed. When points were lost the verdict goes to stderr, where nbgrader's Validate looks for
    a cell's errors (it then lists the verdict instead of a bare "Partial credit"), else to stdout.
    Returns nothing, so that the cell does not end with a bare number.

    Under grading (COURSE_LIB_GRADING=1) it does nothing: the hidden test that follows it in the
    same cell runs the check with a fresh seed.
    """
    from course_lib.ros import rosenv

    if rosenv.under_grading():
        return
    result = execute(assignment, name, SELFCHECK_SEED)
    stream = sys.stderr if result.points < result.max_points else sys.stdout
    stream.write(verdict_text(result, graded=False) + "\n")
    stream.flush()
    _display_images(result)


#: Set by the course's grader (autograder.term.grade) for the notebook run: the hidden tests do not
#: run in the student's kernel, where the student's code could fake their result; the grader
#: runs them afterwards in processes of its own (see :func:`grade_outside`) and writes the
#: verdicts into the graded notebook.


def grade(assignment: str, name: str) -> float:
    """Run a check with a fresh seed (AUTOGRADER_SEED to reproduce one), print the seed and the
    verdict, return the points earned (the test cell's value is the partial credit).

    Under the course's grader (AUTOGRADER_CHECKS_OUTSIDE=1) it only says so and returns 0: the
    grader runs the check itself and replaces this cell's output and score.
    """
    if os.environ.get(contract.CHECKS_OUTSIDE_ENV) == "1":
        print(f"[graded] {get_check(assignment, name).description}\n"
              "  The autograder runs this check outside the notebook; its verdict replaces this text.")
        return 0.0
    return round_points(run_check(assignment, name, fresh_seed(), graded=True).points)


def fresh_seed() -> int:
    """A seed drawn now, or AUTOGRADER_SEED when set (to reproduce a grade)."""
    seed = os.environ.get(contract.SEED_ENV)
    return int(seed) if seed else secrets.randbelow(2**31)


def run_check(assignment: str, name: str, seed: int, graded: bool = False, workdir=None) -> Result:
    """Run one check in a separate process, print its verdict, display its pictures, return its Result."""
    result = execute(assignment, name, seed, workdir=workdir, mode="graded" if graded else "selfcheck")
    print(verdict_text(result, graded))
    _display_images(result)
    return result


def execute(assignment: str, name: str, seed: int, workdir=None, mode: str = "selfcheck") -> Result:
    """Run a check in its own process and return its Result (0 points when it failed to finish).

    `mode` says where its expected answers come from (course_lib.checks.answers): "selfcheck"
    (recorded answers; only the self-check seed's inputs are recorded), "graded" (the grader's
    answer key) or "record" (graded, and the answers written to $AUTOGRADER_RECORD_TO).
    """
    from course_lib import progress
    from course_lib.ros import processes

    spec = get_check(assignment, name)
    workdir = Path(workdir or os.getcwd()).resolve()
    out = Path(tempfile.mkdtemp(prefix="autograder-check-"))
    started = time.monotonic()
    # The seed goes in the environment, which other uids cannot read (a command line they can).
    # The working directory is the check's own: a student's file next to the notebook (json.py,
    # numpy.py) must not shadow a module the checker imports.
    command = [sys.executable, "-m", "course_lib.checks.check_process", "run", assignment, name,
               "--workdir", str(workdir), "--out", str(out)]
    limits = processes.Limits(wall_seconds=spec.timeout + 10, grace_seconds=2.0)
    proc = processes.NodeProcess(command, name=f"autograder-check-{name}", cwd=out, limits=limits,
                                 env={"PYTHONPATH": child_pythonpath(), contract.CHECK_SEED_ENV: str(seed),
                                      contract.ANSWERS_ENV: mode})
    try:
        with progress.Progress(f"check {name!r}") as shown:  # a line under the notebook's cell
            shown.step(spec.description)
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
        embed_images(result, out)
    finally:
        proc.stop(timeout=3)
        shutil.rmtree(out, ignore_errors=True)
    result.points = max(0.0, min(result.points, spec.points))
    result.seconds = round(time.monotonic() - started, 2)
    return result


def embed_images(result: Result, out: Path) -> None:
    """Replace the file names of the result's pictures (written to `out`) by their PNG bytes."""
    for image in result.images:
        path = out / image.pop("file", "")
        if path.is_file():
            image["png"] = base64.b64encode(path.read_bytes()).decode()



def child_pythonpath() -> str:
    """The directory holding course_lib (in a course checkout also the autograder), first on the
    path of child processes."""
    root = str(contract.ROOT)
    rest = [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p and p != root]
    return os.pathsep.join([root] + rest)



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



#: How execute() hands the seed to the check process.
