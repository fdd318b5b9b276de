"""The hidden checks, run by the grader outside the student's kernel, and their verdicts in the notebook."""

from __future__ import annotations

import json
import os
from pathlib import Path

from autograder.grading import fork_server
from autograder.results.grade_result import GradeResult
from autograder.results.submissions import Submission
from autograder.sandbox.namespaces import run_sandboxed
from course_lib import contract
from course_lib.checks import registry
from course_lib.checks.result import Result, images_html, verdict_text

#: Seconds between the checks' own budget and the wall limit of their process.
CHECKS_MARGIN = 3.0


def grade_outside(sub: Submission, result: GradeResult, work: Path, autograded: Path, workdir: Path,
                   domain_id: int, env: dict, hide: list[Path], seconds: float | None = None) -> None:
    """Run the hidden checks of the graded cells in processes of the grader, not in the student's
    kernel, against the module the notebook wrote in `workdir`; their points replace the cells'
    scores and their verdicts replace the outputs of the cells of the notebooks in `autograded`
    (runner.grade only said "graded outside").

    The check runs as root in a fresh sandbox (network and mount namespaces); the student's
    processes it starts run as the worker's uid, so they cannot touch the check or its results.
    With `seconds`, the checks together get that much wall time: the process is told
    (contract.CHECKS_SECONDS_ENV, a little less, so that it can still write its verdicts) and stopped after it.
    """
    names = graded_checks(sub, result)
    if names:
        apply_verdicts(result, autograded, run_checks(sub, names, work / "checks", workdir, domain_id, env, hide,
                                                      seconds))


def graded_checks(sub: Submission, result: GradeResult | None = None) -> list[str]:
    """The checks of the submission's graded cells (of every check of its assignment when
    `result` has no cells yet); [] for an assignment of the instructor's own (nbgrader alone)."""
    try:
        checks = registry.checks_of(sub.assignment)
    except ModuleNotFoundError:  # an assignment of the instructor's own, graded by nbgrader alone
        return []
    if result is None:
        return list(checks)
    return [name for name in (check_of(c["cell"]) for c in result.cells) if name in checks]


def run_checks(sub: Submission, names: list[str], out: Path, workdir: Path, domain_id: int, env: dict,
               hide: list[Path], seconds: float | None = None, run=run_sandboxed) -> dict[str, Result]:
    """Run the checks `names` against `workdir` in one sandboxed grader process (see
    grade_outside) and return {name: Result}; `out` (new) gets their JSON; `run` is
    autograder.sandbox.namespaces.run_sandboxed or a wrapper of it."""
    from course_lib.ros import processes

    checks = registry.checks_of(sub.assignment)
    out.mkdir(mode=0o700)
    command = fork_server.program(fork_server.CHECKS_RUN,
                                  [sub.assignment, *names, "--workdir", str(workdir), "--out", str(out)], env)
    wall = sum(checks[name].timeout + 30 for name in names)
    env = {**env, contract.CHECK_SEED_ENV: None, contract.SEED_ENV: os.environ.get(contract.SEED_ENV)}
    if seconds is not None:
        wall = min(wall, seconds)
        env[contract.CHECKS_SECONDS_ENV] = f"{max(1.0, wall - CHECKS_MARGIN):.1f}"
    proc = run(command, hide, f"checks {sub.key} {out.name}", domain_id, env, out,
               processes.Limits(wall_seconds=wall, grace_seconds=5.0))
    verdicts = {}
    for name in names:
        try:
            verdicts[name] = Result(**json.loads((out / f"{name}.json").read_text()))
        except (OSError, ValueError, TypeError):
            stopped = (f"the hidden checks were given {wall:g} s and did not finish: a call or callback of "
                       f"yours may never return" if proc.exit_reason == "wall_seconds" else proc.describe_exit())
            verdicts[name] = Result(sub.assignment, name, 0.0, checks[name].points, 0,
                                    error=f"The grader could not run this check ({stopped}):\n{proc.log_tail(8)}")
    return verdicts


def apply_verdicts(result: GradeResult, autograded: Path, verdicts: dict[str, Result]) -> None:
    """The checks' points in place of their cells' scores, their verdicts in place of the cells'
    outputs in the notebooks of `autograded`."""
    for cell in result.cells:
        if check_of(cell["cell"]) in verdicts:
            cell["auto_score"] = min(verdicts[check_of(cell["cell"])].points, cell["max_score"])
    _write_verdicts(autograded, verdicts)


def check_of(grade_id: str) -> str | None:
    """The check a graded cell runs: grade id "check_<name>" (assignments/build.py names them so)."""
    return grade_id.removeprefix("check_") if grade_id.startswith("check_") else None


def _write_verdicts(folder: Path, verdicts: dict) -> None:
    """Replace the outputs of the graded cells of the notebooks in `folder` by the verdicts."""
    import nbformat

    for path in sorted(folder.glob("*.ipynb")):
        nb = nbformat.read(path, as_version=4)
        for cell in nb.cells:
            name = check_of(cell.get("metadata", {}).get("nbgrader", {}).get("grade_id", ""))
            if cell.cell_type != "code" or name not in verdicts:
                continue
            verdict = verdicts[name]
            cell.outputs = [nbformat.v4.new_output("stream", name="stdout", text=verdict_text(verdict, True))]
            html = images_html(verdict)
            if html:
                cell.outputs.append(nbformat.v4.new_output("display_data", data={"text/html": html}))
        nbformat.write(nb, path)

