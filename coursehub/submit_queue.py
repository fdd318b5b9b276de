"""The durable queue of the hub's grading service: COURSE_DIR/autograder/submit_queue.sqlite.

One row per submission found in the exchange's inbound/ (its folder name is unique), in the order
found, which is the order of arrival. A row goes

    queued -> grading -> graded -> released      (or: superseded, refused, failed)

and every change is one SQLite transaction (synchronous=FULL), so a service killed at any point
loses nothing: on start, :meth:`SubmitQueue.recover` puts the rows it was grading back in the
queue, and graded rows whose feedback was not released yet are released again. Workers take rows
one at a time (:meth:`claim`), oldest first; a row keeps which worker took it last and when, as a
count of the queue's claims (``worker``, ``claimed``). A newer submission of the same student and
assignment supersedes an older one still queued; one past the assignment's attempts before the
due date is refused (:meth:`add`). ``gradings`` counts the results recorded for a row (1 when
all went well, whatever crashed in between).
"""

from __future__ import annotations

import dataclasses
import sqlite3
import threading
from datetime import datetime, timezone
from pathlib import Path

FILE_NAME = "submit_queue.sqlite"

#: The states a row can be in; the first three are waiting for the service.
STATES = ("queued", "grading", "graded", "released", "superseded", "refused", "failed")

SCHEMA = """
CREATE TABLE IF NOT EXISTS submissions (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    entry TEXT UNIQUE NOT NULL,      -- the folder's name in the exchange's inbound/
    student TEXT NOT NULL,
    assignment TEXT NOT NULL,
    submitted TEXT NOT NULL,         -- nbgrader's timestamp of the submission
    attempt INTEGER NOT NULL,        -- 1 for the student's first submission of the assignment
    state TEXT NOT NULL,
    content TEXT NOT NULL DEFAULT '',  -- autograder.results.submissions.submission_digest(content_only=True)
    reused_from INTEGER,             -- the row whose grading of the same content was reused
    score REAL,
    max_score REAL,
    message TEXT NOT NULL DEFAULT '',
    gradings INTEGER NOT NULL DEFAULT 0,
    changed TEXT NOT NULL,
    worker INTEGER,                  -- the worker that took it last (0, 1, ...: the service's --workers)
    claimed INTEGER                  -- when: 1 for the queue's first claim, 2 for the next, ...
)
"""
#: Columns a queue file written by an earlier version lacks: added when it is opened.
ADDED_COLUMNS = {"worker": "INTEGER", "claimed": "INTEGER"}


@dataclasses.dataclass
class Row:
    id: int
    entry: str
    student: str
    assignment: str
    submitted: str
    attempt: int
    state: str
    content: str = ""
    reused_from: int | None = None
    score: float | None = None
    max_score: float | None = None
    message: str = ""
    gradings: int = 0
    changed: str = ""
    worker: int | None = None
    claimed: int | None = None


def _now() -> str:
    return datetime.now(timezone.utc).isoformat(timespec="milliseconds")


