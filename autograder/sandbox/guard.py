"""nbgrader's own autograde refuses to grade the course's assignments; the course's grader does it.

Plain ``nbgrader autograde`` (and the formgrader's Autograde button, which runs the same code in
the server) would run the notebook's hidden test cells in the student's kernel: the checks would
run outside the sandbox, in a process the student's code can patch, and their scores would
silently replace the sandboxed ones in the gradebook and autograded/. The course's
nbgrader_config.py makes :class:`GraderOnlyExporter` the exporter of nbgrader's Autograde
converter. nbgrader creates the exporter before it touches anything (before it removes an
earlier autograded/ folder or a gradebook entry), so refusing there loses nothing.

The course's grader runs ``nbgrader autograde`` itself, in a private course root inside its
sandbox, with AUTOGRADER_CHECKS_OUTSIDE=1 (the hidden cells only say that the grader runs their
checks afterwards): there the exporter is nbconvert's NotebookExporter, unchanged.
"""

from __future__ import annotations

import os

from nbconvert.exporters import NotebookExporter

from course_lib import contract


def grade_command(course: str, assignment: str, student: str) -> str:
    """The command that grades a submission with the course's grader ('*' or '': every one)."""
    command = f"python -m autograder grade {course}"
    if student and student != "*":
        command += f" --student {student}"
    if assignment and assignment != "*":
        command += f" --assignment {assignment}"
    return command


class GraderOnlyExporter(NotebookExporter):
    """nbconvert's NotebookExporter under the course's grader; anywhere else, a refusal that names
    the command to use (logged by nbgrader and shown by the formgrader)."""

    def __init__(self, *args, **kwargs):
        if os.environ.get(contract.CHECKS_OUTSIDE_ENV) != "1":
            from nbgrader.converters.base import NbGraderException

            parent = kwargs.get("parent")
            coursedir = getattr(parent, "coursedir", None)
            command = grade_command(getattr(coursedir, "root", "COURSE_DIR"),
                                    getattr(coursedir, "assignment_id", ""), getattr(coursedir, "student_id", ""))
            message = ("This course's notebooks are graded by the course's grader, not by nbgrader autograde: "
                       "nbgrader would run the hidden checks in the student's kernel, outside the sandbox, and "
                       f"replace the sandboxed grades. Nothing was changed. Run instead: {command}")
            if parent is not None:
                parent.log.error(message)
            raise NbGraderException(message)
        super().__init__(*args, **kwargs)
