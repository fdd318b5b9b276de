"""A student's folder copied without following anything out of it (autograder.sandbox.untrusted): plain
files and folders are copied; a link, a FIFO, a hard link, another account's file, a name with a
control character, too many files or too many bytes refuse the whole folder with a reason, in
about no time, and leave no target behind."""

from __future__ import annotations

import os

import pytest

from autograder.sandbox import untrusted
from course_lib.checks.validate import IGNORE


def _submission(folder):
    (folder / "ros2_ws" / "src" / "pkg").mkdir(parents=True)
    (folder / "ros2_ws" / "src" / "pkg" / "setup.py").write_text("from setuptools import setup\n")
    (folder / "brightness.ipynb").write_text("{}")
    (folder / "__pycache__").mkdir()
    (folder / "__pycache__" / "x.pyc").write_bytes(b"\0")
    return folder


def test_plain_files_and_folders_are_copied_and_the_ignored_left_out(tmp_path):
    source = _submission(tmp_path / "in")
    untrusted.copy_tree(source, tmp_path / "out", ignore=IGNORE)
    copied = sorted(str(p.relative_to(tmp_path / "out")) for p in (tmp_path / "out").rglob("*"))
    assert copied == ["brightness.ipynb", "ros2_ws", "ros2_ws/src", "ros2_ws/src/pkg", "ros2_ws/src/pkg/setup.py"]
    assert (tmp_path / "out" / "ros2_ws" / "src" / "pkg" / "setup.py").read_text() == "from setuptools import setup\n"


def _refusal(source, target, **limits) -> str:
    with pytest.raises(untrusted.Refused) as refused:
        untrusted.copy_tree(source, target, ignore=IGNORE, limits=untrusted.Limits(**limits) if limits else None)
    assert not os.path.lexists(target), "a refused folder leaves no copy"
    assert not [p for p in target.parent.iterdir() if p.name.startswith(f".{target.name}")], "nor a staging folder"
    return str(refused.value)


@pytest.mark.parametrize("where", ["setup.py", "notes.txt"])
def test_a_link_to_a_file_outside_is_refused_not_followed(tmp_path, where):
    secret = tmp_path / "secret.txt"
    secret.write_text("the instructor's solution")
    source = _submission(tmp_path / "in")
    link = source / "ros2_ws" / "src" / "pkg" / where
    link.unlink(missing_ok=True)
    link.symlink_to(secret)
    message = _refusal(source, tmp_path / "out")
    assert f"'ros2_ws/src/pkg/{where}' in your submission is a symbolic link" in message
    assert "the instructor's solution" not in message


def test_a_linked_folder_and_a_submission_that_is_a_link_are_refused(tmp_path):
    elsewhere = _submission(tmp_path / "elsewhere")
    source = _submission(tmp_path / "in")
    (source / "more").symlink_to(elsewhere)
    assert "'more' in your submission is a symbolic link" in _refusal(source, tmp_path / "out")
    (tmp_path / "linked").symlink_to(elsewhere)
    assert "is a symbolic link, not a folder" in _refusal(tmp_path / "linked", tmp_path / "out")


def test_a_fifo_is_refused_without_blocking(tmp_path):
    source = _submission(tmp_path / "in")
    os.mkfifo(source / "brightness.py")
    assert "'brightness.py' in your submission is a FIFO" in _refusal(source, tmp_path / "out")


def test_a_hard_link_is_refused(tmp_path):
    source = _submission(tmp_path / "in")
    os.link(source / "brightness.ipynb", tmp_path / "elsewhere.ipynb")
    assert "is a hard link (the same file under 2 names)" in _refusal(source, tmp_path / "out")


@pytest.mark.skipif(os.geteuid() != 0, reason="giving a file to another account needs root")
def test_a_file_of_another_account_is_refused(tmp_path):
    source = _submission(tmp_path / "in")
    os.chown(source / "brightness.ipynb", 64980, 64980)
    with pytest.raises(untrusted.Refused, match="'brightness.ipynb' in your submission belongs to another account"):
        untrusted.copy_tree(source, tmp_path / "out", owner=os.geteuid(), ignore=IGNORE)
    os.chown(source / "brightness.ipynb", os.geteuid(), os.getegid())
    untrusted.copy_tree(source, tmp_path / "out", owner=os.geteuid(), ignore=IGNORE)


def test_a_name_with_a_newline_is_refused(tmp_path):
    source = _submission(tmp_path / "in")
    (source / "bad\nname.py").write_text("")
    assert "The name 'bad\\nname.py' in your submission has a control character" in _refusal(source, tmp_path / "out")


def test_too_many_files_or_bytes_are_refused(tmp_path):
    source = _submission(tmp_path / "in")
    for n in range(20):
        (source / f"f{n}.txt").write_text("x" * 100)
    assert "more than 10 files and folders" in _refusal(source, tmp_path / "out", max_files=10)
    assert "more than 0.001 MB (at 'f" in _refusal(source, tmp_path / "out", max_bytes=1000)
    untrusted.copy_tree(source, tmp_path / "out", ignore=IGNORE, limits=untrusted.Limits(max_bytes=3000, max_files=30))


def test_checking_alone_copies_nothing(tmp_path):
    source = _submission(tmp_path / "in")
    before = sorted(tmp_path.iterdir())
    untrusted.copy_tree(source, None, ignore=IGNORE)
    assert sorted(tmp_path.iterdir()) == before


def test_an_entry_is_read_as_what_it_is_without_following_or_blocking(tmp_path):
    """read_entry (the digests of a kernel-written workspace): a link by its target, a file by its
    bytes, a FIFO as 'other' without blocking."""
    (tmp_path / "secret").write_text("root's")
    (tmp_path / "file").write_text("mine")
    (tmp_path / "link").symlink_to(tmp_path / "secret")
    os.mkfifo(tmp_path / "fifo")
    assert untrusted.read_entry(tmp_path / "file") == ("file", b"mine")
    assert untrusted.read_entry(tmp_path / "link") == ("link", str(tmp_path / "secret").encode())
    assert untrusted.read_entry(tmp_path / "fifo") == ("other", b"")
