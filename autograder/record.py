"""``python -m autograder record-answers [ASSIGNMENT ...]``: record the self-checks' answers.

Self-checks compare with answers recorded from the grader's answer key (course_lib.checks.answers)
for the self-check seed's inputs. This runs every check of each assignment that has an answer key
(autograder/answers/<assignment>.py) against the reference solution with the self-check seed,
writes down every answer the key gives, and replaces course_lib/checks/recorded/<assignment>.json.
Run it after changing a check's inputs or an answer key.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from autograder import packages, reference
from course_lib import contract
from course_lib.checks import answers, registry, runner
from course_lib.checks.result import points_text

ANSWER_KEYS = Path(__file__).resolve().parent / "answers"


def assignments_with_keys() -> list[str]:
    return sorted(p.stem for p in ANSWER_KEYS.glob("*.py") if p.stem != "__init__")


def record_answers(assignments: list[str] | None = None) -> list[Path]:
    """Record the answers of the given assignments (default: all with an answer key); return the files.

    Raises:
        RuntimeError: the reference solution did not get every point of a check (the recording
            would then miss the answers of the paths it did not reach).
    """
    with tempfile.TemporaryDirectory(prefix="autograder-record-") as tmp:
        lines = Path(tmp) / "answers.jsonl"
        lines.touch()
        previous = os.environ.get(contract.RECORD_ANSWERS_ENV)
        os.environ[contract.RECORD_ANSWERS_ENV] = str(lines)
        try:
            for assignment in assignments or assignments_with_keys():
                workdir = Path(tmp) / assignment
                workdir.mkdir()
                reference.write_reference_workspace(assignment, workdir)
                report = packages.build_here(assignment, workdir)
                if not report.ok:
                    raise RuntimeError(f"the {assignment} reference packages do not build: {report.reason}")
                os.environ[contract.BUILD_REPORT_ENV] = str(packages.report_path(workdir))
                for name in registry.checks_of(assignment):
                    result = runner.execute(assignment, name, runner.SELFCHECK_SEED, workdir=workdir, mode="record")
                    if result.points < result.max_points:
                        raise RuntimeError(f"the reference solution got {points_text(result.points)} of {points_text(result.max_points)} "
                                           f"points in {assignment}/{name}:\n" + "\n".join(result.verdict_lines()))
        finally:
            os.environ.pop(contract.BUILD_REPORT_ENV, None)
            if previous is None:
                os.environ.pop(contract.RECORD_ANSWERS_ENV, None)
            else:
                os.environ[contract.RECORD_ANSWERS_ENV] = previous
        return answers.merge_recording(lines)
