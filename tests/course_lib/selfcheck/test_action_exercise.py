"""Tests for course_lib.selfcheck.action_exercise: lesson 04's action client exercise, judged
against the check's own FindPictures server in a real session (the reference camera_interfaces,
built once per test run into the tests' interface cache)."""


import pytest
from support import course as course_support

from course_lib import selfcheck
from course_lib.ros import session

pytestmark = pytest.mark.slow  # the first run on a machine builds camera_interfaces (CMake)


@pytest.fixture(scope="module")
def find_pictures_type(tmp_path_factory, session_domain):
    from course_lib.ros import workspace

    for install in course_support.reference_interface_installs(tmp_path_factory, "services_actions"):
        workspace.use_workspace(install.parent)
    from camera_interfaces.action import FindPictures

    return FindPictures


def client(keep_feedback: bool = True, mistake: str = ""):
    """A find_pictures as the lesson asks for it, or one whose feedback callback keeps nothing, or
    with a `mistake` of waiting for the result: "future" returns get_result_async()'s future,
    "no_wait" reads its future.result().result before the future is done."""
    def find_pictures(node, pictures, action_name="/find_pictures"):
        from camera_interfaces.action import FindPictures
        from rclpy.action import ActionClient

        pans = []
        action = ActionClient(node, FindPictures, action_name)
        session.wait_for(action.server_is_ready, timeout=10)
        def keep(message):
            if keep_feedback:
                pans.append(message.feedback.pan)

        sent = action.send_goal_async(FindPictures.Goal(pictures=pictures), feedback_callback=keep)
        session.wait_for(sent.done, timeout=10)
        ended = sent.result().get_result_async()
        if mistake == "future":
            return ended, pans
        if mistake == "no_wait":
            return ended.result().result, pans
        session.wait_for(ended.done, timeout=10)
        return ended.result().result, pans
    return find_pictures


def test_a_client_that_keeps_result_and_feedback_passes(find_pictures_type):
    verdict = selfcheck.find_pictures_exercise(client(), find_pictures_type)
    assert verdict.ok, verdict.text
    assert "the cat is framed at pan -25" in verdict.text


def test_the_stub_is_not_done_and_a_client_without_feedback_is_told_so(find_pictures_type):
    def stub(node, pictures, action_name="/find_pictures"):
        raise NotImplementedError

    assert "Not done yet" in selfcheck.find_pictures_exercise(stub, find_pictures_type).text
    assert "Not done yet" in selfcheck.find_pictures_exercise(None, find_pictures_type).text
    verdict = selfcheck.find_pictures_exercise(client(keep_feedback=False), find_pictures_type)
    assert not verdict.ok and "collect feedback.pan" in verdict.text, verdict.text


def test_a_result_not_waited_for_is_told_to_wait_for_the_future_first(find_pictures_type):
    """Returning get_result_async()'s future, or reading its result() before it is done (None),
    each gets its own message, and both say to wait for the future first."""
    verdict = selfcheck.find_pictures_exercise(client(mistake="future"), find_pictures_type)
    assert not verdict.ok and "the future of get_result_async(), not the result" in verdict.text, verdict.text
    assert "session.wait_for(future.done, timeout=10)" in verdict.text
    verdict = selfcheck.find_pictures_exercise(client(mistake="no_wait"), find_pictures_type)
    assert not verdict.ok and "'NoneType' object has no attribute 'result'" in verdict.text, verdict.text
    assert "result() is None until then: wait first (session.wait_for(future.done, timeout=10))" in verdict.text
