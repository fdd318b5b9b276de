"""autograder.grading.pipeline's budget: one submission's grading is bounded, a notebook stopped at its
share says how long it was given (issue #14), and nothing of the student's outlives it."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
import types

import pytest

from autograder.grading import pipeline
from autograder.results import report
from autograder.results.grade_result import GradeResult
from autograder.results.submissions import Submission
from course_lib import contract
from course_lib.ros import processes


def test_each_step_gets_what_is_left_of_the_budget_less_what_it_keeps_for_later():
    g = pipeline.Grading(None, None, 0, GradeResult("s", "a", ""), None, deadline=time.monotonic() + 30)
    assert 28 < g.seconds_left() <= 30
    assert 8 < g.seconds_left(keep=20) <= 10
    g.deadline = time.monotonic() - 5  # spent: a later step still gets a second to say so
    assert g.seconds_left() == 1.0


def test_a_notebook_stopped_at_its_share_names_the_seconds_given_and_the_cells_that_ran_past_their_limit():
    proc = processes.NodeProcess([sys.executable, "-c", "import time; time.sleep(30)"], name="budget test",
                                 limits=processes.Limits(wall_seconds=0.5, grace_seconds=0.5))
    proc.start()
    proc.wait(10)
    proc.stop(timeout=2)
    log = "[AutogradeApp | ERROR] Timeout waiting for execute reply (30s).\n" * 2
    reason = pipeline._explain_failure(log, proc, 37.5, 60.0)
    assert proc.exit_reason == "wall_seconds"
    assert "did not finish within the 37.5 s its run was given" in reason
    assert "of 60 s for grading one submission" in reason
    assert "2 cell(s) ran past their limit of 30 s" in reason


def test_the_report_shows_where_the_time_went():
    result = GradeResult("s", "a", "",
                         steps={"stage_course_root": 0.01, "run_notebook": 5.43, "run_hidden_checks": 6.3})
    assert report.step_seconds(result) == "run_notebook=5.4 run_hidden_checks=6.3"


def test_the_budget_is_sixty_seconds_on_an_idle_machine_and_grows_with_the_load_up_to_a_bound():
    budget = pipeline.grading_budget()
    assert pipeline.GRADING_SECONDS <= budget <= pipeline.GRADING_SECONDS * pipeline.MAX_LOAD_FACTOR


def test_the_checks_limits_grow_with_the_load_factor_the_grader_passes_on(monkeypatch):
    """A call's and an import's wall-clock backstop, and a check's own timeout, grow with the load
    factor the grader passes on (never below the idle limits, at most MAX_LOAD_FACTOR times); a
    self-check, which has none, takes the machine's load per core now."""
    import os

    from course_lib.checks import context

    cores = os.cpu_count() or 1
    monkeypatch.delenv(contract.LOAD_FACTOR_ENV, raising=False)
    monkeypatch.setattr(os, "getloadavg", lambda: (0.1, 0.1, 0.1))
    assert context.scaled(context.CALL_TIMEOUT) == context.CALL_TIMEOUT
    monkeypatch.setattr(os, "getloadavg", lambda: (2.0 * cores, 0.1, 0.1))
    assert context.scaled(context.CALL_TIMEOUT) == 2.0 * context.CALL_TIMEOUT
    monkeypatch.setenv(contract.LOAD_FACTOR_ENV, "3.5")
    assert context.scaled(context.CALL_TIMEOUT) == 3.5 * context.CALL_TIMEOUT
    monkeypatch.setenv(contract.LOAD_FACTOR_ENV, "0.2")
    assert context.scaled(context.IMPORT_TIMEOUT) == context.IMPORT_TIMEOUT
    monkeypatch.setenv(contract.LOAD_FACTOR_ENV, "100")
    assert context.scaled(context.IMPORT_TIMEOUT) == context.MAX_LOAD_FACTOR * context.IMPORT_TIMEOUT
    monkeypatch.setenv(contract.LOAD_FACTOR_ENV, "busy")
    assert context.scaled(context.IMPORT_TIMEOUT) == 2.0 * context.IMPORT_TIMEOUT


