"""The assignments' checks, shared by the students' self-checks and the grader.

- ``course_lib.checks.assignments.<assignment>``: one file per assignment (``brightness``, ``pubsub``,
  ``catdog_warp``, ``services_actions``, ``quiz``, ``pillar``: every file of that folder), holding its spec, its
  notebook's words and its checks. A notebook imports one as ``from course_lib.checks import
  brightness as checks`` (this package finds the name there) and calls ``checks.selfcheck("values")``.
- ``spec`` (what an assignment's spec is), ``registry`` (what a check is), ``runner`` (how it runs:
  its own process, ``check_process``), ``context`` (what a check gets), ``packages`` (the student's
  workspace: its build report, ``ros2 run``), ``student``/``student_server``/``student_calls``/
  ``student_processes`` (the student's code in another process, one per module serving many calls),
  ``probe`` (the checker's ROS node), ``result`` (the verdict).
- ``brightness_throughput``: the brightness node's throughput, judged against a yardstick node;
  ``lock_step``: the simulated robot as the pillar checks drive it, waiting on the controller's
  processor time;
  ``multiple_choice`` and ``quiz_questions``: the quiz's questions.
- ``answers``: where a check's expected answers come from: the grader's answer key when graded
  (instructor side: the folder the grader hands over, contract.ANSWER_KEYS_ENV), answers
  recorded from it in a self-check (``recorded/<assignment>.json``).
- ``validate``: the cell timeouts of Validate.

No reference solution and no answer key is in this package: students have it.
"""

import importlib
import os
import sys


def __getattr__(name: str):
    """``from course_lib.checks import brightness``: an assignment's module (checks/assignments/<name>.py).
    Found by its file, so that looking up one of this package's own modules imports no assignment."""
    package = sys.modules.get(f"{__name__}.assignments")
    folders = package.__path__ if package is not None else [os.path.join(os.path.dirname(__file__), "assignments")]
    if not name.startswith("_") and any(os.path.isfile(os.path.join(folder, f"{name}.py")) for folder in folders):
        return importlib.import_module(f"{__name__}.assignments.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
