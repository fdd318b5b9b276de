"""The services_actions assignment: its spec, its notebook's words and its checks (the pan camera's
service and action, in a package).

The contract is the notebook's introduction (SERVICES_ACTIONS_INTRO). The expected answers are the
simulation's own (course_lib.pan_camera), for angles and start angles drawn from the check's seed. A
node may look with a real detector instead: the markers a detector may find or miss at an angle
(pan_camera.uncertain_markers) count neither way, nor do the pictures they frame, and a search may
stop where such a picture is first framed (pan_camera.search_stops). The checker's nodes use the
reference interfaces.
"""

from __future__ import annotations

import math

from course_lib.checks import packages
from course_lib.checks.context import Context, scaled
from course_lib.checks.registry import check
from course_lib.checks.spec import Assignment, NotebookText

# --- the notebook's words (markdown) and the spec ----------------------------------------

SERVICES_ACTIONS_INTRO = """
# Assignment: the pan camera's service and action

The camera of Lesson 04 sits on a pan head in front of the marker board (`course_lib.pan_camera`):
turned to `pan` degrees (positive to the right) it sees some of the board's markers, and at about
0 degrees both pictures. You write the node that offers what Lesson 04 taught: a service that answers
a question at once, and an action that takes a while, reports its progress and can be canceled.

**Contract** (this is exactly what is graded). Your workspace `ros2_ws/src` holds two packages:

1. **`camera_interfaces`** (given, as built in Lesson 04): `srv/MarkersInView.srv` and
   `action/FindPictures.action`.
2. **`pan_camera`** (`ament_python`, depending on `rclpy` and `camera_interfaces`) with the
   executable **`pan_camera_node`** (`pan_camera/pan_camera_node.py`, class `PanCameraNode`, node
   **`pan_camera`**), whose camera starts at the parameter **`start_pan`** (degrees; default
   `pan_camera.START_PAN`):
   - the service **`markers_in_view`** (`camera_interfaces/srv/MarkersInView`): for the request's
     `pan`, `ids` = `markers_in_view(pan)`, `framed` = `framed_at(pan)` (as lists), `success` true and
     a short `message`; asking does not turn the camera;
   - the action **`find_pictures`** (`camera_interfaces/action/FindPictures`): from where the camera
     is, turn `STEP_DEGREES` (5) per step, one step per `STEP_SECONDS` (0.1 s), until every picture
     of the goal's `pictures` (empty: both) is framed; after each step publish feedback (`pan`, and the
     `ids` in view there); then succeed with the result `pan` and `framed`. A goal naming another
     picture is rejected. A cancel request is accepted, and the search stops before its next step
     (status CANCELED, the result where it stopped): the service and cancel requests must be served
     while a goal runs (a `ReentrantCallbackGroup`, spun by the `MultiThreadedExecutor` that `main`
     already uses).

The grader builds your workspace, starts `ros2 run pan_camera pan_camera_node` (with `-p
start_pan:=...` for the action) in a ROS domain of its own, asks the service about angles it draws
fresh, sends goals from start angles it draws fresh, and compares with what `course_lib.pan_camera`
says the camera sees. Try your node from a terminal, as in Lesson 04:
`ros2 service call /markers_in_view camera_interfaces/srv/MarkersInView "{pan: -10.0}"` and
`ros2 action send_goal --feedback /find_pictures camera_interfaces/action/FindPictures "{pictures: [cat]}"`.
"""

#: The spec: what assignments/build.py, the grader and the checks below read about it.
SPEC = Assignment("services_actions", "04", {"camera_interfaces": (), "pan_camera": ("pan_camera_node",)},
       NotebookText(intro=SERVICES_ACTIONS_INTRO, plain_ros=(
           "In plain ROS 2 the packages come from `ros2 pkg create --build-type ament_cmake camera_interfaces` "
           "(then the edits of Lesson 04) and `ros2 pkg create --build-type ament_python --dependencies rclpy "
           "camera_interfaces --node-name pan_camera_node pan_camera`."),
           checks={"service": ("the service `markers_in_view`",),
                   "action": ("the action `find_pictures`",),
                   "cancel": ("canceling a goal",)}))
