"""What a student's JupyterLab shows: nbgrader's student side only, and a Validate that is honest
about lessons and says which cell it runs.

``make lab`` puts this folder on ``JUPYTER_CONFIG_PATH`` (a JupyterHub for students can do the
same). The configuration files in it switch off nbgrader's instructor side, which a student
never uses, and say what Validate does:

- ``labconfig/page_config.json``: JupyterLab leaves out the "Create Assignment" sidebar, the
  formgrader and the course list (the Nbgrader menu keeps "Assignment List", and notebooks keep
  the Validate button that assignments need);
- ``jupyter_server_config.json``: the server does not load the formgrader and course-list
  extensions behind them, and serves Validate with :mod:`course_lib.notebook.student_lab.validate` in
  place of nbgrader's extension (a lesson gets a short answer pointing at its self-check cells,
  without a kernel; an assignment is validated by nbgrader, in a thread), and the Assignments panel
  with :mod:`course_lib.notebook.student_lab.assignment_list` (a refused Submit shows its reason, not a
  traceback);
- ``jupyter_server_config.py``: JupyterLab also loads the lab extensions in ``labextensions/``:
  one shows on the Validate button which cell the validation runs and what a long one does
  (``validate_progress``), one shows a lesson's answer under its own heading, not nbgrader's error
  heading (``validate.LESSON_HEADING``).

The same with nbgrader's own commands, for a whole installation::

    jupyter labextension disable --level=sys_prefix @jupyter/nbgrader:create-assignment
    jupyter server extension disable --sys-prefix nbgrader.server_extensions.formgrader
"""

from __future__ import annotations

from pathlib import Path

#: The folder to put on JUPYTER_CONFIG_PATH for a student's lab.
CONFIG_DIR = Path(__file__).resolve().parent
