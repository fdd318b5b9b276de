"""The grader's run of a submission's hidden checks (autograder/grading/hidden_checks_process.py): the
time of all checks together (AUTOGRADER_CHECKS_SECONDS) bounds each call, and a check cut short
says what it was waiting on."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time

from autograder.grading import hidden_checks_process
from autograder.grading.hidden_checks_process import _Run
from course_lib import contract
from course_lib.checks.runner import child_pythonpath
from course_lib.checks.student_server import StudentServers

HANGS = "import time\ndef average_brightness(image):\n    time.sleep(100)\n"


def test_a_hung_call_costs_at_most_the_checks_time_and_is_named(tmp_path):
    module = tmp_path / "ros2_ws" / "src" / "brightness" / "brightness" / "brightness_node.py"
    module.parent.mkdir(parents=True)
    (module.parent / "__init__.py").write_text("")
    module.write_text(HANGS)
    out = tmp_path / "out"
    out.mkdir()
    env = {**os.environ, contract.CHECKS_SECONDS_ENV: "8", "PYTHONPATH": child_pythonpath()}
    subprocess.run([sys.executable, "-m", "autograder.grading.hidden_checks_process", "brightness", "values",
                    "--workdir", str(tmp_path), "--out", str(out)], env=env, cwd=out, timeout=60, check=True)
    result = json.loads((out / "values.json").read_text())
    messages = [item["message"] for item in result["items"]]
    # The call hangs: it ends at the time left (the grading's), or the grading's time runs out
    # while it runs (a loaded machine imports slowly); either way the reason names the call.
    assert "average_brightness on a colour (BGR) image" in messages[0]
    assert "did not return within" in messages[0] or "the grading time of 8 s ran out while" in messages[0]
    assert result["points"] == 0


class _Cut:
    """What the grader knows of a check still running when the time ran out."""

    doing = "student-pubsub-topic_publisher-publisher was starting or running (2.0 s into the check)"
    items = [{"ok": True, "message": "node topic_publisher runs", "weight": 0.0}]
    notes: list = []
    _started = time.monotonic()


def test_checks_cut_short_by_the_time_say_what_was_running_and_earn_nothing(tmp_path):
    run = _Run("pubsub", tmp_path, tmp_path, None, StudentServers(10))
    run.running["publisher"] = (_Cut(), 7)
    run.time_is_up(["publisher", "subscriber"], 30)
    publisher = json.loads((tmp_path / "publisher.json").read_text())
    subscriber = json.loads((tmp_path / "subscriber.json").read_text())
    assert publisher["points"] == 0 and publisher["seed"] == 7
    assert publisher["error"] == ("the grading time of 30 s ran out while student-pubsub-topic_publisher-publisher "
                                  "was starting or running (2.0 s into the check)")
    assert publisher["items"][0]["ok"] and not publisher["items"][-1]["ok"]
    assert subscriber["error"] == "not run: the grading time of 30 s ran out before this check started"


def test_the_budget_comes_from_the_environment(monkeypatch):
    monkeypatch.setenv(contract.CHECKS_SECONDS_ENV, "12.5")
    assert hidden_checks_process.budget_from_environment() == 12.5
    monkeypatch.delenv(contract.CHECKS_SECONDS_ENV)
    assert hidden_checks_process.budget_from_environment() is None


def test_each_check_of_a_grading_gets_two_domains_no_other_check_uses():
    """In the submission's own namespace, a check's domain and its second domain (a launch file's
    nodes beside a single node) are used by no other check of the grading, wherever the base lies."""
    for base in (0, 101, 230):
        domains = [d for index in range(6) for d in hidden_checks_process._domains(base, index)]
        assert len(set(domains)) == len(domains) and all(0 <= d <= 232 for d in domains)
