"""Tests for course_lib.ros.node_names: the full name a node gets, after its remaps."""

import pytest

from course_lib.ros import node_names


@pytest.mark.parametrize("args, expected", [
    (("talker",), "/talker"),
    (("talker", "robot1"), "/robot1/talker"),
    (("talker", "/robot1/"), "/robot1/talker"),
    (("talker", None, ["--ros-args", "-r", "__node:=news", "-r", "__ns:=/r2"]), "/r2/news"),
    (("talker", None, ["--ros-args", "-r", "talker:__node:=news"]), "/news"),
])
def test_expected_name(args, expected):
    assert node_names.expected_name(*args) == expected


def test_hidden_names_have_a_token_that_starts_with_an_underscore():
    assert node_names.is_hidden("/_course_tools") and node_names.is_hidden("/robot/_private/scan")
    assert not node_names.is_hidden("/robot_1/scan") and node_names.full_name("/", "talker") == "/talker"