selfcheck, grade = SPEC.selfcheck, SPEC.grade  # what the notebook calls: checks.selfcheck("...")

INTERFACES, PACKAGE = SPEC.packages
EXECUTABLE = SPEC.executable(PACKAGE)
NODE = "pan_camera"
SERVICE = "/markers_in_view"
SERVICE_TYPE = "camera_interfaces/srv/MarkersInView"
ACTION = "/find_pictures"
ACTION_TYPE = "camera_interfaces/action/FindPictures"
#: Angles the service is asked about per check: most near the board, one past 180 degrees (wrapped).
SERVICE_QUESTIONS = 6


def _start(ctx, start_pan: float | None = None):
    """``ros2 run pan_camera pan_camera_node [--ros-args -p start_pan:=...]``, and its node in the graph."""
    args = () if start_pan is None else ("-p", f"start_pan:={start_pan:.1f}")
    return packages.run(ctx, PACKAGE, EXECUTABLE, *args)


def _endpoint_item(ctx, probe, proc, name: str, wanted: str, kind: str) -> bool:
    """A precondition: the node offers `name` (a service or an action) of type `wanted`; else an
    item that names what it offers instead."""
    from rclpy.action import get_action_names_and_types

    def offered():
        if kind == "action":
            return dict(get_action_names_and_types(probe.node))
        return {n: t for n, t in probe.node.get_service_names_and_types() if not n.startswith(f"/{NODE}/")}

    probe.spin_until(lambda: name in offered() or not proc.running(), scaled(5.0))
    found = offered()
    if name not in found and packages.node_ended(ctx, proc, NODE, f"offered {kind} {name}"):
        return False
    if name not in found:
        others = sorted(n for n in found if not n.startswith("/autograder"))
        create = ("self.create_service(MarkersInView, 'markers_in_view', callback)" if kind == "service" else
                  "ActionServer(self, FindPictures, 'find_pictures', self.execute, ...)")
        return ctx.item(False, f"node {NODE} offers no {kind} {name} (it offers {others or 'none'}): {create}")
    if found[name] != [wanted]:
        return ctx.item(False, f"{kind} {name} is a {found[name]}; the contract says {wanted}")
    return ctx.precondition(True, f"{kind} {name} ({wanted})")


@check(points=4, timeout=60)
def service(ctx: Context) -> None:
    """markers_in_view answers success with the markers and pictures in view at angles drawn fresh."""
    proc = _start(ctx)
    packages.use_interfaces(ctx)
    from camera_interfaces.srv import MarkersInView

    packages.dependency_items(ctx, PACKAGE)
    pans = [round(float(ctx.rng.uniform(-25.0, 25.0)), 1) for _ in range(SERVICE_QUESTIONS - 1)]
    pans.append(round(float(ctx.rng.uniform(355.0, 365.0)), 1))  # the same as -5..5 degrees
    answers = []
    with ctx.probe() as probe:
        if not packages.wait_node(ctx, probe, proc, NODE) or not _endpoint_item(
                ctx, probe, proc, SERVICE, SERVICE_TYPE, "service"):
            return
        client = probe.node.create_client(MarkersInView, SERVICE)
        for pan in pans:
            future = client.call_async(MarkersInView.Request(pan=pan))
            ctx.waiting_on(f"the answer of {SERVICE} for pan {pan:g}")
            gives_up = ctx.no_answer_coming(proc, 5.0)
            probe.spin_until(lambda f=future, g=gives_up: f.done() or not proc.running() or g(), scaled(10.0))
            if not future.done():
                ctx.item(False, f"{SERVICE} did not answer pan {pan:g} "
                                f"({'the process ended' if not proc.running() else 'no answer'}): the callback must "
                                "return the response", weight=4)
                return
            answers.append(future.result())
    failed = [(pan, a) for pan, a in zip(pans, answers, strict=True) if not a.success]
    ctx.item(not failed, f"success true for all {len(pans)} angles" if not failed else
             f"pan {failed[0][0]:g} answered success=False ({failed[0][1].message!r}): set response.success = True "
             "when the question is answered")
    wrong_ids = [why for pan, a in zip(pans, answers, strict=True) if (why := ids_wrong(pan, a.ids, "the response's"))]
    ctx.item(not wrong_ids, f"ids right at all {len(pans)} angles ({', '.join(f'{p:g}' for p in pans)})"
             if not wrong_ids else f"{wrong_ids[0]}: response.ids = list(markers_in_view(request.pan))", weight=2)
    wrong_framed = [why for pan, a in zip(pans, answers, strict=True) if (why := framed_wrong(pan, a.framed))]
    ctx.item(not wrong_framed, "framed right at all angles" if not wrong_framed else
             f"{wrong_framed[0]}: response.framed = list(framed_at(request.pan))")


