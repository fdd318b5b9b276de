"""Courses for the grading tests, with their costly set-up done once per test run instead of
once per test module.

- The release (nbgrader generate_assignment: about 8 s of CPU per assignment) is made once, of
  every assignment, and copied into each course; a course that releases fewer assignments gets
  the others taken out again (their release/ folder and their gradebook entry), which leaves what
  a release of just those assignments leaves.
- The reference interface packages (a CMake build each, 20-30 s of CPU) are built once into the
  interface cache of tests and benchmarks (autograder.builds.caches.local_cache) and copied into each
  course's own cache (COURSE_DIR/autograder/.interface-cache), where the grader finds them as if
  an earlier submission had built them: a submission with the reference .msg files then builds
  only its own packages. Courses of the same test run share nothing else.

Both are shared by the xdist workers of one run through a folder beside the workers' temporary
folders, under a file lock (the first worker that needs one makes it, the others wait for it).
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import shutil
from pathlib import Path

from course_lib.checks import assignments as specs

ASSIGNMENTS = tuple(sorted(specs.ASSIGNMENTS))


def shared_folder(tmp_path_factory) -> Path:
    """A folder every xdist worker of this test run sees (the parent of the workers' basetemp)."""
    base = tmp_path_factory.getbasetemp()
    folder = (base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "shared-courses"
    folder.mkdir(exist_ok=True)
    return folder


@contextlib.contextmanager
def locked(path: Path):
    """Hold an exclusive lock on the file `path` (made if missing), across the processes of the run."""
    with open(path, "a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def released_course(tmp_path_factory, course: Path, assignments: list[str]) -> Path:
    """COURSE as `autograder.term.release.release(course, assignments)` leaves it (no due dates)."""
    from nbgrader.api import Gradebook

    from autograder.term import release

    unknown = set(assignments) - set(ASSIGNMENTS)
    assert not unknown, f"course_support releases {ASSIGNMENTS}, not {sorted(unknown)}"
    shared = shared_folder(tmp_path_factory)
    template = shared / "released"
    with locked(shared / "released.lock"):
        if not (template / ".complete").is_file():
            shutil.rmtree(template, ignore_errors=True)
            release.release(template, list(ASSIGNMENTS))
            (template / ".complete").touch()
    course = Path(course)
    shutil.copytree(template, course, symlinks=True, dirs_exist_ok=True,
                    ignore=shutil.ignore_patterns(".complete"))
    others = sorted(set(ASSIGNMENTS) - set(assignments))
    for name in others:
        shutil.rmtree(course / "release" / name)
    if others:
        with Gradebook(f"sqlite:///{course / 'gradebook.db'}") as gb:
            for name in others:
                gb.remove_assignment(name)
    return course.resolve()


def seed_lab_exchange(tmp_path_factory, lab_root: Path) -> None:
    """The lab served from lab_root (``make lab``) with every assignment released into its own
    exchange, from this run's shared release, unless it already is: ``make lab``'s release-lab
    then finds nothing to do (its own release is tested in tests/browser/test_browser_validate.py)."""
    from autograder.term import release
    from course_lib.notebook.student_lab.exchange import local_course, local_exchange

    course, exchange = local_course(lab_root), local_exchange(lab_root)
    if all(release.released_as_is(course, exchange, name) for name in ASSIGNMENTS):
        return
    released_course(tmp_path_factory, course, list(ASSIGNMENTS))
    release.release_to_exchange(course, exchange, list(ASSIGNMENTS))


def seed_interface_cache(tmp_path_factory, course: Path, assignments: list[str]) -> None:
    """Put the assignments' reference interface packages, built once, into COURSE's interface cache."""
    from autograder.builds import caches, workspace_build
    from autograder.builds.reference import REFERENCE_SRC

    cache, target = caches.local_cache(), caches.cache_of(course)
    for assignment in assignments:
        reference_interface_installs(tmp_path_factory, assignment)
    for assignment in assignments:
        for name in specs.spec(assignment).packages:
            folder = REFERENCE_SRC / name
            if workspace_build.is_interface_package(folder):
                key = caches.content_key(folder)
                if not target.entry(key).exists():
                    shutil.copytree(cache.entry(key), target.entry(key), symlinks=True)


def reference_interface_installs(tmp_path_factory, assignment: str) -> list[Path]:
    """The install folders of the assignment's reference interface packages, built once into the
    interface cache of tests and benchmarks (the first worker that needs them builds them)."""
    from autograder.builds import caches, workspace_build

    shared = shared_folder(tmp_path_factory)
    with locked(shared / "interface-cache.lock"):
        return workspace_build.reference_interfaces(assignment, caches.local_cache(), shared / "interface-scratch")
