"""python -m coursehub create-course|start|release|collect|grade|feedback|remove-course: the course
on a JupyterHub (run as root on the server)."""

from __future__ import annotations

import argparse
import csv
import os
import pwd
import shutil
import sys
from pathlib import Path

from course_lib.contract import ROOT as REPO
from coursehub import accounts, closed_repository, exchange, instructor
from coursehub import course as course_settings


def create_course(roster_csv: Path, instructor_name: str, hub_dir: Path, group: str, exchange_root: Path,
                  port: int, hub_port: int, ip: str) -> course_settings.Course:
    """Accounts, exchange, settings and the instructor's nbgrader course from a roster; run again
    with a longer roster to add students (nobody is removed, no password changes)."""
    from autograder import config
    from autograder.term import release, roster

    students = [row["id"] for row in roster.read_roster(roster_csv)[0]]
    for name in [instructor_name, group, *students]:
        accounts.check_name(name)
    if instructor_name in students:
        raise ValueError(f"{instructor_name!r} is both the instructor and a student in {roster_csv}: remove the row")
    hub_dir.mkdir(parents=True, exist_ok=True)
    os.chmod(hub_dir, 0o711)  # students only traverse it to reach run/<user>/server.sock
    course = course_settings.Course(hub_dir=hub_dir, course_id=config.COURSE_ID, group=group,
                                    instructor=instructor_name, students=students, exchange=exchange_root,
                                    port=port, hub_port=hub_port, ip=ip)
    accounts.ensure_group(group)
    passwords = _read_passwords(course.passwords)
    for user in [instructor_name, *students]:
        if accounts.ensure_user(user, group) or user not in passwords:
            passwords[user] = accounts.set_password(user)
    _write_passwords(course.passwords, passwords)
    _close_repository(course)
    exchange.create_exchange(exchange_root)
    exchange.write_settings(course)
    for student in students:
        home = Path(pwd.getpwnam(student).pw_dir)
        exchange.write_student_settings(home, student)
        if not os.path.lexists(home / "notebooks"):  # the lessons, the student's own copy, made as the student
            accounts.as_user(student, lambda home=home: shutil.copytree(
                REPO / "notebooks", home / "notebooks", ignore=shutil.ignore_patterns(".ipynb_checkpoints",
                                                                                       "__pycache__")))
    course_dir = release.prepare_course(course.course_dir)
    roster.import_roster(course_dir, roster_csv)
    accounts.chown_tree(course_dir, instructor_name)
    os.chmod(course_dir, 0o700)  # the gradebook holds the hidden tests
    course.save()
    return course


def _read_passwords(path: Path) -> dict:
    if not path.is_file():
        return {}
    with open(path, newline="") as handle:
        return {row["user"]: row["password"] for row in csv.DictReader(handle)}


def _write_passwords(path: Path, passwords: dict) -> None:
    path.touch(mode=0o600)
    os.chmod(path, 0o600)
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["user", "password"])
        writer.writerows(sorted(passwords.items()))


def _close_repository(course) -> None:
    """What students must not read of this repository, closed to the course's accounts (an ssh login
    is one); a filesystem without ACLs leaves it open, and the admin is told."""
    for failure in closed_repository.close_to_students(course):
        print(f"python -m coursehub: students can read {failure}: put the repository on one that has "
              "them (ext4, xfs and btrfs do)", file=sys.stderr)


def remove_course(course) -> None:
    """Delete the course's accounts (and homes), its group, its exchange folder and the hub directory.

    Raises:
        ValueError: a course account still runs processes (the hub is running).
    """
    import psutil

    uids = {pwd.getpwnam(u).pw_uid for u in [course.instructor, *course.students] if accounts.exists(u)}
    running = [p.pid for p in psutil.process_iter(["uids"]) if p.info["uids"] and p.info["uids"].real in uids]
    if running:
        raise ValueError(f"the course's accounts still run {len(running)} processes (e.g. {running[:5]}): stop the hub "
                         "first (Ctrl-C where `make hub` runs), then remove the course")
    closed_repository.reopen_to_students(course)
    for user in [course.instructor, *course.students]:
        accounts.remove_user(user, course.group)
    accounts.remove_group(course.group)
    shutil.rmtree(course.exchange / course.course_id, ignore_errors=True)
    shutil.rmtree(course.hub_dir, ignore_errors=True)


