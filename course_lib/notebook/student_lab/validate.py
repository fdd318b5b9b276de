"""The Validate button's server side in a student's lab: a lesson gets a short answer at once, an
assignment goes to nbgrader.

Validate checks the graded cells of an assignment. A lesson has none, so nbgrader would run the
whole lesson and answer "Success! Your notebook passes all the tests." whatever the student
wrote. This server extension takes the place of nbgrader's ``validate_assignment`` extension
(``jupyter_server_config.json`` beside this file swaps them) and serves the same URLs with the
same handlers, except that Validate on a notebook without nbgrader cells answers with
:data:`LESSON_ANSWER` before a kernel starts: nothing runs, nothing is left running, and the
dialog shows four short lines instead of a traceback.
"""

from __future__ import annotations

import json
from pathlib import Path

from jupyter_server.utils import url_path_join
from nbgrader.server_extensions.validate_assignment import handlers as nbgrader_handlers

#: What Validate answers on a lesson; nbgrader's dialog shows it under "There was an error running
#: the validate command:". The fix comes first, and the lines are short (the dialog does not wrap them).
LESSON_ANSWER = ("Use this lesson's self-check cells instead of Validate:\n"
                 "each answers ✔ or ✘ and says what is wrong.\n"
                 "Validate checks an assignment's graded cells; a lesson has none.\n"
                 "Your assignments: Nbgrader > Assignment List.")


def is_assignment(notebook) -> bool:
    """True when some cell carries nbgrader metadata (a graded, solution, task or locked cell)."""
    for cell in notebook.get("cells", []):
        meta = cell.get("metadata", {}).get("nbgrader", {})
        if any(meta.get(key) for key in ("grade", "solution", "task", "locked")):
            return True
    return False


def is_lesson_file(path: Path) -> bool:
    """True for a notebook file without nbgrader cells; False for an assignment and for anything
    that is not a readable notebook (nbgrader then answers as it would)."""
    try:
        notebook = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(notebook, dict) and not is_assignment(notebook)


class ValidateHandler(nbgrader_handlers.ValidateAssignmentHandler):
    """nbgrader's POST /assignments/validate, answering a lesson without running it."""

    def validate_notebook(self, path):
        root = Path(self.root_dir).resolve()
        target = (root / path).resolve()
        if target.is_relative_to(root) and is_lesson_file(target):
            return {"success": False, "value": LESSON_ANSWER}
        return super().validate_notebook(path)  # also refuses a path outside the root (403)


def _jupyter_server_extension_points():
    return [{"module": "course_lib.notebook.student_lab.validate"}]


def _load_jupyter_server_extension(serverapp) -> None:
    """Serve nbgrader's validate URLs (the version check too) as its own extension would, with
    :class:`ValidateHandler` for Validate."""
    webapp = serverapp.web_app
    webapp.settings["root_dir"] = serverapp.root_dir
    handlers = [(pattern, ValidateHandler if handler is nbgrader_handlers.ValidateAssignmentHandler else handler)
                for pattern, handler in nbgrader_handlers.default_handlers]
    webapp.add_handlers(".*$", [(url_path_join(webapp.settings["base_url"], pattern), handler)
                                for pattern, handler in handlers])
    serverapp.log.info("course_lib: Validate answers lessons itself, nbgrader validates assignments")
