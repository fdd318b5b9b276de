"""nbgrader configuration of the course, written once here.

``write_config(course_dir)`` puts an ``nbgrader_config.py`` in a course directory that loads
:func:`apply`, so that both the nbgrader CLI (run by hand in that directory, and the formgrader
started there) and the autograder use the same settings; the instructor's own settings (late
penalties, the LMS's file names) go below its marker line and are kept. Layout: nbgrader's own
(``source/ release/ submitted/ autograded/ feedback/``), gradebook ``gradebook.db`` (SQLite) and
the LMS export ``grades.csv`` in the course root.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from traitlets import Dict, Int
from traitlets.config import Configurable

from course_lib.checks.validate import apply_student
from course_lib.contract import COURSE_ID

#: The stub ClearSolutions puts in place of a solution, at the solution's indentation.
CODE_STUB = "# YOUR CODE HERE\nraise NotImplementedError(\"replace this line with your code\")"


def apply(c, root: str | Path | None = None) -> None:
    """Fill an nbgrader config object (``c = get_config()``) with the course's settings."""
    c.CourseDirectory.course_id = COURSE_ID
    if root is not None:
        c.CourseDirectory.root = str(root)
    c.CourseDirectory.db_url = f"sqlite:///{Path(root).resolve() / 'gradebook.db'}" if root else ""
    c.ClearSolutions.code_stub = {"python": CODE_STUB}
    apply_student(c)
    # A student who deleted a test cell gets it back (and its points are graded), not a crash.
    c.OverwriteCells.add_missing_cells = True
    # Students' notebooks may print a lot; the feedback keeps the start of each output.
    c.LimitOutput.max_lines = 400
    # nbgrader's own autograde (CLI, formgrader button) would run the hidden checks in the
    # student's kernel, outside the sandbox: it refuses and names the course's grader.
    c.Autograde.exporter_class = "autograder.sandbox.guard.GraderOnlyExporter"
    # The notebook's run stops an ordinary cell by its processor time, or once it idles, instead of
    # at its wall-clock timeout, which grows with the load (autograder.sandbox.cell_watch).
    c.Autograde.autograde_preprocessors = watched_preprocessors()
    # `nbgrader export` and `python -m autograder export` write one file, in one format.
    c.ExportApp.plugin_class = "autograder.term.export.CourseCsvExport"
    if root is not None:
        c.ExportPlugin.to = str(Path(root).resolve() / "grades.csv")
    # Late penalties per assignment (c.LatePenalty.per_day in the course's nbgrader_config.py).
    c.AssignLatePenalties.plugin_class = "autograder.term.late.LatePenalty"
    # `nbgrader zip_collect`: the file names and times of an LMS download.
    c.ZipCollectApp.collector_plugin = "autograder.term.collect.LmsFileNames"
    quiet_add_submission()


def watched_preprocessors() -> list:
    """nbgrader's autograde preprocessors, its Execute replaced by autograder.sandbox.cell_watch's."""
    from nbgrader.converters import Autograde
    from nbgrader.preprocessors import Execute

    from autograder.sandbox.cell_watch import WatchedExecute

    steps = Autograde.class_traits()["autograde_preprocessors"].default()
    return [WatchedExecute if step is Execute else step for step in steps]


def quiet_add_submission() -> None:
    """Silence the one SQLAlchemy warning nbgrader's Gradebook.add_submission raises on every new
    submission ("Object of type <SubmittedAssignment> not in session, add operation along
    'Student.submissions' will not proceed"): add_submission builds the ORM objects before it adds
    them to the session, and reading the assignment's notebooks meanwhile autoflushes. Harmless
    (the objects are added right after), but printed by every grading run. Only that message,
    only from nbgrader.api."""
    import warnings

    try:
        from sqlalchemy.exc import SAWarning
    except ImportError:
        return
    warnings.filterwarnings("ignore", message=r"Object of type <Submitted\w+> not in session",
                            category=SAWarning, module=r"nbgrader\.api")


