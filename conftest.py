"""Test-wide set-up: every test run gets a ROS domain of its own and the 'under test' flag.

Both are set in os.environ before any test runs, so nodes started in-process, node processes
and notebook kernels (nbmake) all inherit them.
"""

import os

import cv2
import pytest

from course_lib import contract
from course_lib.ros import rosenv

_reservation = rosenv.reserve_domain_id()
os.environ["ROS_DOMAIN_ID"] = str(_reservation.domain_id)
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.pop("ROS_LOCALHOST_ONLY", None)
os.environ[contract.UNDER_TEST_ENV] = "1"
# The xdist workers start after this file is read, and every process the suite starts inherits it.
rosenv.keep_blas_to_one_thread(os.environ)
# The workers outnumber the cores, so OpenCV's thread pool in a worker only adds switching: the
# scene and photo tests take 41 CPU-s with it and 32 without. Processes the tests start keep theirs.
cv2.setNumThreads(1)


def pytest_addoption(parser, pluginmanager):
    """With nbmake left out (`-p no:nbmake`, as `make check` runs) no notebook is collected, and its
    options in pyproject.toml's addopts are accepted and do nothing instead of stopping the run."""
    if pluginmanager.is_blocked("nbmake"):
        group = parser.getgroup("nbmake", "left out by -p no:nbmake: these options do nothing")
        group.addoption("--nbmake", action="store_true")
        group.addoption("--nbmake-timeout", type=int)


@pytest.fixture(scope="module")
def session_domain():
    """A ROS domain reserved for one test module, with the notebook session (course_lib.ros.session,
    which graph's tool node uses) started on it and stopped at the end."""
    from course_lib.ros import session

    with rosenv.reserve_domain_id() as reservation:
        session.stop()
        session.start(domain_id=reservation.domain_id)
        try:
            yield reservation.domain_id
        finally:
            session.stop()


@pytest.fixture(autouse=True, scope="module")
def _no_session_left_running():
    """Every test module ends with the notebook session stopped. Tests that drive a notebook from
    the test's process (the browser tests) start it on the run's domain; left running, it made the
    next module in that worker fail at session.start(domain_id=N) ("already runs on domain 101")."""
    yield
    import sys

    session = sys.modules.get("course_lib.ros.session")
    if session is not None and session.is_running():
        session.stop()


@pytest.fixture
def domain_id():
    """A ROS domain id reserved for one test, for tests that need traffic nobody else sees.

    A notebook session the test started on it is stopped with the reservation: left running, its
    tool node showed up in the next test's domain of the same id (a self-check in a suite run
    took `_course_tools` for the student's node)."""
    from course_lib.ros import session

    with rosenv.reserve_domain_id() as reservation:
        try:
            yield reservation.domain_id
        finally:
            if session.domain_id() == reservation.domain_id:
                session.stop()


#: The test files that take longest (whole grading runs, JupyterLab in Chromium), longest first
#: (a folder ending in "/" stands for its files):
#: a long file started last ends the suite last. With `--dist loadfile` xdist hands out files in
#: collection order only under `--no-loadscope-reorder` (make test and make check pass it); by default it
#: hands out the files with the most tests first (tests/course_lib/launch/test_launch_parser.py), and
#: the hub and the lessons in Chromium started 7-8 minutes into an 11-minute run.
LONGEST_FIRST = (
    "tests/autograder/test_term.py",
    "tests/browser/test_browser.py",
    "tests/assignments/test_autograder_zoo.py",
    "notebooks/",  # the lessons under nbmake, one file each
    "tests/coursehub/test_hub.py",
    "tests/course_lib/ros2cli/test_ros2cli_interface_builds.py",
    "tests/browser/test_browser_validate.py",
    "tests/assignments/test_autograder.py",
    "tests/lessons/test_lesson_commands.py",
    "tests/assignments/test_autograder_pipeline.py",
    # make check's longest (the files above are left out of it)
    "tests/course_lib/imaging/test_photos.py",
    "tests/course_lib/ros2cli/test_ros2cli.py",
    "tests/course_lib/ros2cli/test_ros2cli_daemon.py",
    "tests/course_lib/checks/test_lock_step.py",
    "tests/course_lib/imaging/test_scenes.py",
    "tests/course_lib/ros2cli/test_ros2cli_service.py",
)


def pytest_collection_modifyitems(items):
    """Move the items of LONGEST_FIRST to the front, in that order (the rest keep theirs)."""
    def rank(item):
        name = item.path.relative_to(item.config.rootpath).as_posix()
        for place, first in enumerate(LONGEST_FIRST):
            if name == first or (first.endswith("/") and name.startswith(first)):
                return place
        return len(LONGEST_FIRST)

    items.sort(key=rank)


@pytest.hookimpl(wrapper=True)
def pytest_runtest_call(item):
    """nbmake's run of a lesson gets a ROS domain of its own, keeps the executed notebook
    (artifacts/lessons/) and fails on what a student would see wrong in its outputs (support.lesson_runs)."""
    from support import lesson_runs  # tests/ is on the path (pyproject's pythonpath)

    if not lesson_runs.is_lesson(item):
        return (yield)
    with lesson_runs.own_domain(), lesson_runs.keeping_executed(item) as kept:
        outcome = yield
    found = lesson_runs.problems(item.path.name, kept[0])
    if found:
        raise lesson_runs.failure(item.path, kept[0], found)
    return outcome
