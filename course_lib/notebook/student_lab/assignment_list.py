"""The Assignments panel's server side in a student's lab: nbgrader's, except for what a refused
Submit shows.

When nbgrader's submit refuses (an ``ExchangeError``: past the attempts the hub's grading service
grades, a notebook missing from the release, ...), nbgrader's panel opens its "Invalid Submission"
dialog on the whole Python traceback, with the reason on its last line. This server extension
takes the place of nbgrader's ``assignment_list`` extension (``jupyter_server_config.json`` beside
this file swaps them): the same URLs and handlers, but a refusal answers with its reason alone, in
lines the dialog shows without scrolling sideways. Any other error keeps nbgrader's traceback (it
is a fault to report, not a reason for the student), and every error stays in the server's log.
"""

from __future__ import annotations

import textwrap

from nbgrader.exchange import ExchangeError
from nbgrader.server_extensions.assignment_list import handlers as nbgrader_handlers

#: The widest line of a refusal: the dialog shows it in a <pre>, which does not wrap.
LINE_WIDTH = 64

#: How a traceback names nbgrader's refusal on its last line.
_REFUSED = f"\n{ExchangeError.__module__}.{ExchangeError.__qualname__}: "


def refusal(traceback_text: str) -> str | None:
    """The reason of nbgrader's refusal at the end of `traceback_text`, wrapped to LINE_WIDTH; None
    when the traceback ends in another error."""
    start = traceback_text.rfind(_REFUSED)
    if start < 0:
        return None
    reason = traceback_text[start + len(_REFUSED):].strip()
    if "Traceback (most recent call last):" in reason:  # another error came after the refusal
        return None
    return "\n".join(textwrap.fill(line, LINE_WIDTH) for line in reason.splitlines())


class AssignmentList(nbgrader_handlers.AssignmentList):
    """nbgrader's list, fetch and submit; a refused Submit says only why."""

    def submit_assignment(self, course_id, assignment_id):
        answer = super().submit_assignment(course_id, assignment_id)
        if not answer["success"]:  # nbgrader has logged the traceback
            answer["value"] = refusal(answer["value"]) or answer["value"]
        return answer


def _jupyter_server_extension_points():
    return [{"module": "course_lib.notebook.student_lab.assignment_list"}]


def _load_jupyter_server_extension(serverapp) -> None:
    """nbgrader's extension, then :class:`AssignmentList` as the manager its handlers call."""
    nbgrader_handlers.load_jupyter_server_extension(serverapp)
    manager = AssignmentList(parent=serverapp)
    manager.root_dir = serverapp.root_dir
    serverapp.web_app.settings["assignment_list_manager"] = manager
    serverapp.log.info("course_lib: a refused Submit shows its reason without the traceback")
