"""The grader's run of a graded notebook's hidden checks, outside the student's kernel:
``python -m autograder.hidden_checks_process ASSIGNMENT CHECK... --workdir DIR --out DIR`` (started by autograder.hidden_checks)."""

from __future__ import annotations

import argparse
import dataclasses
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

from autograder.student_uid import StudentUid
from course_lib.checks import answers
from course_lib.checks.check_process import write_json, run_in_this_process
from course_lib.checks.registry import get_check
from course_lib.checks.runner import embed_images, fresh_seed


def run_outside(assignment: str, names: list[str], workdir, out: Path) -> None:
    """The grader's run of a graded notebook's checks: each with a fresh seed and the answer key,
    one after the other in this process (one interpreter start-up for all of them; the student's
    code they call runs in processes of its own, bounded in time, as the grader's student uid when it
    set one: autograder.student_uid), each result in out/<name>.json."""
    os.environ[answers.MODE_ENV] = "graded"
    students = StudentUid.from_environment()
    for name in names:
        spec = get_check(assignment, name)
        scratch = Path(tempfile.mkdtemp(prefix=f"autograder-{name}-"))
        started = time.monotonic()
        try:
            result = run_in_this_process(assignment, name, fresh_seed(), Path(workdir).resolve(), scratch,
                                         students)
            embed_images(result, scratch)
        finally:
            shutil.rmtree(scratch, ignore_errors=True)
        result.points = max(0.0, min(result.points, spec.points))
        result.seconds = round(time.monotonic() - started, 2)
        write_json(out / f"{name}.json", dataclasses.asdict(result))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m autograder.hidden_checks_process",
                                     description="Run the hidden checks of a graded notebook's module (the grader).")
    parser.add_argument("assignment")
    parser.add_argument("checks", nargs="+")
    parser.add_argument("--workdir", required=True)
    parser.add_argument("--out", required=True)
    args = parser.parse_args(argv)
    run_outside(args.assignment, args.checks, args.workdir, Path(args.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
