"""Tests for course_lib.selfcheck: stubs get 'not done yet', wrong answers a specific hint."""

import pytest
from rclpy.node import Node
from std_msgs.msg import Int32, String

from course_lib import graph, selfcheck, session


@pytest.fixture
def my_node(monkeypatch):
    monkeypatch.setattr(graph, "SETTLE_SECONDS", 0)  # in-process nodes need no discovery wait
    session.start()
    node = session.add_node(Node("my_node"))
    yield node
    session.stop()


@pytest.mark.parametrize("stub", [None, ..., "...", ""])
def test_task1_stub_is_not_done_yet(stub):
    verdict = selfcheck.task1_node_name(stub)
    assert not verdict and "Not done yet" in str(verdict) and "graph.node_list()" in str(verdict)


def test_task1_accepts_the_listed_name(my_node):
    verdict = selfcheck.task1_node_name("/my_node")
    assert verdict and str(verdict).startswith("✔")


def test_task1_missing_slash_gets_the_namespace_hint(my_node):
    verdict = selfcheck.task1_node_name("my_node")
    assert not verdict and "Write '/my_node'" in str(verdict)


def test_task1_someone_elses_node(my_node):
    session.add_node(Node("other"))
    verdict = selfcheck.task1_node_name("/other")
    assert not verdict and "not yours" in str(verdict)


def test_task1_node_not_running(monkeypatch):
    monkeypatch.setattr(graph, "SETTLE_SECONDS", 0)
    session.start()
    try:
        verdict = selfcheck.task1_node_name("/my_node")
    finally:
        session.stop()
    assert not verdict and "is it still running?" in str(verdict)


def test_task2_verdicts():
    assert "Not done yet" in str(selfcheck.task2_echo(None))
    assert "Nothing was echoed" in str(selfcheck.task2_echo([]))
    assert "carries std_msgs/msg/String" in str(selfcheck.task2_echo([Int32(data=3)]))
    assert "which the talker did not send" in str(selfcheck.task2_echo([String(data="hi")]))
    assert selfcheck.task2_echo([String(data="Hello World: 7")])
    assert selfcheck.task2_echo(String(data="Hello World: 7")), "a single message (not a list) is fine too"
