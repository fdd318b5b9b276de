"""coursehub.closed_repository.close_to_students on folders of a test's own: the course's group is denied them
(one made later is made, and closed), its instructor reads them, other accounts are not touched;
reopening leaves a folder as it was, with another course's entries kept and those of a course
removed by hand gone. System accounts stand in for the course's (nobody, daemon, bin, sys). Root
only (it opens as other uids); the hub's own test is tests/coursehub/test_hub.py."""

from __future__ import annotations

import grp
import os
import pwd
import shutil
import tempfile
from pathlib import Path

import pytest
from support.hub import opened_as

from coursehub import closed_repository
from coursehub import course as course_settings

pytestmark = pytest.mark.skipif(os.geteuid() != 0, reason="opens files as other uids: run as root")


def _course(group: str, instructor: str) -> course_settings.Course:
    return course_settings.Course(hub_dir=Path("/nonexistent"), course_id="c", group=group, instructor=instructor,
                                  students=[], exchange=Path("/nonexistent"))


@pytest.fixture
def closed(monkeypatch):
    """Folders other uids may enter (pytest's tmp_path is root's only) as the closed folders: one
    with a solution, one missing, and one made later."""
    top = Path(tempfile.mkdtemp(prefix="closed-folders-"))
    os.chmod(top, 0o755)
    folders = [top / "assignments", top / "missing", top / "made-later"]
    (folders[0] / "source").mkdir(parents=True)
    (folders[0] / "source" / "solution.py").write_text("answer = 42\n")
    monkeypatch.setattr(closed_repository, "closed_folders", lambda: folders)
    monkeypatch.setattr(closed_repository, "made_later", lambda: folders[2:])
    yield folders[0]
    shutil.rmtree(top)


def test_the_courses_group_is_denied_its_instructor_reads_and_nobody_else_changes(closed):
    student = pwd.getpwnam("nobody")
    course = _course(grp.getgrgid(student.pw_gid).gr_name, "daemon")
    inside = [str(closed), str(closed / "source" / "solution.py"), str(closed.parent / "made-later")]
    assert closed_repository.close_to_students(course) == []
    assert not (closed.parent / "missing").exists()
    assert opened_as("nobody", inside) == []
    assert opened_as("daemon", inside) == inside
    assert opened_as("bin", inside) == inside
    assert (os.stat(closed).st_mode & 0o777) == 0o755


def test_reopening_leaves_the_folder_as_it_was_and_another_courses_entries_in_place(closed):
    gone = next(gid for gid in range(59999, 50000, -1) if not _exists(grp.getgrgid, gid))
    closed_repository._write_acl(closed, {**closed_repository._read_acl(closed), (closed_repository._GROUP, gone): 0})
    first, second = _course(grp.getgrgid(pwd.getpwnam("nobody").pw_gid).gr_name, "daemon"), _course("bin", "sys")
    closed_repository.close_to_students(first)
    closed_repository.close_to_students(second)
    named = {key for key in closed_repository._read_acl(closed) if key[0] in (closed_repository._USER,
                                                                             closed_repository._GROUP)}
    assert (closed_repository._GROUP, gone) not in named and len(named) == 4, named  # a removed course's entry goes
    closed_repository.reopen_to_students(first)
    assert opened_as("bin", [str(closed)]) == [] and opened_as("nobody", [str(closed)]) == [str(closed)]
    closed_repository.reopen_to_students(second)
    with pytest.raises(OSError):  # no ACL left: the mode alone, as before
        os.getxattr(closed, "system.posix_acl_access")
    assert (os.stat(closed).st_mode & 0o777) == 0o755


def _exists(lookup, number: int) -> bool:
    try:
        lookup(number)
    except KeyError:
        return False
    return True
