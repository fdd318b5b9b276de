"""nbgrader's exchange on this server, and the nbgrader/JupyterLab settings of each user.

The exchange root is writable by everyone (``chmod ugo+rw``, nbgrader's documented set-up); nbgrader
itself gives ``<course>/outbound`` (released assignments, readable by all), ``inbound`` (write and
enter only: a student can submit but not list or read other submissions) and ``feedback`` (files
named by a hash of the student's own submission) their permissions when the instructor releases.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from coursehub.accounts import as_user


def create_exchange(root: Path) -> None:
    root.mkdir(parents=True, exist_ok=True)
    os.chmod(root, 0o777)  # ugo+rw (and x) as nbgrader's guide sets it; not sticky: nbgrader's own modes rule


def write_settings(course) -> Path:
    """``<hub dir>/jupyter/nbgrader_config.py``, read by every server of the hub (JUPYTER_CONFIG_PATH)
    and by the instructor's commands: the course id, the exchange, the Submit that refuses what the
    grading service would not grade (coursehub.limited_submit), the course's cell timeouts."""
    folder = course.jupyter_config_dir
    folder.mkdir(parents=True, exist_ok=True)
    os.chmod(folder, 0o755)
    path = folder / "nbgrader_config.py"
    path.write_text(
        "# Written by `python -m coursehub create-course`: every server of the hub reads it.\n"
        "from course_lib.checks.validate import apply_student\n\n"
        "c = get_config()  # noqa: F821 (provided by nbgrader)\n"
        f"c.CourseDirectory.course_id = {course.course_id!r}\n"
        f"c.Exchange.root = {str(course.exchange)!r}\n"
        "# Submit refused past the attempts the hub's grading service grades (coursehub.limited_submit).\n"
        "c.ExchangeFactory.submit = 'coursehub.limited_submit.LimitedSubmit'\n"
        "# Collect takes a submission only from its owner, and follows no link (coursehub.checked_collect).\n"
        "c.ExchangeFactory.collect = 'coursehub.checked_collect.CheckedCollect'\n"
        f"c.LimitedSubmit.rules_file = {str(course.submit_rules)!r}\n"
        "apply_student(c)\n")
    os.chmod(path, 0o644)
    return path


def write_student_settings(home: Path, user: str) -> None:
    """A student's ~/.jupyter: no prompt about Jupyter's news (the server's namespace has no network
    to fetch them). The instructor's nbgrader extensions are off through course_lib/notebook/student_lab on
    the student's JUPYTER_CONFIG_PATH (coursehub.sandbox.user_environment), as in `make lab`.
    Written as the student (coursehub.accounts.as_user): the home is theirs, links and all."""

    def write() -> None:
        notification = home / ".jupyter" / "lab" / "user-settings" / "@jupyterlab" / "apputils-extension"
        notification.mkdir(parents=True, exist_ok=True)
        (notification / "notification.jupyterlab-settings").write_text(
            json.dumps({"fetchNews": "false", "checkForUpdates": False}, indent=2))

    as_user(user, write)
