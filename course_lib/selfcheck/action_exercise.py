"""The exercise of lesson 04: an action client, a function that sends a FindPictures goal and
keeps the feedback, judged against an action server the check runs in the notebook's session.

The check's server is a real rclpy ActionServer under an action name of its own (so the lesson's
``/find_pictures`` process is not disturbed); it turns a pan camera of its own from CHECK_START
and publishes feedback after each step, a step taking STEP_SECONDS as in the lesson's server (a
burst of feedback without pause loses messages in rclpy's action client: about 1 s in all).
"""

from __future__ import annotations

from course_lib import progress
from course_lib.imaging import pan_camera
from course_lib.ros import teardown
from course_lib.selfcheck.verdicts import Verdict, _not_a_function, _verdict

#: The check's own action name, and where its camera starts (the lesson's START_PAN).
CHECK_ACTION = "/selfcheck/find_pictures"
CHECK_START = pan_camera.START_PAN


class _CheckServer:
    """A FindPictures server at CHECK_ACTION, spun by an executor of its own in a thread (so its
    execute may take the head's STEP_SECONDS per step, as the lesson's server does, without
    holding up the session's executor, which runs the student's client); close() ends it."""

    def __init__(self, action_type):
        import threading

        from rclpy.action import ActionServer
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node

        from course_lib.ros import session

        session.start()  # the default context the student's client uses
        self.pan = CHECK_START
        self.action_type = action_type
        self.node = Node("selfcheck_find_pictures")
        self.server = ActionServer(self.node, action_type, CHECK_ACTION, self.execute)
        self.executor = SingleThreadedExecutor(context=self.node.context)
        self.executor.add_node(self.node)
        self.thread = threading.Thread(target=self.executor.spin, name="selfcheck.find_pictures", daemon=True)
        self.thread.start()

    def execute(self, goal_handle):
        import time

        for pan in pan_camera.search_pans(self.pan, goal_handle.request.pictures):
            time.sleep(pan_camera.STEP_SECONDS)  # the head turning (its feedback comes a step apart)
            self.pan = pan
            goal_handle.publish_feedback(self.action_type.Feedback(pan=pan, ids=list(pan_camera.markers_in_view(pan))))
        goal_handle.succeed()
        return self.action_type.Result(pan=self.pan, framed=list(pan_camera.framed_at(self.pan)))

    def close(self) -> None:
        self.executor.shutdown(timeout_sec=2.0)
        self.thread.join(timeout=2.0)
        teardown.destroy_node(self.node)  # with its action server


#: How the lesson waits for a future (the notebook's session spins the node meanwhile).
_WAIT = "session.wait_for(future.done, timeout=10)"


def _not_the_result(answer) -> str:
    """Why the first of the returned pair is not the goal's result, and the fix."""
    from rclpy.task import Future

    if isinstance(answer, Future):
        return (f"The first of the pair is the future of get_result_async(), not the result: the result comes "
                f"later. Wait until the future is done ({_WAIT}), then return future.result().result.")
    if hasattr(answer, "status") and hasattr(answer, "result"):
        return (f"The first of the pair is the answer to get_result (status {answer.status}) that holds the "
                "result: return its .result, the FindPictures result.")
    return (f"The first of the pair is {answer!r}, not the goal's result: wait until get_result_async()'s "
            f"future is done ({_WAIT}), then return future.result().result.")


def _unfinished_future(error: Exception) -> str:
    """The fix when `error` is what reading an unfinished future gives (its result() is None)."""
    if isinstance(error, AttributeError) and str(error).startswith("'NoneType' object has no attribute"):
        return (". Is it a future's result() read before the future was done? result() is None until then: "
                f"wait first ({_WAIT}), after send_goal_async and again after get_result_async.")
    return ""


@progress.while_running("self-check: sending your goal")
def find_pictures_exercise(find_pictures, action_type) -> Verdict:
    """Exercise (lesson 04): ``find_pictures(node, pictures, action_name)`` sends a FindPictures
    goal, waits for its result and returns ``(result, pans)``: the result message and the ``pan``
    of every feedback message, in order. The check calls it with a server of its own."""
    from course_lib.ros import session

    hint = ("Write find_pictures(node, pictures, action_name): an ActionClient on the node, send_goal_async with "
            "a feedback_callback that appends feedback.pan to a list; wait until its future is done "
            f"({_WAIT}); then get_result_async() on the goal handle, wait again until that future is done, "
            "and return (future.result().result, pans).")
    if (problem := _not_a_function(find_pictures, "find_pictures", hint)) is not None:
        return problem
    server = _CheckServer(action_type)
    client_node = None
    try:
        from rclpy.node import Node

        client_node = session.add_node(Node("selfcheck_find_pictures_client"))
        expected = pan_camera.search_pans(CHECK_START, ["cat"])
        try:
            answer = find_pictures(client_node, ["cat"], CHECK_ACTION)
        except NotImplementedError:
            return _verdict(False, "Not done yet: replace the raise NotImplementedError with your code. " + hint)
        except Exception as error:  # a check never raises on a wrong answer
            return _verdict(False, f"find_pictures(node, ['cat'], {CHECK_ACTION!r}) raised "
                                   f"{type(error).__name__}: {error}" + _unfinished_future(error))
        if not (isinstance(answer, tuple) and len(answer) == 2):
            return _verdict(False, f"find_pictures returned {answer!r}; return a pair (result, pans).")
        result, pans = answer
        if not hasattr(result, "pan") or not hasattr(result, "framed"):
            return _verdict(False, _not_the_result(result))
        if not isinstance(pans, list) or not pans:
            return _verdict(False, f"The second of the pair is {pans!r}: collect feedback.pan of every feedback "
                                   "message in a list (the feedback_callback gets a message whose .feedback has it).")
        # Feedback (a topic) and the result (a service) travel apart: the last feedback message
        # may reach the callback just after find_pictures returned, into the same list.
        session.wait_for(lambda: len(pans) >= len(expected), timeout=5.0)
        if [round(p, 6) for p in pans] != [round(p, 6) for p in expected]:
            return _verdict(False, f"The feedback pans were {[round(p, 1) for p in expected]}, your list holds "
                                   f"{[round(p, 1) for p in pans]}: append feedback.pan once per feedback message.")
        if abs(result.pan - expected[-1]) > 1e-6 or "cat" not in result.framed:
            return _verdict(False, f"The result you returned says pan {result.pan:g}, framed {list(result.framed)}; "
                                   f"the server's result was pan {expected[-1]:g} with the cat framed.")
        return _verdict(True, f"find_pictures sent {{pictures: [cat]}}, kept {len(pans)} feedback pans "
                              f"({pans[0]:g} ... {pans[-1]:g}) and returned the result: the cat is framed at pan "
                              f"{result.pan:g}. In a terminal: ros2 action send_goal --feedback ...")
    finally:
        server.close()
        if client_node is not None:
            try:
                session.remove_node(client_node)
            except ValueError:  # the student's code removed it already
                pass
