"""Due dates and late penalties, with nbgrader's own mechanisms.

- The due date of an assignment is the gradebook's (``Assignment.duedate``): set it with
  ``python -m autograder release COURSE_DIR --assignment A --duedate "2025-03-14 23:59 Europe/Berlin"``
  (:func:`set_duedate`), with ``nbgrader db assignment add A --duedate=...`` or in the
  formgrader's "Manage Assignments" page. A submission's time is its ``timestamp.txt`` (written by
  ``nbgrader zip_collect``), which the grader copies into the gradebook.
- The penalty is computed by nbgrader's AssignLatePenalties preprocessor with the plugin the
  course's nbgrader_config.py names: :class:`LatePenalty`, a fraction of the score per started
  day late, set per assignment::

      c.LatePenalty.per_day = {"pubsub": 0.1}    # 10 % of the score per started day late
      c.LatePenalty.maximum = 0.5                # never more than half of it

  Assignments it does not name fall back to nbgrader's ``LateSubmissionPlugin.penalty_method``
  ("none" by default, or "zero").
"""

from __future__ import annotations

import math

from nbgrader.plugins import LateSubmissionPlugin
from traitlets import Dict, Float

from course_lib.checks.result import round_points

DAY = 24 * 3600.0


class LatePenalty(LateSubmissionPlugin):
    """A late penalty per assignment: ``per_day[assignment]`` × started days late × score, at most
    ``maximum`` × score."""

    per_day = Dict(value_trait=Float(min=0.0), default_value={},
                   help="Assignment -> fraction of the score lost per started day late (0.1: 10 %)").tag(config=True)
    maximum = Float(1.0, min=0.0, max=1.0,
                    help="The largest fraction of the score a late penalty takes").tag(config=True)

    def late_submission_penalty(self, student_id: str, score: float, total_seconds_late: float):
        # nbgrader's AssignLatePenalties creates the plugin with itself as parent, the assignment set.
        assignment = getattr(self.parent, "assignment_id", None)
        if assignment not in self.per_day:
            return super().late_submission_penalty(student_id, score, total_seconds_late)
        return round_points(score * fraction(self.per_day[assignment], self.maximum, total_seconds_late))


def fraction(per_day: float, maximum: float, seconds_late: float) -> float:
    """The fraction of the score lost: per_day per started day late, at most maximum."""
    if seconds_late <= 0:
        return 0.0
    return min(maximum, per_day * math.ceil(seconds_late / DAY))


def check_settings(config, assignments: list[str]) -> None:
    """Raise ValueError naming the fix when c.LatePenalty.per_day names no assignment of the course
    (a typo would silently give no penalty)."""
    per_day = dict(config.LatePenalty.get("per_day", {})) if "LatePenalty" in config else {}
    unknown = sorted(set(per_day) - set(assignments))
    if unknown:
        raise ValueError(f"c.LatePenalty.per_day in the course's nbgrader_config.py names {', '.join(unknown)}, which "
                         f"is no assignment of the course ({', '.join(assignments)}): correct the name.")


def set_duedate(course_dir, assignment: str, when: str) -> str:
    """Record an assignment's due date in the gradebook; return it as nbgrader stores it (UTC).

    Args:
        when: a date and time with its time zone, e.g. "2025-03-14 23:59 Europe/Berlin" or
            "2025-03-14T23:59:00+01:00" (without one, UTC).

    Raises:
        ValueError: `when` is not a date (the message shows the form to use).
    """
    from nbgrader.utils import parse_utc

    from autograder.results import gradebook

    try:
        utc = parse_utc(when)
    except (ValueError, OverflowError) as error:
        raise ValueError(f"--duedate {when!r} is not a date and time ({error}); give it like "
                         "\"2025-03-14 23:59 Europe/Berlin\" or \"2025-03-14T23:59:00+01:00\"") from None
    with gradebook.open_gradebook(course_dir) as gb:
        gb.update_or_create_assignment(assignment, duedate=utc)
    return f"{utc:%Y-%m-%d %H:%M:%S} UTC"