def ids_wrong(pan: float, ids, whose: str) -> str | None:
    """Why `ids` are not the markers in view at `pan` (None when they are): every marker in view
    must be there, and no other but those a detector may find or miss (pan_camera.uncertain_markers)."""
    from course_lib.imaging import pan_camera

    ids, sure, maybe = list(ids), list(pan_camera.markers_in_view(pan)), pan_camera.uncertain_markers(pan)
    if not set(sure) <= set(ids) <= set(sure) | set(maybe):
        return f"at pan {pan:g} {whose} ids are {ids}, the markers in view are {sure}" + _either_way(maybe)
    if ids != sorted(set(ids)):
        return f"at pan {pan:g} {whose} ids are {ids}: list each marker once, ascending"
    return None


def framed_wrong(pan: float, framed) -> str | None:
    """Why `framed` is not the pictures framed at `pan` (None when it is), the pictures a detector
    may find framed or not (pan_camera.maybe_framed_at) counting neither way."""
    from course_lib.imaging import pan_camera
    from course_lib.imaging.marker_board import PICTURES

    framed, sure, maybe = list(framed), list(pan_camera.framed_at(pan)), pan_camera.maybe_framed_at(pan)
    if not set(sure) <= set(framed) <= set(sure) | set(maybe):
        return f"at pan {pan:g} the response's framed is {framed}, the pictures framed are {sure}" + _either_way(maybe)
    if framed != [name for name in PICTURES if name in framed]:
        return f"at pan {pan:g} the response's framed is {framed}: each picture once, in the order {list(PICTURES)}"
    return None


def stops_at(start: float, steps: list[float], stop: float) -> int:
    """How many of a search's `steps` from `start` lead to `stop` (one of them, or `start`: 0)."""
    from course_lib.imaging import pan_camera

    return next(k for k, pan in enumerate([pan_camera.wrap(start), *steps]) if math.isclose(pan, stop, abs_tol=1e-6))


def _either_way(maybe) -> str:
    return f" (a detector may find {list(maybe)} too, or not)" if maybe else ""


def _send_goal(ctx, probe, proc, pictures, on_feedback):
    """(goal handle, None) once the node accepted a FindPictures goal, or (None, why not)."""
    from camera_interfaces.action import FindPictures
    from rclpy.action import ActionClient

    client = ActionClient(probe.node, FindPictures, ACTION)
    if not probe.spin_until(lambda: client.server_is_ready() or not proc.running(), scaled(10.0)):
        return None, f"the action server {ACTION} is not ready"
    sent = client.send_goal_async(FindPictures.Goal(pictures=list(pictures)),
                                  feedback_callback=lambda message: on_feedback(message.feedback))
    ctx.waiting_on(f"the answer to a goal sent to {ACTION}")
    probe.spin_until(lambda: sent.done() or not proc.running(), scaled(10.0))
    if not sent.done():
        return None, f"{ACTION} did not answer the goal (accepted or rejected): is the node spinning?"
    if not sent.result().accepted:
        return None, f"{ACTION} rejected the goal {{pictures: {list(pictures)}}}: accept goals that name cat or dog"
    return sent.result(), None