def test_the_grader_tells_the_checks_its_load_factor(tmp_path):
    from autograder.results.submissions import Submission

    sub = Submission("s", "brightness", tmp_path)
    g = pipeline.Grading(sub, tmp_path, 0, GradeResult("s", "brightness", ""), tmp_path, budget=150.0)
    pipeline.choose_environment(g)
    assert g.env[contract.LOAD_FACTOR_ENV] == "2.50"


def test_the_checks_student_processes_may_start_fewer_tasks_than_the_kernel(tmp_path):
    """As root, the kernel's uid may have MAX_PROCESSES processes and threads, the checks' student
    processes checks_max_processes(): what the references' checks need with room to spare, a third
    of the kernel's on 2 cores, so that a fork bomb in the student's function or node forks a third
    as many copies of a ROS process (the zoo's fork_bomb)."""
    from autograder.results.submissions import Submission

    sub = Submission("s", "brightness", tmp_path)
    g = pipeline.Grading(sub, tmp_path, 0, GradeResult("s", "brightness", "", isolation="root"), tmp_path)
    pipeline.choose_environment(g)
    assert g.env[contract.KERNEL_NPROC_ENV] == str(contract.MAX_PROCESSES)
    assert g.env[contract.STUDENT_NPROC_ENV] == str(pipeline.checks_max_processes())
    assert pipeline.checks_max_processes(cores=2) == 128
    assert pipeline.checks_max_processes(cores=2) >= 68 * 1.8  # the references' checks peak at 68 tasks there
    assert pipeline.checks_max_processes(cores=64) == contract.MAX_PROCESSES


def test_an_early_run_still_going_at_the_deadline_is_waited_for_not_dropped(tmp_path, monkeypatch):
    """On a machine busier than the budget allows for, the notebook can end while the early build
    and checks are past the grading's deadline: their verdicts are waited for (their steps bound
    themselves), not dropped for a build and checks again with a second left."""
    from autograder.builds import notebook_writes
    from autograder.grading import early_checks, hidden_checks

    building = threading.Event()

    def build(g, folder, run, early):
        building.wait(10)  # a build still running when the deadline passes
        return {"BUILT": "1"}

    monkeypatch.setattr(hidden_checks, "run_checks",
                        lambda sub, names, *args, **kwargs: dict.fromkeys(names, "verdict"))
    sub = Submission("s", "brightness", tmp_path)
    g = pipeline.Grading(sub, None, 0, GradeResult("s", "brightness", ""), tmp_path, deadline=time.monotonic() - 1)
    early = early_checks.EarlyRun(g, ["values"], build)
    early.digest = notebook_writes.folder_digest(tmp_path)  # the notebook wrote what was predicted
    early._thread.start()
    threading.Timer(0.5, building.set).start()
    assert early.outcome_for(tmp_path, ["values"]) == ({"BUILT": "1"}, {"values": "verdict"})


@pytest.mark.skipif(os.geteuid() != 0, reason="the student's uids are the grader's as root only")
def test_what_still_runs_as_the_students_uids_at_the_end_is_killed_and_reported():
    """A process of the kernel's uid that outlived the submission's grading is killed before the
    uid goes to the next submission, and the instructor's report says so."""
    # No grader uses these (theirs are pipeline.KERNEL_UID_BASE + a domain id, and 1000 more), nor
    # does test_process_tree.py (64999), which runs beside this test in another worker.
    uid = 64990
    g = types.SimpleNamespace(result=GradeResult("s", "a", "", kernel_uid=uid), early_uid=uid + 1)
    pipeline._end_student_processes(g)
    assert g.result.detail == ""
    left = subprocess.Popen(["/bin/sleep", "60"], user=uid)
    try:
        pipeline._end_student_processes(g)
        assert left.wait(timeout=10) == -signal.SIGKILL
        assert "1 process(es) of the student's uid still ran" in g.result.detail
    finally:
        left.kill()
        left.wait(timeout=10)