class GradeOnSubmit(Configurable):
    """Grading on submission (the hub's grading service, coursehub.grading_service), per assignment,
    in the course's nbgrader_config.py::

        c.GradeOnSubmit.assignments = {"brightness": {"attempts": 3, "reasons_before_due": False}}

    An assignment not named is graded only by the instructor's grade run. ``attempts``: how many
    submissions before the due date are graded (default: no limit; later ones are refused and set
    aside, so the instructor's collect takes the last one graded). ``reasons_before_due``: False
    shows only the scores of the hidden checks until the due date, not why they failed (default
    True). After the due date the instructor's grade and feedback runs give the final grades.
    ``c.GradeOnSubmit.workers = 2``: submissions graded at the same time (read when the service
    starts; the hub restarts it when it is stopped)."""

    assignments = Dict(default_value={}, help="assignment -> {'attempts': int, 'reasons_before_due': bool}; "
                       "named assignments are graded when submitted").tag(config=True)
    workers = Int(default_value=None, allow_none=True,
                  help="submissions graded at the same time (default SUBMIT_WORKERS)").tag(config=True)


@dataclasses.dataclass(frozen=True)
class SubmitRules:
    """One assignment's grading on submission (GradeOnSubmit)."""
    attempts: int | None = None       # graded submissions before the due date; None: no limit
    reasons_before_due: bool = True   # False: scores only until the due date


SUBMIT_RULE_KEYS = {field.name for field in dataclasses.fields(SubmitRules)}

#: Seconds between two looks of the hub's grading service at the exchange's inbound/.
SUBMIT_POLL_SECONDS = 1.0
#: Submissions the hub's grading service grades at the same time (each keeps 2 cores busy).
SUBMIT_WORKERS = 1


def submit_rules(course_config, assignments: list[str]) -> dict[str, SubmitRules]:
    """The assignments graded on submission and their rules, from a course's configuration (load).

    Raises:
        ValueError: c.GradeOnSubmit.assignments names no assignment of the course, or holds a
            setting that does not exist or has the wrong type (the message names the fix).
    """
    named = dict(GradeOnSubmit(config=course_config).assignments)
    rules = {}
    for name, settings in named.items():
        where = f"c.GradeOnSubmit.assignments[{name!r}] in the course's nbgrader_config.py"
        if name not in assignments:
            raise ValueError(f"{where}: {name!r} is no assignment of the course ({', '.join(assignments)}): "
                             "correct the name.")
        settings = dict(settings or {})
        unknown = sorted(set(settings) - SUBMIT_RULE_KEYS)
        if unknown:
            raise ValueError(f"{where} has {', '.join(unknown)}: the settings are "
                             f"{', '.join(sorted(SUBMIT_RULE_KEYS))}.")
        attempts = settings.get("attempts")
        if attempts is not None and (not isinstance(attempts, int) or isinstance(attempts, bool) or attempts < 1):
            raise ValueError(f"{where}: 'attempts' is {attempts!r}; give a whole number of at least 1, or leave it "
                             "out for no limit.")
        if not isinstance(settings.get("reasons_before_due", True), bool):
            raise ValueError(f"{where}: 'reasons_before_due' must be True or False.")
        rules[name] = SubmitRules(**settings)
    return rules


def submit_workers(course_config) -> int:
    """How many submissions the grading service grades at the same time (c.GradeOnSubmit.workers).

    Raises:
        ValueError: the setting is not a whole number of at least 1 (the message names the fix).
    """
    from traitlets import TraitError

    try:
        workers = GradeOnSubmit(config=course_config).workers
    except TraitError:
        workers = course_config.GradeOnSubmit.workers
    if workers is None:
        return SUBMIT_WORKERS
    if not isinstance(workers, int) or isinstance(workers, bool) or workers < 1:
        raise ValueError(f"c.GradeOnSubmit.workers in the course's nbgrader_config.py is {workers!r}: give a whole "
                         f"number of at least 1 (each grading keeps about two cores busy), or leave it out for "
                         f"{SUBMIT_WORKERS}.")
    return workers