def _wait_result(ctx, probe, proc, handle, seconds: float, feedback: list):
    """The (status, result) of an accepted goal, or None when it does not end: when the node waits
    for `seconds` without a result or a new feedback message. Each feedback starts the wait
    again (the goal is moving), so a goal of many steps on a busy machine is not cut short for
    taking longer than its steps' sleeps add up to."""
    future = handle.get_result_async()
    ctx.waiting_on(f"the result of the goal sent to {ACTION}")
    waited = {"feedback": len(feedback), "gives_up": ctx.no_answer_coming(proc, seconds)}

    def gives_up() -> bool:
        if len(feedback) != waited["feedback"]:
            waited.update(feedback=len(feedback), gives_up=ctx.no_answer_coming(proc, seconds))
        return waited["gives_up"]()

    # The check's own time limit (scaled with the load) is the backstop, less a moment to report.
    probe.spin_until(lambda: future.done() or not proc.running() or gives_up(), max(1.0, ctx.remaining() - 2.0))
    if not future.done():
        return None
    return future.result().status, future.result().result


@check(points=5, timeout=90)
def action(ctx: Context) -> None:
    """find_pictures turns from a fresh start angle step by step, feedback after each, until the pictures are framed."""
    from action_msgs.msg import GoalStatus

    from course_lib.imaging import pan_camera

    start = round(float(ctx.rng.uniform(-58.0, -30.0)), 1)
    pictures = [["cat"], ["dog"], []][int(ctx.rng.integers(3))]
    expected = pan_camera.search_pans(start, pictures)
    stops = pan_camera.search_stops(start, pictures)
    proc = _start(ctx, start)
    packages.use_interfaces(ctx)
    feedback = []
    with ctx.probe() as probe:
        if not packages.wait_node(ctx, probe, proc, NODE) or not _endpoint_item(
                ctx, probe, proc, ACTION, ACTION_TYPE, "action"):
            return
        handle, why = _send_goal(ctx, probe, proc, pictures, feedback.append)
        if handle is None:
            ctx.item(False, why, weight=5)
            return
        seconds = len(expected) * pan_camera.STEP_SECONDS + 5.0
        ended = _wait_result(ctx, probe, proc, handle, seconds, feedback)
        # Feedback and result travel apart: the last feedback may come just after the result.
        probe.spin_until(lambda: len(feedback) >= len(expected) or not proc.running(), scaled(2.0))
    asked = f"{{pictures: {pictures}}} from start_pan {start:g}"
    if ended is None:
        ctx.item(False, f"the goal {asked} did not end: no result, and no new feedback for {seconds:.0f} s "
                        f"while the node waited ({len(feedback)} feedback messages): "
                        "call goal_handle.succeed() and return a FindPictures.Result() once the pictures are framed",
                 weight=2)
    else:
        status, result = ended
        ok = status == GoalStatus.STATUS_SUCCEEDED
        ctx.item(ok, f"the goal {asked} succeeded" if ok else
                 f"the goal {asked} ended with status {_STATUS.get(status, status)}: call goal_handle.succeed() when "
                 "the pictures are framed")
        stop = next((p for p in stops if math.isclose(result.pan, p, abs_tol=1e-6)), None)
        right = stop is not None and not framed_wrong(stop, result.framed)
        ctx.item(right, f"result: pan {result.pan:g}, framed {list(result.framed)}" + ("" if right else
                 f"; the camera should stop at the first step where {pictures or ['cat', 'dog']} are framed, pan "
                 f"{stops[-1]:g}, framed {list(pan_camera.framed_at(stops[-1]))}" + (len(stops) > 1) * (
                     f" (or pan {', '.join(f'{p:g}' for p in stops[:-1])}, where a detector may find them framed)")))
        if stop is not None:  # feedback is expected for the steps up to where the node stopped
            expected = expected[:stops_at(start, expected, stop)]
    pans = [round(f.pan, 6) for f in feedback]
    if not feedback:
        ctx.item(False, f"no feedback arrived ({len(expected)} steps from {start:g}): "
                        "goal_handle.publish_feedback(FindPictures.Feedback(pan=..., ids=...)) after every step",
                 weight=2)
        ctx.consequence("feedback pans and ids")
        return
    ok = pans == [round(p, 6) for p in expected]
    ctx.item(ok, f"feedback after each of the {len(expected)} steps: pan {pans[0]:g} ... {pans[-1]:g}" if ok else
             f"feedback pans {pans[:5]}{'...' if len(pans) > 5 else ''}; expected one after each step of "
             f"{pan_camera.STEP_DEGREES:g} degrees from {start:g}: {expected[:5]}{'...' if len(expected) > 5 else ''}",
             weight=2)
    wrong = [why for f in feedback if (why := ids_wrong(f.pan, f.ids, "the feedback's"))]
    ctx.item(not wrong, "feedback ids are the markers in view at each pan" if not wrong else wrong[0])


