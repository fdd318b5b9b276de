"""The grading service's queue (coursehub.submit_queue): arrival order, one row per claim,
superseded and refused submissions, and nothing lost when its process dies."""

from __future__ import annotations

import subprocess
import sys
import threading
from datetime import datetime, timedelta

from course_lib import contract
from coursehub.submit_queue import SubmitQueue

T0 = datetime(2026, 3, 1, 12, 0)


def _add(queue, student, minute, attempts=None, duedate=None, assignment="brightness"):
    return queue.add(f"{student}+{assignment}+{minute}", student, assignment, T0 + timedelta(minutes=minute),
                     attempts, duedate)


def test_rows_are_claimed_in_arrival_order_and_each_by_one_worker(tmp_path):
    queue = SubmitQueue(tmp_path)
    for n in range(20):
        _add(queue, f"s{n:02d}", n)
    claimed, lock = [], threading.Lock()

    def work(worker):
        while (row := queue.claim(worker)) is not None:
            with lock:
                claimed.append(row.student)
    threads = [threading.Thread(target=work, args=(n,)) for n in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert sorted(claimed) == [f"s{n:02d}" for n in range(20)]  # each once
    assert {r.state for r in queue.all()} == {"grading"} and queue.busy()
    # Each row says which worker took it, and when: the claims went oldest first.
    rows = queue.all()
    assert [r.claimed for r in rows] == list(range(1, 21)) and {r.worker for r in rows} <= set(range(4))


def test_a_queue_file_of_the_first_version_gets_the_worker_columns(tmp_path):
    import sqlite3

    from coursehub.submit_queue import SCHEMA

    (tmp_path / "autograder").mkdir()
    old = SCHEMA.replace("changed TEXT NOT NULL,", "changed TEXT NOT NULL").split("\n    worker")[0] + "\n)"
    with sqlite3.connect(tmp_path / "autograder" / "submit_queue.sqlite") as db:
        db.execute(old)
        db.execute("INSERT INTO submissions (entry, student, assignment, submitted, attempt, state, changed) "
                   "VALUES ('ann+brightness+1', 'ann', 'brightness', '2026-03-01', 1, 'queued', 'then')")
    queue = SubmitQueue(tmp_path)
    row = queue.claim(1)
    assert (row.student, row.worker, row.claimed) == ("ann", 1, 1)


def test_a_newer_submission_supersedes_the_queued_one_and_the_page_counts_who_is_ahead(tmp_path):
    from coursehub import grading_status  # here, not at collection: it imports JupyterHub (about 1.5 CPU-s)

    queue = SubmitQueue(tmp_path)
    _add(queue, "ann", 0)
    old = _add(queue, "bob", 1)
    newer = _add(queue, "bob", 2)
    assert queue.get(old.id).state == "superseded" and newer.attempt == 2
    assert grading_status.describe(queue, newer) == "queued (1 ahead)"
    assert queue.claim().student == "ann"
    assert grading_status.describe(queue, queue.get(newer.id)) == "queued (0 ahead)"
    page = grading_status.page(queue, "bob")
    assert "ann" not in page and "replaced this one" in page  # a student sees only their own


def test_submissions_past_the_attempts_before_the_due_date_are_refused(tmp_path):
    queue = SubmitQueue(tmp_path)
    due = T0 + timedelta(minutes=10)
    assert [_add(queue, "bob", m, attempts=2, duedate=due).state for m in (1, 2, 3)] == ["queued", "queued", "refused"]
    assert "allows 2 graded submissions before the due date (2026-03-01 12:10 UTC), and this is your 3rd" \
        in queue.of_student("bob")[0].message
    assert _add(queue, "bob", 11, attempts=2, duedate=due).state == "queued"  # late: graded, the penalty applies
    assert _add(queue, "ann", 4, attempts=2, duedate=due).state == "queued"  # per student


def test_rows_being_graded_when_the_process_was_killed_are_queued_again(tmp_path):
    """A process that claimed a row and recorded another dies by SIGKILL: a new queue on the same file
    has both, and the claimed row queued again."""
    script = f"""
import os, signal
from datetime import datetime
from coursehub.submit_queue import SubmitQueue
queue = SubmitQueue({str(tmp_path)!r})
for n in range(3):
    queue.add(f"s{{n}}+a+x", f"s{{n}}", "a", datetime(2026, 3, 1), None, None)
done = queue.claim()
queue.graded(done.id, "content", 5.0, 10.0)
queue.claim()
os.kill(os.getpid(), signal.SIGKILL)
"""
    died = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          cwd=contract.ROOT)  # python -c imports autograder from its working directory
    assert died.returncode == -9, died.stderr
    queue = SubmitQueue(tmp_path)
    assert [r.state for r in queue.all()] == ["graded", "grading", "queued"]
    assert queue.recover() == 1
    assert [(r.state, r.gradings) for r in queue.all()] == [("graded", 1), ("queued", 0), ("queued", 0)]
    assert queue.claim().student == "s1"
