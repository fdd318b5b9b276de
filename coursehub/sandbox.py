"""A command as a course user, in namespaces of its own: the grader's sandbox
(``autograder.sandbox.namespaces.sandbox_command``) and then ``setpriv`` to the user's uid, groups and home.

The spawner starts every server so; the instructor's commands (``coursehub.instructor``) run so
too, because the course's interpreter may sit below /root, which only the sandbox makes
reachable for another uid.
"""

from __future__ import annotations

import os
import pwd
import sys
from pathlib import Path

from course_lib import contract

REPO = contract.ROOT


def as_user(course, user: str, command: list[str]) -> list[str]:
    """`command` wrapped so that it runs as `user` in a network, mount and /dev/shm namespace; a
    student's also has the repository's instructor folders hidden (namespaces.HIDDEN_FROM_STUDENTS)."""
    from autograder.sandbox import namespaces

    account = pwd.getpwnam(user)
    hide = [] if user == course.instructor else namespaces.HIDDEN_FROM_STUDENTS
    drop = ["setpriv", f"--reuid={account.pw_uid}", f"--regid={account.pw_gid}", "--init-groups", "--"]
    return namespaces.sandbox_command(drop + command, hide)


def user_environment(course, user: str, base: dict) -> dict:
    """`base` completed for a course user's process: home, the course's Python and nbgrader settings."""
    from autograder.sandbox import namespaces
    from course_lib.notebook import student_lab

    account = pwd.getpwnam(user)
    env = dict(base)
    bindir = str(Path(sys.executable).parent)
    env.update(
        USER=user, HOME=account.pw_dir, SHELL=account.pw_shell or "/bin/bash",
        # A student's lab shows nbgrader's student side only, as in `make lab` (course_lib/notebook/student_lab).
        JUPYTER_CONFIG_PATH=os.pathsep.join(
            ([] if user == course.instructor else [str(student_lab.CONFIG_DIR)]) + [str(course.jupyter_config_dir)]),
        PYTHONPATH=str(REPO),
        VIRTUAL_ENV=str(Path(sys.executable).parent.parent),
        PATH=os.pathsep.join([bindir] + [p for p in env.get("PATH", os.defpath).split(os.pathsep) if p != bindir]),
    )
    exposure = namespaces.interpreter_exposure()
    if exposure:  # the interpreter lives below /root: the sandbox puts it back for the user
        (course.run_dir / "stage").mkdir(mode=0o700, parents=True, exist_ok=True)
        env.update(exposure, **{contract.STAGE_ENV: str(course.run_dir / "stage")})
    return env