class SubmitQueue:
    """The queue in a course directory; one object may be used from several threads."""

    def __init__(self, course: Path):
        self.path = Path(course) / "autograder" / FILE_NAME
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._lock = threading.Lock()
        self._db = sqlite3.connect(self.path, check_same_thread=False, isolation_level=None, timeout=60)
        self._db.row_factory = sqlite3.Row
        self._db.execute("PRAGMA journal_mode=WAL")
        self._db.execute("PRAGMA synchronous=FULL")
        self._db.execute(SCHEMA)
        columns = {row[1] for row in self._db.execute("PRAGMA table_info(submissions)")}
        for name, declaration in ADDED_COLUMNS.items():
            if name not in columns:
                self._db.execute(f"ALTER TABLE submissions ADD COLUMN {name} {declaration}")

    def close(self) -> None:
        with self._lock:
            self._db.close()

    def _transaction(self, work):
        with self._lock:
            self._db.execute("BEGIN IMMEDIATE")
            try:
                value = work(self._db)
            except BaseException:
                self._db.execute("ROLLBACK")
                raise
            self._db.execute("COMMIT")
            return value

    def _rows(self, sql: str, *args) -> list[Row]:
        with self._lock:
            return [Row(**dict(r)) for r in self._db.execute(sql, args).fetchall()]

    def known(self) -> set[str]:
        """The inbound folder names already in the queue."""
        with self._lock:
            return {r[0] for r in self._db.execute("SELECT entry FROM submissions")}

    def add(self, entry: str, student: str, assignment: str, submitted: datetime, attempts: int | None,
            duedate: datetime | None, refused: str | None = None) -> Row:
        """Queue a new submission: it supersedes the student's older one of the assignment still
        queued; it is refused when it is past `attempts` submissions before the due date (None:
        no limit; a submission after the due date is never refused), or with the reason `refused`
        (an entry that is no submission of the student's: coursehub.inbound). Times are naive UTC."""

        def work(db):
            attempt = 1 + db.execute("SELECT COUNT(*) FROM submissions WHERE student=? AND assignment=?",
                                     (student, assignment)).fetchone()[0]
            before_due = duedate is None or submitted <= duedate
            counted = db.execute("SELECT COUNT(*) FROM submissions WHERE student=? AND assignment=? "
                                 "AND state != 'refused' AND (? IS NULL OR submitted <= ?)",
                                 (student, assignment, _iso(duedate), _iso(duedate))).fetchone()[0]
            state, message = "queued", ""
            if refused:
                state, message = "refused", refused
            elif attempts is not None and before_due and counted >= attempts:
                state = "refused"
                due = f"the due date ({duedate:%Y-%m-%d %H:%M} UTC)" if duedate else "the due date"
                message = (f"{assignment} allows {attempts} graded submission"
                           f"{'s' if attempts != 1 else ''} before {due}, and this is your "
                           f"{_ordinal(counted + 1)}. Your last graded submission stands; your instructor "
                           "grades it again after the due date.")
            else:
                db.execute("UPDATE submissions SET state='superseded', changed=?, message=? WHERE student=? "
                           "AND assignment=? AND state='queued'",
                           (_now(), "A newer submission of yours replaced this one before it was graded.",
                            student, assignment))
            cursor = db.execute(
                "INSERT INTO submissions (entry, student, assignment, submitted, attempt, state, message, changed) "
                "VALUES (?, ?, ?, ?, ?, ?, ?, ?)", (entry, student, assignment, _iso(submitted), attempt, state,
                                                    message, _now()))
            return cursor.lastrowid

        return self.get(self._transaction(work))

    def get(self, row_id: int) -> Row:
        return self._rows("SELECT * FROM submissions WHERE id=?", row_id)[0]

    def claim(self, worker: int = 0) -> Row | None:
        """The oldest queued row, now 'grading' by `worker`; None when nothing is queued."""

        def work(db):
            found = db.execute("SELECT id FROM submissions WHERE state='queued' ORDER BY id LIMIT 1").fetchone()
            if found is None:
                return None
            db.execute("UPDATE submissions SET state='grading', worker=?, claimed=(SELECT COALESCE(MAX(claimed), 0) "
                       "+ 1 FROM submissions), changed=? WHERE id=?", (worker, _now(), found[0]))
            return found[0]

        row_id = self._transaction(work)
        return None if row_id is None else self.get(row_id)

    def graded(self, row_id: int, content: str, score: float, max_score: float, message: str = "",
               reused_from: int | None = None) -> None:
        """Record a row's result (its feedback is not released yet)."""
        self._transaction(lambda db: db.execute(
            "UPDATE submissions SET state='graded', content=?, score=?, max_score=?, message=?, reused_from=?, "
            "gradings=gradings+1, changed=? WHERE id=? AND state='grading'",
            (content, score, max_score, message, reused_from, _now(), row_id)))

    def failed(self, row_id: int, message: str, content: str | None = None, score: float | None = None,
               max_score: float | None = None) -> None:
        """A row that ends without feedback to release; with `content`, its (failed) result was recorded."""
        recorded = 1 if content is not None else 0
        self._transaction(lambda db: db.execute(
            "UPDATE submissions SET state='failed', message=?, content=COALESCE(?, content), score=COALESCE(?, score), "
            "max_score=COALESCE(?, max_score), gradings=gradings+?, changed=? WHERE id=?",
            (message, content, score, max_score, recorded, _now(), row_id)))

    def refuse(self, row_id: int, message: str) -> None:
        """A row whose files were not taken (autograder.sandbox.untrusted): not graded, for the reason `message`."""
        self._transaction(lambda db: db.execute(
            "UPDATE submissions SET state='refused', message=?, changed=? WHERE id=?", (message, _now(), row_id)))

    def released(self, row_ids: list[int]) -> None:
        """The feedback of these rows is in the exchange."""
        def work(db):
            for row_id in row_ids:
                db.execute("UPDATE submissions SET state='released', changed=? WHERE id=? AND state='graded'",
                           (_now(), row_id))
        self._transaction(work)

    def recover(self) -> int:
        """After a stop or crash: rows left 'grading' are queued again (their grading did not end);
        return how many."""
        return self._transaction(lambda db: db.execute(
            "UPDATE submissions SET state='queued', changed=? WHERE state='grading'", (_now(),)).rowcount)

    def busy(self) -> bool:
        """Whether a row is queued or being graded."""
        with self._lock:
            return self._db.execute("SELECT 1 FROM submissions WHERE state IN ('queued', 'grading') LIMIT 1"
                                    ).fetchone() is not None

    def waiting_for_feedback(self) -> list[Row]:
        return self._rows("SELECT * FROM submissions WHERE state='graded' ORDER BY id")

    def same_content(self, assignment: str, content: str) -> list[Row]:
        """Rows of the assignment graded before with this content, newest first."""
        return self._rows("SELECT * FROM submissions WHERE assignment=? AND content=? AND state IN "
                          "('graded', 'released') ORDER BY id DESC", assignment, content)

    def of_student(self, student: str) -> list[Row]:
        """A student's rows, newest first."""
        return self._rows("SELECT * FROM submissions WHERE student=? ORDER BY id DESC", student)

    def ahead_of(self, row: Row) -> int:
        """How many queued rows come before `row`."""
        with self._lock:
            return self._db.execute("SELECT COUNT(*) FROM submissions WHERE state='queued' AND id < ?",
                                    (row.id,)).fetchone()[0]

    def all(self) -> list[Row]:
        return self._rows("SELECT * FROM submissions ORDER BY id")


def _iso(when: datetime | None) -> str | None:
    return None if when is None else when.strftime("%Y-%m-%d %H:%M:%S.%f")


def _ordinal(n: int) -> str:
    suffix = "th" if 10 <= n % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(n % 10, "th")
    return f"{n}{suffix}"
