"""What a student's JupyterLab shows: nbgrader's student side only, and a Validate that is honest
about lessons.

``make lab`` puts this folder on ``JUPYTER_CONFIG_PATH`` (a JupyterHub for students can do the
same). Two configuration files in it switch off nbgrader's instructor side, which a student
never uses:

- ``labconfig/page_config.json``: JupyterLab leaves out the "Create Assignment" sidebar, the
  formgrader and the course list (the Nbgrader menu keeps "Assignment List", and notebooks keep
  the Validate button that assignments need);
- ``jupyter_server_config.json``: the server does not load the formgrader and course-list
  extensions behind them.

The same with nbgrader's own commands, for a whole installation::

    jupyter labextension disable --level=sys_prefix @jupyter/nbgrader:create-assignment
    jupyter server extension disable --sys-prefix nbgrader.server_extensions.formgrader

Validate checks the graded cells of an assignment. A lesson has none, so nbgrader would answer
"Success! Your notebook passes all the tests." whatever the student wrote. The lab's
``nbgrader_config.py`` therefore sets :func:`refuse_lessons` as the executor's start hook: on a
notebook without nbgrader cells Validate stops with :class:`NotAnAssignment`, whose message points
at the lesson's self-check cells.
"""

from __future__ import annotations

from pathlib import Path

#: The folder to put on JUPYTER_CONFIG_PATH for a student's lab.
CONFIG_DIR = Path(__file__).resolve().parent


class NotAnAssignment(Exception):
    """Validate was pressed on a notebook without graded cells (a lesson)."""


def is_assignment(notebook) -> bool:
    """True when some cell carries nbgrader metadata (a graded, solution, task or locked cell)."""
    for cell in notebook.get("cells", []):
        meta = cell.get("metadata", {}).get("nbgrader", {})
        if any(meta.get(key) for key in ("grade", "solution", "task", "locked")):
            return True
    return False


def refuse_lessons(notebook, **_) -> None:
    """nbclient's on_notebook_start hook: stop Validate on a lesson with a message that helps.

    Raises:
        NotAnAssignment: the notebook has no nbgrader cells.
    """
    if not is_assignment(notebook):
        raise NotAnAssignment(
            "This notebook is a lesson, not an assignment: it has no graded cells, so Validate has nothing "
            "to check (nbgrader would say 'Success' whatever your answers are). Run each task's self-check "
            "cell instead: it answers ✔ or ✘ and says what is wrong. Validate is for the assignments you "
            "fetch from Nbgrader > Assignment List.")