#: The line of the course's nbgrader_config.py below which the instructor's settings are kept.
MARKER = "# ---- Your settings below this line are kept when the autograder rewrites this file ----"

#: The repository the grader runs from (it is not installed: students' environments never hold it).
REPO = Path(__file__).resolve().parent.parent

CONFIG_HEADER = f'''\
# nbgrader configuration of the course (written by `python -m autograder`).
# The course's settings live in autograder/config.py; the lines above the marker are rewritten.
import sys
from pathlib import Path

try:
    from autograder.config import apply
except ImportError:  # nbgrader or the formgrader started by hand: the grader's repository
    sys.modules.pop("autograder", None)  # the course's autograder/ folder (grading records), not the grader
    sys.path.append({str(REPO)!r})
    from autograder.config import apply

c = get_config()  # noqa: F821 (provided by nbgrader)
apply(c, Path(__file__).resolve().parent)

{MARKER}
'''

#: What a new course's settings section holds: the settings an instructor may want, commented out.
SETTINGS_EXAMPLE = '''\
# Late penalty per assignment: the fraction of the score lost per started day late, capped.
# Due dates are in the gradebook:
#   python -m autograder release COURSE_DIR --assignment pubsub --duedate "2025-03-14 23:59 Europe/Berlin"
# c.LatePenalty.per_day = {"pubsub": 0.1, "brightness": 0.1, "catdog_warp": 0.1}
# c.LatePenalty.maximum = 0.5
# Grading on submission on the course's JupyterHub (its grading service), per assignment: how many
# submissions before the due date are graded, and whether the hidden checks' reasons show before it:
# c.GradeOnSubmit.assignments = {"brightness": {"attempts": 3, "reasons_before_due": True}}
# and how many submissions it grades at the same time (each keeps about two cores busy):
# c.GradeOnSubmit.workers = 1
# The time zone of the submission times in your LMS's file names (python -m autograder collect):
# c.LmsFileNames.timezone = "Europe/Berlin"
# The file names of your LMS's download, when they differ from autograder.term.collect.LMS_FILE_NAME
# (a regular expression with the groups student_id, file_id and, to keep the submission time, timestamp):
# c.FileNameCollectorPlugin.named_regexp = r"..."
'''

#: The file earlier versions wrote (no settings section): replaced as a whole.
_OLD_TEMPLATE = '''\
# nbgrader configuration of the course (written by `python -m autograder release`).
# The settings live in autograder/config.py; edit them there.
from pathlib import Path

from autograder.config import apply

c = get_config()  # noqa: F821 (provided by nbgrader)
apply(c, Path(__file__).resolve().parent)
'''


def write_config(course_dir: Path) -> Path:
    """Write course_dir/nbgrader_config.py (idempotent) and return its path: the course's header,
    and below the marker the instructor's settings as they are (a new file gets commented examples).

    Raises:
        ValueError: the file exists but was not written by the autograder (no marker line).
    """
    path = Path(course_dir) / "nbgrader_config.py"
    text = path.read_text() if path.exists() else None
    if text is None or text == _OLD_TEMPLATE:
        settings = SETTINGS_EXAMPLE
    elif MARKER in text:
        settings = text.split(MARKER, 1)[1].lstrip("\n")
    else:
        raise ValueError(f"{path} was not written by the autograder, which needs its own header in it. "
                         f"Rename your file, run the command again, and copy your settings below the line "
                         f"'{MARKER}' of the new one.")
    wanted = CONFIG_HEADER + settings
    if text != wanted:
        path.write_text(wanted)
    return path


def load(course_dir):
    """The course's nbgrader configuration (its nbgrader_config.py, instructor's settings included),
    as a traitlets Config for nbgrader classes used in this process."""
    from traitlets.config.loader import PyFileConfigLoader

    return PyFileConfigLoader("nbgrader_config.py", path=str(Path(course_dir).resolve())).load_config()