@check(points=2, timeout=60)
def cancel(ctx: Context) -> None:
    """A find_pictures goal canceled after its first feedback stops there: cancel accepted, status CANCELED."""
    from action_msgs.msg import GoalStatus

    from course_lib.imaging import pan_camera

    start = round(float(ctx.rng.uniform(-170.0, -120.0)), 1)
    steps = len(pan_camera.search_pans(start, []))
    proc = _start(ctx, start)
    packages.use_interfaces(ctx)
    feedback, canceling = [], []
    with ctx.probe() as probe:
        if not packages.wait_node(ctx, probe, proc, NODE) or not _endpoint_item(
                ctx, probe, proc, ACTION, ACTION_TYPE, "action"):
            return
        handle, why = _send_goal(ctx, probe, proc, [], feedback.append)
        if handle is None:
            ctx.item(False, why, weight=2)
            return
        ctx.waiting_on("the first feedback")
        gives_up, done = ctx.no_answer_coming(proc, 5.0), handle.get_result_async()
        probe.spin_until(lambda: bool(feedback) or done.done() or not proc.running() or gives_up(), scaled(10.0))
        if not feedback:
            ctx.item(False, "no feedback arrived, so the check could not cancel after the first step: publish "
                            "feedback after every step", weight=2)
            return
        future = handle.cancel_goal_async()
        probe.spin_until(lambda: future.done() or not proc.running(), scaled(10.0))
        if future.done():
            canceling = list(future.result().goals_canceling)
        ended = _wait_result(ctx, probe, proc, handle, steps * pan_camera.STEP_SECONDS + 5.0, feedback)
    ctx.item(bool(canceling), "the cancel request was accepted" if canceling else
             "the cancel request was refused: ActionServer(..., cancel_callback=...) returning CancelResponse.ACCEPT")
    if ended is None:
        ctx.consequence("the canceled goal did not end")
        return
    status, result = ended
    ok = status == GoalStatus.STATUS_CANCELED and not set(pan_camera.framed_at(result.pan)) >= {"cat", "dog"}
    ctx.item(ok, f"the goal ended CANCELED at pan {result.pan:g}" if ok else
             f"the goal ended {_STATUS.get(status, status)} at pan {result.pan:g}: before each step check "
             "goal_handle.is_cancel_requested, then goal_handle.canceled() and return the result (and spin a "
             "MultiThreadedExecutor with a ReentrantCallbackGroup, so the cancel request is served while execute runs)")


_STATUS = {1: "ACCEPTED", 2: "EXECUTING", 3: "CANCELING", 4: "SUCCEEDED", 5: "CANCELED", 6: "ABORTED"}
