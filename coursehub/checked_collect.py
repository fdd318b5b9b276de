"""``nbgrader collect`` on the hub (the instructor's command and the formgrader's Collect button):
nbgrader's own, but it takes a submission only from the student who owns its folder and copies it
without following anything out of it, as the grading service does (coursehub.inbound).

nbgrader's collect trusts a folder's name (it only warns when the owner differs) and copies with
shutil.copytree, which follows links: run as the instructor, a student's link to the instructor's
source notebook would be collected as the student's work. Here the submissions that would be
refused are left out before nbgrader chooses each student's newest one, so a refused folder
neither replaces nor removes what was collected before; each is logged with its reason.
"""

from __future__ import annotations

import glob
import os
import pwd
from pathlib import Path

from nbgrader.exchange.default.collect import ExchangeCollect

# autograder (and coursehub.inbound, which uses it) is imported where collecting needs it: every
# server of the hub loads this class with nbgrader's settings, and a student's hides autograder/.


class CheckedCollect(ExchangeCollect):
    def init_src(self):
        """nbgrader's look at inbound/ (its checks, the due date), with the refused folders left out
        before each student's submission is chosen (nbgrader's own fails the whole collect on one
        folder whose name it cannot read)."""
        from nbgrader.api import Gradebook, MissingEntry

        if self.coursedir.course_id == "":
            self.fail("No course id specified. Re-run with --course flag.")
        self.course_path = os.path.join(self.root, self.coursedir.course_id)
        self.inbound_path = os.path.join(self.course_path, "inbound")
        if not os.path.isdir(self.inbound_path):
            self.fail(f"Course not found: {self.inbound_path}")
        with Gradebook(self.coursedir.db_url, self.coursedir.course_id) as gb:
            try:
                self.duedate = gb.find_assignment(self.coursedir.assignment_id).duedate
            except MissingEntry:
                self.duedate = None
        chosen = self.coursedir.student_id  # nbgrader's default is "*": every student
        student = glob.escape(chosen) if chosen and chosen != "*" else "*"
        assignment = glob.escape(self.coursedir.assignment_id)
        pattern = os.path.join(glob.escape(self.inbound_path), f"{student}+{assignment}+*")
        by_student: dict[str, list[dict]] = {}
        for path in glob.glob(pattern):
            refusal = self.refusal(Path(path))
            if refusal:
                self.log.error("Not collected: %s", refusal)
                continue
            record = self._path_to_record(path)
            by_student.setdefault(record["username"], []).append(record)
        self.src_records = [self.newest(records) for records in by_student.values()]

    def newest(self, records: list[dict]) -> dict:
        """nbgrader's choice among a student's submissions: the newest, or with --before-duedate
        the newest before the due date when there is one."""
        ordered = self._sort_by_timestamp(records)
        if self.duedate is not None and self.before_duedate:
            before = [r for r in ordered if r["timestamp"] <= self.duedate]
            return (before or ordered)[0]
        return ordered[0]

    def refusal(self, path: Path) -> str | None:
        """Why the submission folder `path` is not collected, or None."""
        from autograder.sandbox import untrusted
        from coursehub import inbound

        parsed = inbound.parse_name(path.name)
        if parsed is None:
            return f"{untrusted.shown(path.name)} is not named as nbgrader's submit names a submission"
        try:
            uid = pwd.getpwnam(parsed[0]).pw_uid
        except KeyError:
            return f"{untrusted.shown(path.name)} names {untrusted.shown(parsed[0])}, who has no account here"
        try:
            if os.lstat(path).st_uid != uid:
                return f"{untrusted.shown(path.name)} names {parsed[0]} but was made by another account"
            untrusted.copy_tree(path, None, owner=uid, ignore=self.coursedir.ignore)
        except (OSError, untrusted.Refused) as error:
            return f"{untrusted.shown(path.name)}: {error}"
        return None

    def do_copy(self, src, dest, log=None):
        """Copy a submission (checked in init_src) without following anything out of it."""
        from autograder.sandbox import untrusted
        from coursehub import inbound

        try:
            untrusted.copy_tree(src, dest, owner=pwd.getpwnam(inbound.parse_name(Path(src).name)[0]).pw_uid,
                                ignore=self.coursedir.ignore)
        except untrusted.Refused as refusal:  # changed since it was checked
            self.log.error("Not collected: %s: %s", untrusted.shown(Path(src).name), refusal)
