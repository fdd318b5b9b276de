"""What the grader (autograder/) and the checks (course_lib/checks/) agree on, each defined once:
the environment variables one sets for the other, the seeds, the folders, and the limits of the
student's code. A test (tests/repository/test_repository.py) fails when one of these names or folders is
spelled out again elsewhere: import it from here.

The grader sets these variables for the processes it starts (the notebook's kernel, the hidden
checks, the student's nodes); the checks and course_lib read them. Nothing here is secret: the
student's package holds this module, and the answer keys stay on the instructor's side
(``autograder/answers/``, handed to the checks as ANSWER_KEYS_ENV).
"""

from __future__ import annotations

import os
from pathlib import Path

#: nbgrader's course id: the course's assignments in an exchange, on a hub and in a student's lab alike.
COURSE_ID = "ros2-jazzy-opencv"

# --- folders ------------------------------------------------------------------------------------

#: The folder that holds course_lib: in a course checkout, the repository's root (autograder/,
#: assignments/, coursehub/ beside it); in a student's installed wheel, site-packages.
ROOT = Path(__file__).resolve().parents[1]
#: The colcon workspace beside an assignment's notebook (``ros2_ws/src/<package>/``).
WORKSPACE = "ros2_ws"
#: The nbgrader source notebooks of the assignments in the repository (assignments/build.py writes them).
ASSIGNMENTS_SOURCE = ROOT / "assignments" / "source"

# --- who runs: grading, the test suite ---------------------------------------------------------

#: "1" in every process of a grading run (under_grading).
GRADING_ENV = "COURSE_LIB_GRADING"
#: "1" under the test suite and CI's notebook runs: loops that would run for ever live are bounded.
UNDER_TEST_ENV = "COURSE_LIB_UNDER_TEST"


def under_grading() -> bool:
    """True while the autograder runs a submission (a separate flag from under_test on purpose)."""
    return os.environ.get(GRADING_ENV, "") not in ("", "0")


def under_test() -> bool:
    """True under the test suite or CI notebook runs: bound loops that would run forever live."""
    return os.environ.get(UNDER_TEST_ENV, "") not in ("", "0")

# --- seeds --------------------------------------------------------------------------------------

#: Set by the instructor to grade again with the seed a feedback page shows (reproduce a grade).
SEED_ENV = "AUTOGRADER_SEED"
#: The seed of one check's process, set by the runner that starts it.
CHECK_SEED_ENV = "AUTOGRADER_CHECK_SEED"

# --- the checks in a grading run ---------------------------------------------------------------

#: "1": the notebook's hidden test cells only say that the grader runs their checks outside.
CHECKS_OUTSIDE_ENV = "AUTOGRADER_CHECKS_OUTSIDE"
#: Seconds that all hidden checks of a submission may take together.
CHECKS_SECONDS_ENV = "AUTOGRADER_CHECKS_SECONDS"
#: How much longer than on an idle machine the wall-clock backstops may be (the grader's load).
LOAD_FACTOR_ENV = "AUTOGRADER_LOAD_FACTOR"
#: Where a check's expected answers come from: "selfcheck", "graded" or "record" (checks.answers).
ANSWERS_ENV = "AUTOGRADER_ANSWERS"
#: The folder of the grader's answer keys, ``<assignment>.py`` each (a function per question), that
#: the grader hands its graded checks and recordings (autograder.answers.environment): in a grading,
#: its private copy, which the student's uid cannot read. Student processes never get it.
ANSWER_KEYS_ENV = "AUTOGRADER_ANSWER_KEYS"
#: The file the answers are written to while recording them (``python -m autograder record-answers``).
RECORD_ANSWERS_ENV = "AUTOGRADER_RECORD_TO"
#: The JSON report of the grader's build of the submission's workspace (autograder.builds.workspace_build).
BUILD_REPORT_ENV = "AUTOGRADER_BUILD_REPORT"
#: "0" turns off the checks that start while the notebook still runs (autograder.grading.pipeline).
EARLY_CHECKS_ENV = "AUTOGRADER_EARLY_CHECKS"
#: "0" builds every submission's packages, even where an identical build could be reused.
REUSE_BUILDS_ENV = "AUTOGRADER_REUSE_BUILDS"

# --- the student's uid, kernel and sandbox ------------------------------------------------------

#: The uid the student's processes run as (when the grader runs as root), and its process limit.
STUDENT_UID_ENV = "AUTOGRADER_STUDENT_UID"
STUDENT_NPROC_ENV = "AUTOGRADER_STUDENT_NPROC"
#: The same for the grading kernel (autograder.sandbox.kernel), and the folder of its private /tmp.
KERNEL_UID_ENV = "AUTOGRADER_KERNEL_UID"
KERNEL_NPROC_ENV = "AUTOGRADER_KERNEL_NPROC"
KERNEL_TMP_ENV = "AUTOGRADER_KERNEL_TMP"
#: The sandbox's view of the interpreter (autograder.sandbox.namespaces). autograder/sandbox/sandbox_entry.py runs
#: with ``python -I -S`` and imports nothing of the course: it spells these three itself.
EXPOSE_ENV = "AUTOGRADER_EXPOSE"
BLOCKED_ENV = "AUTOGRADER_BLOCKED"
STAGE_ENV = "AUTOGRADER_STAGE"

# --- points ------------------------------------------------------------------------------------

#: Points are given and shown to this many decimals, rounded half up (checks.result.round_points).
#: nbgrader's feedback page shows scores to two decimals, so the self-check, the grader, the
#: gradebook, the grades file and every page agree on one number (7 of 8 items of a 7-point
#: check: 6.125 is 6.13 everywhere).
POINT_DECIMALS = 2

# --- limits of the student's code ---------------------------------------------------------------

#: Address space (MB) of each process of a submission's notebook run and of its build (CMake, the
#: compiler, rosidl's generators). Fast DDS + numpy + OpenCV need about 1 GB.
MEMORY_MB = 4096
#: Address space (MB) of each process the checks start for the student. rclpy with Fast DDS maps a
#: few hundred MB.
STUDENT_MEMORY_MB = 2048
#: Processes and threads of the student's uid (RLIMIT_NPROC, root only) in the notebook run and the
#: build. A kernel needs about 16.
MAX_PROCESSES = 384
#: The same bound while the checks run the student's code (its functions' server, its nodes):
#: CHECKS_PROCESSES_BASE + CHECKS_PROCESSES_PER_CORE per core, at most MAX_PROCESSES
#: (autograder.grading.pipeline.checks_max_processes). The references' checks peak at 68 tasks of the
#: uid (services_actions; catdog_warp 51, brightness and pillar 31) on 2 cores, and a process that uses
#: OpenCV's pool adds a thread per core. A fork bomb forks copies of a ROS process up to this bound,
#: and its cost grows with it (the zoo's fork_bomb, docs/developers.md).
CHECKS_PROCESSES_BASE = 64
CHECKS_PROCESSES_PER_CORE = 32
