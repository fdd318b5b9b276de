"""JupyterLab's setting for a student's lab that a JSON file cannot hold: where the lab extension of
Validate's progress is (``labextensions/`` beside this file; course_lib.notebook.student_lab.validate_progress).

Jupyter reads this file as configuration, with ``get_config``, from the folder on
``JUPYTER_CONFIG_PATH`` (beside ``jupyter_server_config.json``); it is not imported.
"""

from pathlib import Path

c = get_config()  # noqa: F821 (Jupyter's configuration loader defines it)
c.LabApp.extra_labextensions_path = [str(Path(__file__).resolve().parent / "labextensions")]
