"""coursehub's parts that need no hub: the doors of a student's namespace (forward), user names
from a roster (accounts), the course's settings (course). The hub itself: tests/coursehub/test_hub.py."""

from __future__ import annotations

import asyncio
import os
import pwd

import pytest

from coursehub import accounts, course, forward


async def _echo_server(folder):
    """An upper-casing server on loopback, and the two doors in front of it as on the hub."""
    async def upper(reader, writer):
        data = await reader.read()  # to EOF: the client's half-close must come through
        writer.write(data.upper())
        await writer.drain()
        writer.close()

    server = await asyncio.start_server(upper, "127.0.0.1", 0)
    inner = await forward.unix_to_tcp(f"{folder}/server.sock", "127.0.0.1", server.sockets[0].getsockname()[1])
    return server, inner


async def _ask(port: int, text: bytes) -> bytes:
    reader, writer = await asyncio.open_connection("127.0.0.1", port)
    try:
        writer.write(text)
        writer.write_eof()
        return await asyncio.wait_for(reader.read(), 10)
    except ConnectionResetError:  # closed on us, unread bytes and all: no answer
        return b""
    finally:
        writer.close()


def test_bytes_and_the_half_close_pass_both_doors(tmp_path):
    async def run():
        server, inner = await _echo_server(tmp_path)
        outer = await forward.tcp_to_unix("127.0.0.1", 0, f"{tmp_path}/server.sock", owner=os.getuid())
        try:
            return await _ask(outer.sockets[0].getsockname()[1], b"chatter" * 100_000)
        finally:
            for each in (server, inner, outer):
                each.close()

    assert asyncio.run(run()) == b"CHATTER" * 100_000


def test_the_hubs_door_refuses_a_symlink_in_place_of_the_students_socket(tmp_path):
    async def run():
        server, inner = await _echo_server(tmp_path)
        os.symlink(f"{tmp_path}/server.sock", f"{tmp_path}/link.sock")
        outer = await forward.tcp_to_unix("127.0.0.1", 0, f"{tmp_path}/link.sock", owner=os.getuid())
        try:
            return await _ask(outer.sockets[0].getsockname()[1], b"chatter")
        finally:
            for each in (server, inner, outer):
                each.close()

    assert asyncio.run(run()) == b""


def test_the_unix_door_has_the_mode_it_was_given(tmp_path):
    async def run():
        door = await forward.unix_to_tcp(f"{tmp_path}/hub.sock", "127.0.0.1", 9, mode=0o666)
        door.close()

    asyncio.run(run())
    assert os.stat(tmp_path / "hub.sock").st_mode & 0o777 == 0o666


@pytest.mark.parametrize("name", ["1alice", "Alice", "a/b", "alice smith", "", "a" * 33])
def test_an_id_that_cannot_be_a_linux_user_name_is_refused_with_the_fix(name):
    with pytest.raises(ValueError, match="prefix the roster's ids"):
        accounts.check_name(name)


def test_a_hub_directory_without_a_course_names_the_command_that_creates_it(tmp_path):
    with pytest.raises(FileNotFoundError, match="python -m coursehub create-course"):
        course.load(tmp_path)


def test_course_settings_survive_a_save_and_a_load(tmp_path):
    saved = course.Course(hub_dir=tmp_path, course_id="c", group="g", instructor="teacher", students=["s1", "s2"],
                          exchange=tmp_path / "exchange", port=18000, hub_port=18081)
    saved.save()
    assert course.load(tmp_path) == saved
    assert os.stat(tmp_path / "course.json").st_mode & 0o777 == 0o600


def test_a_file_removed_while_a_tree_is_given_away_is_left_out(tmp_path, monkeypatch):
    """chown_tree lists a folder, then changes each owner: a file removed in between (SQLite's
    journal of another grading worker's write to the gradebook) is no error. It once failed a
    grading of the hub's service, whose submission then never got its feedback."""
    (tmp_path / "gradebook.db").write_text("")
    walk = os.walk

    def listed_before_the_journal_went(path):
        for directory, dirs, files in walk(path):
            yield directory, dirs, [*files, "gradebook.db-journal"]

    monkeypatch.setattr(os, "walk", listed_before_the_journal_went)
    me = pwd.getpwuid(os.getuid())
    accounts.chown_tree(tmp_path, me.pw_name)
    assert (tmp_path / "gradebook.db").stat().st_uid == me.pw_uid
