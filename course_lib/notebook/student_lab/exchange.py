"""nbgrader's exchange for a student who works alone (``make lab``): a folder inside the lab.

The lessons send students to *Nbgrader > Assignment List* for the assignments. On a hub the
instructor releases them into the hub's exchange (coursehub). A student alone has no instructor
and no ``/usr/local/share/nbgrader/exchange`` (nbgrader's default, whence "The exchange directory
does not exist"), so ``make lab`` releases the course's assignments into an exchange of the lab's
own, ``.lab/exchange`` under the lab's root (hidden from the file browser and from git), with the
course's grader (``python -m autograder release-lab``). The lab's ``nbgrader_config.py`` names that
exchange and the course id with :func:`use_local_exchange`; the panel then lists the assignments,
Fetch copies one to ``<root>/<assignment>/``, and Validate works on it. Submit keeps a copy in
the exchange, where no instructor collects it: ``python -m autograder grade-lab``
(autograder/term/lab_grading.py) grades the latest submission with the course's grader and releases its
feedback into this exchange, where Fetch Feedback finds it.
"""

from __future__ import annotations

from pathlib import Path

from course_lib.contract import COURSE_ID

#: The lab's own nbgrader folders, under its root: exchange/ and the course/ released from.
LAB_STATE = ".lab"


def local_exchange(lab_root) -> Path:
    """The exchange of the lab served from lab_root."""
    return Path(lab_root) / LAB_STATE / "exchange"


def local_course(lab_root) -> Path:
    """The nbgrader course folder (source/, release/, gradebook) the lab's assignments are released from."""
    return Path(lab_root) / LAB_STATE / "course"


def use_local_exchange(c, lab_root) -> None:
    """Point an nbgrader config object (``c = get_config()``) at the lab's exchange and the course."""
    c.CourseDirectory.course_id = COURSE_ID
    c.Exchange.root = str(local_exchange(lab_root))
