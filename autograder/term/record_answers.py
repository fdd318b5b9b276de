"""``python -m autograder record-answers [ASSIGNMENT ...]``: record the self-checks' answers.

Self-checks compare with answers recorded from the grader's answer key (course_lib.checks.answers)
for the self-check seed's inputs. This runs every check of each assignment that has an answer key
(its spec's ``answers="key"``: autograder/answers/<assignment>.py) against the reference solution
with the self-check seed, writes down every answer the key gives, and replaces
course_lib/checks/recorded/<assignment>.json.
Run it after changing a check's inputs or an answer key.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

from autograder import answers as answer_keys
from autograder.builds import reference, workspace_build
from course_lib import contract
from course_lib.checks import answers, registry, runner
from course_lib.checks.assignments import ASSIGNMENTS
from course_lib.checks.result import points_text


def assignments_with_keys() -> list[str]:
    return sorted(name for name, spec in ASSIGNMENTS.items() if spec.answers == "key")


def record_answers(assignments: list[str] | None = None) -> list[Path]:
    """Record the answers of the given assignments (default: all with an answer key); return the files.

    Raises:
        RuntimeError: the reference solution did not get every point of a check (the recording
            would then miss the answers of the paths it did not reach).
    """
    with tempfile.TemporaryDirectory(prefix="autograder-record-") as tmp, \
            _environment({**answer_keys.environment(), contract.RECORD_ANSWERS_ENV: str(Path(tmp) / "answers.jsonl")}):
        lines = Path(os.environ[contract.RECORD_ANSWERS_ENV])
        lines.touch()
        for assignment in assignments or assignments_with_keys():
            workdir = Path(tmp) / assignment
            workdir.mkdir()
            reference.write_reference_workspace(assignment, workdir)
            report = workspace_build.build_here(assignment, workdir)
            if not report.ok:
                raise RuntimeError(f"the {assignment} reference packages do not build: {report.reason}")
            with _environment({contract.BUILD_REPORT_ENV: str(workspace_build.report_path(workdir))}):
                for name in registry.checks_of(assignment):
                    result = runner.execute(assignment, name, runner.SELFCHECK_SEED, workdir=workdir, mode="record")
                    if result.points < result.max_points:
                        raise RuntimeError(f"the reference solution got {points_text(result.points)} of "
                                           f"{points_text(result.max_points)} points in {assignment}/{name}:\n"
                                           + "\n".join(result.verdict_lines()))
        return answers.merge_recording(lines)


@contextlib.contextmanager
def _environment(values: dict[str, str]):
    """Set these variables in os.environ (the check processes inherit them), then restore them."""
    previous = {name: os.environ.get(name) for name in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for name, value in previous.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value
