"""The process a check runs in: ``python -m course_lib.checks.check_process run ASSIGNMENT CHECK
--workdir DIR --out DIR`` (started by course_lib.checks.runner.execute)."""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys
import traceback
from pathlib import Path

from course_lib import contract
from course_lib.checks.context import Context, StudentError
from course_lib.checks.registry import get_check
from course_lib.checks.result import Result, earned_points
from course_lib.checks.runner import SELFCHECK_SEED
from course_lib.checks.student_processes import StudentProcesses
from course_lib.ros import processes


def run_in_this_process(assignment: str, name: str, seed: int, workdir: Path, out: Path,
                        students: StudentProcesses | None = None, on_start=None, **context) -> Result:
    """Run a check here (the check process) and return its Result; `students` starts the student's
    processes (default: as this process's user, course_lib.checks.student_processes); `context`:
    more of Context's arguments (servers, deadline, domain_id); on_start(ctx) is called first."""
    spec = get_check(assignment, name)
    ctx = Context(spec, seed, workdir, out, students, **context)
    if on_start is not None:
        on_start(ctx)
    error = None
    try:
        spec.function(ctx)
    except StudentError as failure:
        error = str(failure)
    except Exception:  # a bug in the check, not the student's fault: say so plainly
        error = "The checker itself failed (tell your instructor):\n" + traceback.format_exc(limit=4)
    finally:
        ctx.close()
    points = earned_points(spec.points, ctx.items, failed=error is not None)
    return Result(assignment, name, points, spec.points, seed, ctx.items, ctx.notes, ctx.images, error,
                  seeded=ctx.seeded)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m course_lib.checks.check_process",
                                     description="Run one graded check.")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run")
    run.add_argument("assignment")
    run.add_argument("check")
    run.add_argument("--seed", type=int, default=None,
                     help=f"default: ${contract.CHECK_SEED_ENV}, else {SELFCHECK_SEED}")
    run.add_argument("--workdir", default=".")
    run.add_argument("--out", required=True)
    args = parser.parse_args(argv)
    out = Path(args.out)
    seed = args.seed if args.seed is not None else int(os.environ.get(contract.CHECK_SEED_ENV, SELFCHECK_SEED))
    try:
        result = run_in_this_process(args.assignment, args.check, seed, Path(args.workdir).resolve(), out)
    finally:
        processes.stop_all(timeout=1.0)
    write_json(out / "result.json", dataclasses.asdict(result))
    return 0


def write_json(path: Path, data) -> None:
    """Write `data` as JSON so that a reader never sees half a file (a temporary file, renamed)."""
    path.with_suffix(".tmp").write_text(json.dumps(data))
    os.replace(path.with_suffix(".tmp"), path)


if __name__ == "__main__":
    # Run through the imported module, so that the checks register where they are looked up.
    from course_lib.checks.check_process import main as _main

    sys.exit(_main())