def start(course) -> int:
    """Close the repository's folders to the course's accounts (again), then run the hub in the
    foreground, its files in course.private_dir (Ctrl-C stops it and every server)."""
    proxy = Path(sys.prefix) / "chp" / "node_modules" / ".bin" / "configurable-http-proxy"
    if not proxy.exists():
        raise FileNotFoundError(f"configurable-http-proxy is not installed at {proxy}: "
                                "run `make hub-deps` (or `make hub`)")
    env = dict(os.environ, **{course_settings.HUB_DIR_ENV: str(course.hub_dir)}, PYTHONPATH=str(REPO),
               PATH=os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", os.defpath)]))
    _close_repository(course)  # again: the repository may be a fresh clone since create-course
    course.private_dir.mkdir(mode=0o700, exist_ok=True)
    os.chmod(course.private_dir, 0o700)
    for earlier in course.hub_dir.glob("jupyterhub*"):  # where a hub before private/ kept them, readable
        os.replace(earlier, course.private_dir / earlier.name)
    os.chdir(course.private_dir)  # where JupyterHub writes what it is not told where to write
    config = Path(__file__).resolve().parent / "jupyterhub_config.py"
    os.execve(sys.executable, [sys.executable, "-m", "jupyterhub", "-f", str(config)], env)


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m coursehub", description=__doc__)
    parser.add_argument("--hub-dir", type=Path, default=course_settings.DEFAULT_HUB_DIR,
                        help=f"where the hub keeps the course (default {course_settings.DEFAULT_HUB_DIR})")
    sub = parser.add_subparsers(dest="command", required=True)
    cre = sub.add_parser("create-course",
                         help="Linux accounts, exchange and nbgrader course from a roster CSV (id column)")
    cre.add_argument("roster", type=Path)
    cre.add_argument("--instructor", required=True, help="the instructor's user name (created when missing)")
    cre.add_argument("--group", default="ros2cv", help="Linux group of the course's accounts (default ros2cv)")
    cre.add_argument("--exchange", type=Path, default=course_settings.DEFAULT_EXCHANGE)
    cre.add_argument("--port", type=int, default=8000, help="the hub's public port (default 8000)")
    cre.add_argument("--hub-port", type=int, default=8081)
    cre.add_argument("--ip", default="127.0.0.1", help="the hub's public address (default 127.0.0.1)")
    sub.add_parser("start", help="run the hub (foreground)")
    for step in ("release", "collect", "grade", "feedback"):
        one = sub.add_parser(step, help=instructor.__dict__[step].__doc__ or f"the instructor's {step} step")
        one.add_argument("assignment")
        if step == "release":
            one.add_argument("--duedate")
        if step == "grade":
            one.add_argument("--workers", type=int, default=2)
            one.add_argument("--student")
            one.add_argument("--force", action="store_true", help="grade again submissions that did not change")
    sub.add_parser("remove-course", help="delete the course's accounts, homes, exchange folder and hub directory")
    return parser


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    if os.geteuid() != 0:
        print(f"python -m coursehub {args.command}: run as root (it manages Linux accounts and starts "
              "servers as their users), e.g. sudo .venv/bin/python -m coursehub ...", file=sys.stderr)
        return 2
    try:
        if args.command == "create-course":
            course = create_course(args.roster, args.instructor, args.hub_dir.resolve(), args.group,
                                   args.exchange.resolve(), args.port, args.hub_port, args.ip)
            print(f"course {course.course_id}: {len(course.students)} students, instructor {course.instructor}; "
                  f"initial passwords in {course.passwords}; start the hub with `make hub`")
            return 0
        course = course_settings.load(args.hub_dir)
        if args.command == "start":
            return start(course)
        if args.command == "remove-course":
            remove_course(course)
            return 0
        step = getattr(instructor, args.command)
        extra = {"release": {"duedate": getattr(args, "duedate", None)},
                 "grade": {"workers": getattr(args, "workers", 2), "student": getattr(args, "student", None),
                           "force": getattr(args, "force", False)}}
        print(step(course, args.assignment, **extra.get(args.command, {})), end="")
        return 0
    except (ValueError, FileNotFoundError, RuntimeError) as error:
        print(f"python -m coursehub {args.command}: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
