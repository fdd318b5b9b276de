"""Linux accounts of a course: one group, one account per student and the instructor's.

The hub's authenticator is PAM, so these accounts and their passwords are the class's logins; the
servers run as these uids, and the nbgrader exchange relies on their Unix permissions. An account
that exists but is not in the course's group is never adopted or removed (a roster naming
``root`` or a staff account stops with an error instead).
"""

from __future__ import annotations

import contextlib
import grp
import os
import pwd
import re
import secrets
import subprocess

USER_NAME = re.compile(r"^[a-z_][a-z0-9_-]{0,31}$")


def check_name(name: str) -> str:
    if not USER_NAME.match(name):
        raise ValueError(f"{name!r} cannot be a Linux user name: use at most 32 lower-case letters, digits, "
                         "'-' and '_', starting with a letter (prefix the roster's ids if they start with a digit)")
    return name


def in_group(user: str, group: str) -> bool:
    try:
        return user in grp.getgrnam(group).gr_mem
    except KeyError:
        return False


def exists(user: str) -> bool:
    try:
        pwd.getpwnam(user)
        return True
    except KeyError:
        return False


def ensure_group(group: str) -> None:
    check_name(group)
    try:
        grp.getgrnam(group)
    except KeyError:
        subprocess.run(["groupadd", group], check=True)


def ensure_user(user: str, group: str) -> bool:
    """Create the account (home 0700, bash, member of `group`) unless it is already the course's.

    Returns:
        True when the account was created (it then needs a password).

    Raises:
        ValueError: the account exists outside the course's group.
    """
    check_name(user)
    if exists(user):
        if not in_group(user, group):
            raise ValueError(f"the account {user!r} exists and is not in the course's group {group!r}: "
                             "rename the student in the roster (e.g. with the course's prefix), or add the "
                             f"account to the group by hand (usermod -aG {group} {user}) if it is theirs")
        return False
    subprocess.run(["useradd", "--create-home", "--shell", "/bin/bash", "--user-group",
                    "--groups", group, user], check=True)
    os.chmod(pwd.getpwnam(user).pw_dir, 0o700)  # classmates cannot read each other's home
    return True


def set_password(user: str) -> str:
    """Give the account a new random password and return it."""
    password = secrets.token_urlsafe(9)
    subprocess.run(["chpasswd"], input=f"{user}:{password}\n", text=True, check=True)
    return password


def remove_user(user: str, group: str) -> None:
    """Delete a course account and its home (only a member of the course's group)."""
    if exists(user) and in_group(user, group):
        subprocess.run(["userdel", "--remove", user], check=True, capture_output=True)


def remove_group(group: str) -> None:
    try:
        grp.getgrnam(group)
    except KeyError:
        return
    subprocess.run(["groupdel", group], check=True)


def chown_tree(path, user: str) -> None:
    """Give a folder and everything in it to `user` (and their primary group). What is removed
    while it walks is left out: the grading service's other workers write the gradebook meanwhile,
    and SQLite's journal beside it comes and goes."""
    entry = pwd.getpwnam(user)
    for directory, dirs, files in os.walk(path):
        with contextlib.suppress(FileNotFoundError):  # a folder swapped for a link meanwhile: the link's
            os.chown(directory, entry.pw_uid, entry.pw_gid, follow_symlinks=False)
        for name in files + dirs:
            with contextlib.suppress(FileNotFoundError):
                os.chown(os.path.join(directory, name), entry.pw_uid, entry.pw_gid, follow_symlinks=False)


def as_user(user: str, work) -> None:
    """Call `work()` in a child process that runs as `user` (their uid and group, no other groups):
    root writing into a folder the user controls, such as their home, would follow their links.

    Raises:
        RuntimeError: `work` raised in the child (its traceback was printed there).
    """
    entry = pwd.getpwnam(user)
    pid = os.fork()
    if pid == 0:  # the child: never returns
        code = 1
        try:
            os.setgroups([])
            os.setgid(entry.pw_gid)
            os.setuid(entry.pw_uid)
            os.environ["HOME"] = entry.pw_dir
            work()
            code = 0
        except BaseException:  # noqa: BLE001 - reported through the exit code
            import traceback

            traceback.print_exc()
        finally:
            os._exit(code)
    code = os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1])
    if code != 0:
        raise RuntimeError(f"writing in {user}'s home as {user} failed (exit status {code})")
