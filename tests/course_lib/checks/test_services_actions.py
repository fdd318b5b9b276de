"""Tests for course_lib.checks.services_actions's verdicts on the answers a node gives (the
checks themselves run against real nodes in tests/assignments/test_autograder_zoo.py)."""

from course_lib.checks import services_actions
from course_lib.imaging import marker_board, pan_camera

#: Angles where a detector may find markers or miss them (pan_camera.uncertain_markers), and
#: angles without any doubt.
UNCERTAIN = (-31.6, -26.8, -24.5, -14.75, -14.6, 14.5, 14.75, 24.5, 26.8, 31.6)
CERTAIN = (-40.0, -25.0, -10.0, 0.0, 7.5, 20.0)


def detected(pan: float) -> tuple[list[int], list[str]]:
    """The markers OpenCV's ArUco detector finds in the frame at `pan`, and the pictures they frame."""
    _, ids, _ = marker_board.detector().detectMarkers(pan_camera.frame_at(pan))
    found = sorted(int(i) for i in ids.ravel()) if ids is not None else []
    return found, [name for name, markers in marker_board.PICTURES.items() if set(markers) <= set(found)]


def test_a_node_that_answers_what_a_detector_finds_is_never_wrong():
    for pan in UNCERTAIN + CERTAIN:
        ids, framed = detected(pan)
        assert services_actions.ids_wrong(pan, ids, "the response's") is None, (pan, ids)
        assert services_actions.framed_wrong(pan, framed) is None, (pan, framed)


def test_uncertain_markers_count_neither_way():
    """At -14.6 a detector may or may not find the dog's markers 6 and 7, so either answer is right."""
    assert services_actions.ids_wrong(-14.6, [1, 2, 3, 4, 5, 8], "the response's") is None
    assert services_actions.ids_wrong(-14.6, [1, 2, 3, 4, 5, 6, 7, 8], "the response's") is None
    assert services_actions.framed_wrong(-14.6, ["cat"]) is None
    assert services_actions.framed_wrong(-14.6, ["cat", "dog"]) is None


def test_a_marker_in_view_left_out_or_one_out_of_view_named_is_wrong():
    why = services_actions.ids_wrong(-14.6, [1, 2, 3, 5, 8], "the response's")
    assert why == ("at pan -14.6 the response's ids are [1, 2, 3, 5, 8], the markers in view are "
                   "[1, 2, 3, 4, 5, 8] (a detector may find [6, 7] too, or not)")
    assert "the markers in view are [1, 2, 3, 4]" in services_actions.ids_wrong(-25, [1, 2, 3, 4, 5], "the feedback's")
    assert services_actions.ids_wrong(0, [8, 7, 6, 5, 4, 3, 2, 1], "the response's").endswith("once, ascending")
    assert services_actions.framed_wrong(-25, []) == ("at pan -25 the response's framed is [], "
                                                      "the pictures framed are ['cat']")
    assert "in the order ['cat', 'dog']" in services_actions.framed_wrong(0, ["dog", "cat"])


def test_the_feedback_expected_ends_where_the_node_stopped():
    start = -54.6
    steps = pan_camera.search_pans(start, ["dog"])
    early, last = pan_camera.search_stops(start, ["dog"])
    assert services_actions.stops_at(start, steps, early) == len(steps) - 1
    assert services_actions.stops_at(start, steps, last) == len(steps)
    assert services_actions.stops_at(0.0, [], 0.0) == 0


#: A node as the untouched release makes it: the node exists, then its __init__ raises (here once
#: the test has seen the node, so that the order does not depend on the machine's speed).
RAISES_AFTER_START = """
import pathlib, sys, time
import rclpy
from rclpy.node import Node
rclpy.init()
node = Node('pan_camera')
go = pathlib.Path(sys.argv[1])
deadline = time.monotonic() + 60
while not go.exists() and time.monotonic() < deadline:
    time.sleep(0.05)
raise NotImplementedError('replace this line with your code')
"""


def test_a_node_that_raises_after_it_appeared_did_not_start_and_shows_no_tick(tmp_path):
    """The untouched release's node appears, then raises in __init__: the check's one failure is
    the process's end with its error, and no item says the node runs."""
    import sys

    from course_lib.checks import packages, registry
    from course_lib.checks.context import Context

    ctx = Context(registry.get_check("services_actions", "action"), 1, tmp_path, tmp_path)
    go = tmp_path / "go"
    try:
        proc = ctx.students.start([sys.executable, "-c", RAISES_AFTER_START, str(go)], name="student-raises",
                                  cwd=tmp_path, domain_id=ctx.domain_id, wall_seconds=120)
        with ctx.probe() as probe:
            assert packages.wait_node(ctx, probe, proc, "pan_camera")
            assert ctx.items == [{"ok": True, "message": "node pan_camera runs", "weight": 0.0}]
            go.touch()
            proc.wait(60)
            assert not services_actions._endpoint_item(ctx, probe, proc, services_actions.ACTION,
                                                       services_actions.ACTION_TYPE, "action")
    finally:
        ctx.close()
    (item,) = ctx.items
    assert not item["ok"] and item["message"].startswith(
        "the process ended (exit code 1) before node pan_camera offered action /find_pictures:")
    assert "NotImplementedError: replace this line with your code" in item["message"]
