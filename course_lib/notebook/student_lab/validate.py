"""The Validate button's server side in a student's lab: a lesson gets a short answer at once, an
assignment goes to nbgrader.

Validate checks the graded cells of an assignment. A lesson has none, so nbgrader would run the
whole lesson and answer "Success! Your notebook passes all the tests." whatever the student
wrote. This server extension takes the place of nbgrader's ``validate_assignment`` extension
(``jupyter_server_config.json`` beside this file swaps them) and serves the same URLs with the
same handlers, except that Validate on a notebook without nbgrader cells answers with
:data:`LESSON_ANSWER` before a kernel starts: nothing runs, nothing is left running, and the
dialog shows a heading and four short lines instead of a traceback. An assignment is validated in a thread, so
that the server answers meanwhile, among others the lab extension that asks which cell runs
(:mod:`course_lib.notebook.student_lab.validate_progress`).
"""

from __future__ import annotations

import json
import threading
from pathlib import Path

from jupyter_server.utils import url_path_join
from nbgrader.server_extensions.validate_assignment import handlers as nbgrader_handlers
from tornado import web
from tornado.ioloop import IOLoop

from course_lib.notebook.student_lab.validate_progress import PROGRESS, PROGRESS_URL, ProgressHandler

#: The heading of Validate's answer on a lesson, its first line. nbgrader's dialog shows an answer
#: that is no validation under "There was an error running the validate command:"; for a notebook
#: without nbgrader cells the lab extension labextensions/@course-lib/validate-lesson shows this
#: line as the heading instead, in nbgrader's dialog of a success: the lesson did nothing wrong.
LESSON_HEADING = "This is a lesson: Validate has nothing to grade here."
#: What Validate answers on a lesson: the heading, then the fix, in short lines (the dialog does
#: not wrap them).
LESSON_ANSWER = (f"{LESSON_HEADING}\n"
                 "Use this lesson's self-check cells instead of Validate:\n"
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


def read_notebook(path: Path) -> dict | None:
    """The notebook's JSON, or None when path is no readable notebook."""
    try:
        notebook = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return notebook if isinstance(notebook, dict) else None


def is_lesson_file(path: Path) -> bool:
    """True for a notebook file without nbgrader cells; False for an assignment and for anything
    that is not a readable notebook (nbgrader then answers as it would)."""
    notebook = read_notebook(path)
    return notebook is not None and not is_assignment(notebook)


#: nbgrader's Validator changes the process's working folder while it runs a notebook, so the
#: threads validate one notebook at a time.
_ONE_AT_A_TIME = threading.Lock()


class ValidateHandler(nbgrader_handlers.ValidateAssignmentHandler):
    """nbgrader's POST /assignments/validate, answering a lesson without running it, and running
    an assignment in a thread while recording which cell runs."""

    _path = ""

    @web.authenticated
    async def post(self):
        try:
            path = self.get_argument("path")
        except web.MissingArgumentError:
            path = self.get_json_body()["path"]
        output = await IOLoop.current().run_in_executor(None, self.validate_notebook, path)
        self.finish(json.dumps(output))

    def validate_notebook(self, path):
        root = Path(self.root_dir).resolve()
        target = (root / path).resolve()
        if target.is_relative_to(root) and is_lesson_file(target):
            return {"success": False, "value": LESSON_ANSWER}
        with _ONE_AT_A_TIME:
            self._path = path
            PROGRESS.start(path, read_notebook(target) or {})
            try:
                return super().validate_notebook(path)  # also refuses a path outside the root (403)
            finally:
                PROGRESS.finish(path)

    def load_config(self):
        """nbgrader's configuration, with the hook that counts the cells the validation runs."""
        config = super().load_config()
        config.Execute.on_cell_execute = PROGRESS.hook(self._path)
        return config


def _jupyter_server_extension_points():
    return [{"module": "course_lib.notebook.student_lab.validate"}]


def _load_jupyter_server_extension(serverapp) -> None:
    """Serve nbgrader's validate URLs (the version check too) as its own extension would, with
    :class:`ValidateHandler` for Validate, and the progress of a validation."""
    webapp = serverapp.web_app
    webapp.settings["root_dir"] = serverapp.root_dir
    handlers = [(pattern, ValidateHandler if handler is nbgrader_handlers.ValidateAssignmentHandler else handler)
                for pattern, handler in nbgrader_handlers.default_handlers]
    handlers.append((PROGRESS_URL, ProgressHandler))
    webapp.add_handlers(".*$", [(url_path_join(webapp.settings["base_url"], pattern), handler)
                                for pattern, handler in handlers])
    serverapp.log.info("course_lib: Validate answers lessons itself, nbgrader validates assignments")
