"""Submit in a student's Assignments panel, refused with a clear message past the attempts the
hub's grading service grades before the due date (nbgrader's panel shows it in its "Invalid
Submission" dialog).

The student's server reads the rules the grading service publishes (``Course.submit_rules`` in the
hub's jupyter settings folder, readable by all: attempts and due date per assignment graded on
submission; the course's nbgrader_config.py itself is the instructor's) and counts the student's
own earlier submissions in nbgrader's cache of them (``~/.local/share/jupyter/nbgrader_cache``).
This only spares the student a submission that would not be graded: the service counts again from
the exchange and refuses what gets past (coursehub.grading_service). The message names the
service's page, where the student sees their submissions and scores.
"""

from __future__ import annotations

import glob
import json
import os
from pathlib import Path

from nbgrader.exchange.default.submit import ExchangeSubmit
from nbgrader.utils import parse_utc
from traitlets import Unicode

from coursehub.course import GRADING_PAGE, GRADING_SERVICE


def write_rules(path: Path, rules: dict) -> None:
    """Publish `rules` (assignment -> {"attempts": n or None, "duedate": "... UTC" or None})."""
    temporary = path.with_name(f".{path.name}.tmp")
    temporary.write_text(json.dumps(rules, indent=1, sort_keys=True))
    os.chmod(temporary, 0o644)
    os.replace(temporary, path)


class LimitedSubmit(ExchangeSubmit):
    rules_file = Unicode("", help="The grading service's published rules (coursehub.course.Course.submit_rules)"
                         ).tag(config=True)

    def init_dest(self):
        super().init_dest()
        self.check_attempts()

    def check_attempts(self) -> None:
        """Fail (nbgrader's ExchangeError) when this submission is past the assignment's attempts."""
        try:
            rule = json.loads(Path(self.rules_file).read_text()).get(self.coursedir.assignment_id)
        except (OSError, ValueError):
            return  # no grading service: nbgrader's own submit
        if not rule or rule.get("attempts") is None:
            return
        due = parse_utc(rule["duedate"]) if rule.get("duedate") else None
        if due is not None and parse_utc(self.timestamp) > due:
            return  # late: graded, the late penalty applies
        student, assignment = self.assignment_filename.split("+")[:2]
        earlier = [path for path in glob.glob(os.path.join(glob.escape(self.cache_path), f"{student}+{assignment}+*"))
                   if due is None or parse_utc(os.path.basename(path).split("+")[2]) <= due]
        if len(earlier) >= rule["attempts"]:
            before = f"before the due date ({due:%Y-%m-%d %H:%M} UTC)" if due else "before the due date"
            page = f"{os.environ.get('JUPYTERHUB_BASE_URL', '/')}{GRADING_PAGE}"
            self.fail(f"{assignment} allows {rule['attempts']} graded submissions {before}, and you have made "
                      f"{len(earlier)}: this one would not be graded. Your last graded submission stands; your "
                      f"instructor grades it again after the due date.\nYour submissions and their scores: {page} on "
                      f"the hub (its home page: Services > {GRADING_SERVICE}).")
