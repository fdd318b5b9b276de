"""One student process serving many calls (course_lib/checks/student_server.py, through
Context.call as the checks use it): one import, a time limit per call, a hung function named
and not called again, answers kept across a crash."""

from __future__ import annotations

import numpy as np

from course_lib.checks import context
from course_lib.checks.context import Context, StudentError
from course_lib.checks.registry import get_check
from course_lib.checks.student_server import StudentServers

MODULE = """
import os, time
def average_brightness(image):
    if image.size == 7:
        time.sleep(100)
    if image.size == 5:
        os._exit(3)
    return os.getpid()
"""


def _context(tmp_path, code: str, servers=None) -> Context:
    module = tmp_path / "ros2_ws" / "src" / "brightness" / "brightness" / "brightness_node.py"
    module.parent.mkdir(parents=True, exist_ok=True)
    (module.parent / "__init__.py").write_text("")
    module.write_text(code)
    out = tmp_path / "out"
    out.mkdir(exist_ok=True)
    return Context(get_check("brightness", "values"), 1, tmp_path, out, servers=servers)


def test_calls_share_one_process_and_a_hung_function_is_named_and_not_called_again(tmp_path):
    servers = StudentServers(60)
    ctx = _context(tmp_path, MODULE, servers)
    try:
        images = [np.zeros(3), np.zeros(4), np.zeros(7), np.zeros(3)]
        first, second, hung, later = ctx.call("average_brightness", [((i,), {}) for i in images], timeout=1.5,
                                              labels=["'one'", "'two'", "'the slow one'", "'four'"])
        assert first.ok and second.ok and first.value == second.value  # one process, imported once
        assert "average_brightness on 'the slow one' did not return within 2 s" in hung.error
        assert later.error == "not run: average_brightness did not return within 2 s on 'the slow one' earlier"
        again = _context(tmp_path / "next", MODULE, servers)  # a later check of the same grading
        assert again.call("average_brightness", [((images[0],), {})])[0].error.startswith("not run: ")
    finally:
        ctx.close()
        servers.close()


def test_after_a_crash_the_next_call_runs_in_a_fresh_process(tmp_path):
    ctx = _context(tmp_path, MODULE)
    try:
        before, crash, after = ctx.call("average_brightness", [((np.zeros(n),), {}) for n in (3, 5, 3)])
        assert before.ok and after.ok and before.value != after.value
        assert "average_brightness on input 2 ended the process (exit code 3)" in crash.error
    finally:
        ctx.close()


def test_an_import_that_never_ends_is_marked_for_later_checks(tmp_path, monkeypatch):
    monkeypatch.setattr(context, "IMPORT_TIMEOUT", 2.0)
    ctx = _context(tmp_path, "while True:\n    pass\n")
    try:
        try:
            ctx.call("average_brightness", [((np.zeros(3),), {})])
            raise AssertionError("the import did not fail")
        except StudentError as error:
            assert "did not finish within 2 s" in str(error)
        assert (tmp_path / context.IMPORT_HANG_MARK).exists()
    finally:
        ctx.close()
