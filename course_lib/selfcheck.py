"""Instant self-checks for the lesson tasks (the graded assignments have their own checks).

Each check returns a Verdict, which a notebook shows as one line (✔ or ✘ and what to do) and
which is true only when the answer is right. A check never raises on a wrong answer, so "Run
All" goes on to the end of a lesson. A stub left as it is gets "not done yet" and a hint; a
wrong answer gets what is wrong.
"""

from __future__ import annotations

import dataclasses

PLACEHOLDERS = (None, ..., "...", "")


@dataclasses.dataclass(frozen=True)
class Verdict:
    ok: bool
    text: str

    def __bool__(self) -> bool:
        return self.ok

    def __str__(self) -> str:
        return ("✔ " if self.ok else "✘ ") + self.text

    def _repr_pretty_(self, printer, cycle):  # how IPython shows it as a cell's result
        printer.text(str(self))


def _verdict(ok: bool, text: str) -> Verdict:
    return Verdict(ok, text)


def _not_done(answer, hint: str) -> Verdict | None:
    if any(answer is p or (isinstance(answer, str) and answer == p) for p in PLACEHOLDERS):
        return _verdict(False, "Not done yet. " + hint)
    return None


def task1_node_name(answer, expected_node: str = "my_node") -> Verdict:
    """Task 1 (lesson 00): the name of the student's node as `ros2 node list` prints it."""
    from course_lib import graph

    hint = "Run graph.node_list() and copy your node's name, exactly as printed, into my_node_name."
    if (result := _not_done(answer, hint)) is not None:
        return result
    if not isinstance(answer, str):
        return _verdict(False, f"my_node_name should be a string like the list's entries, not {type(answer).__name__}.")
    names = graph.node_list()
    if answer in names and answer.rsplit("/", 1)[-1] == expected_node:
        return _verdict(True, f"{answer} is in the node list: your node is running and discoverable.")
    if "/" + answer in names:
        return _verdict(False, f"Almost: node list entries are fully qualified names, with the namespace. "
                               f"Write '/{answer}'.")
    if answer in names:
        return _verdict(False, f"{answer} is a node, but not yours: look for '{expected_node}'.")
    if not any(n.endswith("/" + expected_node) for n in names):
        return _verdict(False, f"{expected_node} is not in the node list at all: is it still running? "
                               "Run the cell that starts it (workspace.run) again, then graph.node_list().")
    return _verdict(False, f"{answer!r} is not in the node list {names}.")


def task2_echo(messages, topic: str = "/chatter", text_prefix: str = "Hello World") -> Verdict:
    """Task 2 (lesson 01): messages echoed from the talker's topic, like `ros2 topic echo --once`."""
    hint = ("Find the talker's topic (graph.topic_list() lists the topics), echo one message from it "
            "and store what the echo returns in echoed.")
    if (result := _not_done(messages, hint)) is not None:
        return result
    if not isinstance(messages, (list, tuple)):
        messages = [messages]
    if not messages:
        return _verdict(False, f"Nothing was echoed: is the talker running and publishing on {topic}? "
                               "Check graph.topic_list() for the topic's name.")
    first = messages[0]
    if not hasattr(type(first), "get_fields_and_field_types"):
        where = (" It looks like what the notebook's listener heard (listener.heard): that is the listener's "
                 "record, not an echo." if isinstance(first, str) else "")
        return _verdict(False, f"Got {first!r}, a {type(first).__name__}, not a ROS message.{where} Echo the "
                               "topic yourself with graph.topic_echo: it returns a list of the messages it "
                               "received.")
    data = getattr(first, "data", None)
    if not isinstance(data, str):
        return _verdict(False, f"Got a {type(first).__name__}, but {topic} carries std_msgs/msg/String: "
                               "did you echo the right topic?")
    if not data.startswith(text_prefix):
        return _verdict(False, f"Got {data!r}, which the talker did not send: echo {topic}, not another topic.")
    return _verdict(True, f"Echoed {len(messages)} message(s) from {topic}; the first says {data!r}.")


def _call(function, *args):
    """(result, None) or (None, a Verdict naming the exception) for one call of a student's function."""
    import warnings

    import numpy as np

    try:
        # Overflow warnings would only repeat what the verdict explains.
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            return function(*args), None
    except NotImplementedError:
        return None, _verdict(False, "Not done yet: replace the raise NotImplementedError with your code.")
    except Exception as error:  # a check never raises on a wrong answer
        shown = ", ".join(repr(a.tolist() if hasattr(a, "tolist") and getattr(a, "ndim", 0) else a) for a in args)
        return None, _verdict(False, f"Calling it with ({shown}) raised {type(error).__name__}: {error}")


def task3_brightness_on_change(function) -> Verdict:
    """Task 3 (lesson 02): should_publish(last_sent, current, threshold), true when the change is more than threshold."""
    import numpy as np

    hint = ("Write should_publish(last_sent, current, threshold) so that it returns True when nothing was "
            "sent yet (last_sent is None) or the brightness moved by more than threshold, else False.")
    if (result := _not_done(function, hint)) is not None:
        return result
    if not callable(function):
        return _verdict(False, f"Pass the function itself (should_publish, without brackets), not a "
                               f"{type(function).__name__}.")
    first, problem = _call(function, None, 120, 5)
    if problem is not None:
        if "Not done yet" in problem.text:
            return problem
        return _verdict(False, problem.text + ". Before anything was sent last_sent is None, and the first "
                                              "brightness must be published: test `last_sent is None` first.")
    if first is None:
        return _verdict(False, "Not done yet: should_publish returns None. " + hint)
    # (last_sent, current, threshold, expected, what is wrong when the answer differs)
    cases = [
        (None, 120, 5, True, "nothing was sent yet (last_sent is None), so the first brightness must be "
                             "published: test `last_sent is None` first"),
        (100, 100, 5, False, "the brightness did not change, so nothing should be published"),
        (0, 0, 5, False, "brightness 0 (a black frame) was sent last, and 0 again needs no message. 0 is "
                         "a brightness, not 'nothing sent': test `last_sent is None`, not `not last_sent`"),
        (0, 3, 5, False, "brightness 0 was sent last and a change of 3 is not more than 5. 0 is a "
                         "brightness, not 'nothing sent': test `last_sent is None`, not `not last_sent`"),
        (100, 103, 5, False, "a change of 3 is not more than 5"),
        (100, 106, 5, True, "a rise of 6 is more than 5 and must be published"),
        (100, 94, 5, True, "a drop of 6 counts too: compare abs(current - last_sent) with threshold"),
        (100, 105, 5, False, "a change of exactly 5 is not *more than* 5: use >, not >="),
        (100, 101, 0, True, "with threshold 0 every change must be published"),
        (np.uint8(100), np.uint8(103), 5, False,
         "with numpy uint8 values (what a frame's pixels are) 100 - 103 is 253, not -3: uint8 arithmetic "
         "wraps around. Convert to int before subtracting: int(current) - int(last_sent)"),
        (np.uint8(103), np.uint8(100), 5, False,
         "with numpy uint8 values (what a frame's pixels are) 100 - 103 is 253, not -3: uint8 arithmetic "
         "wraps around. Convert to int before subtracting: int(current) - int(last_sent)"),
    ]
    for last_sent, current, threshold, expected, why in cases:
        answer, problem = _call(function, last_sent, current, threshold)
        if problem is not None:
            return problem
        if answer is None or bool(answer) != expected:
            return _verdict(False, f"should_publish({last_sent!r}, {current!r}, {threshold}) returned {answer!r}, "
                                   f"expected {expected}: {why}.")
    return _verdict(True, "should_publish publishes the first value and every change of more than threshold, "
                          "up or down, and no other.")


def _four_points(function, args, function_name: str, hint: str, case: str, array_only: bool = False):
    """Call function(*args) and read its answer as four points: (float32 (4, 2) array, None) or (None, Verdict).
    With `array_only`, a list of points is refused (what follows needs the array the task asks for)."""
    import numpy as np

    answer, problem = _call(function, *args)
    if problem is not None:
        return None, problem
    if answer is None:
        return None, _verdict(False, f"Not done yet: {function_name} returns None. " + hint)
    if not array_only and not isinstance(answer, np.ndarray):
        try:
            answer = np.asarray(answer, dtype=np.float32)
        except (TypeError, ValueError):
            pass
    if not isinstance(answer, np.ndarray) or answer.shape != (4, 2):
        what = f"an array of shape {answer.shape}" if isinstance(answer, np.ndarray) else f"a {type(answer).__name__}"
        return None, _verdict(False, f"{function_name} should return a numpy array of shape (4, 2), which what "
                                     f"follows indexes as corners[:, 0] and hands to cv2.getPerspectiveTransform; "
                                     f"for {case} it returned {what}: {answer!r}. Build one with np.array(...).")
    try:
        return answer.astype(np.float32), None
    except (TypeError, ValueError):
        return None, _verdict(False, f"{function_name} should return numbers; for {case} it returned {answer!r}.")


def task4_order_corners(function) -> Verdict:
    """Task 4 (lesson 03): order_corners(points) returns four points as top-left, top-right, bottom-right, bottom-left."""
    import math

    import numpy as np

    hint = ("Write order_corners(points): given 4 (x, y) points in any order, return them as a (4, 2) array in "
            "the order top-left, top-right, bottom-right, bottom-left (clockwise on screen).")
    if (result := _not_done(function, hint)) is not None:
        return result
    if not callable(function):
        return _verdict(False, f"Pass the function itself (order_corners, without brackets), not a "
                               f"{type(function).__name__}.")
    a = math.radians(30)
    thin = np.array([[0, 0], [160 * math.cos(a), -160 * math.sin(a)],
                     [160 * math.cos(a) + 40 * math.sin(a), -160 * math.sin(a) + 40 * math.cos(a)],
                     [40 * math.sin(a), 40 * math.cos(a)]]) + [100, 200]
    b = math.radians(-20)
    rotated = np.array([[math.cos(b) * x - math.sin(b) * y, math.sin(b) * x + math.cos(b) * y]
                        for x, y in [(-50, -50), (50, -50), (50, 50), (-50, 50)]]) + [300, 240]
    # (name, the corners in the right order, the order in which the function gets them)
    cases = [
        ("an upright square", [[10, 10], [90, 10], [90, 90], [10, 90]], (2, 0, 3, 1)),
        ("a square turned by 20 degrees", rotated, (3, 1, 0, 2)),
        ("a trapezoid seen in perspective", [[120, 50], [260, 70], [300, 200], [80, 220]], (1, 3, 2, 0)),
        ("a long rectangle tilted by 30 degrees (its top-right corner is higher than its top-left and "
         "its bottom-right corner is higher than its top-left too, so 'the two highest points are the top' fails)",
         thin, (0, 2, 3, 1)),
        ("points already in order", [[15, 12], [95, 18], [92, 88], [10, 80]], (0, 1, 2, 3)),
        # Two corners tie on x + y and two on y - x: either tied corner may come first.
        ("a 3:1 rectangle turned by 45 degrees", [[80, 120], [100, 100], [160, 160], [140, 180]], (1, 3, 2, 0)),
    ]
    names = ("top-left", "top-right", "bottom-right", "bottom-left")
    for name, expected, shuffle in cases:
        expected = np.asarray(expected, dtype=np.float32)
        given = expected[list(shuffle)]
        answer, problem = _four_points(function, (given.copy(),), "order_corners", hint, name, array_only=True)
        if problem is not None:
            return problem
        lowest = expected.sum(axis=1).min()
        if any(np.allclose(answer, np.roll(expected, -k, axis=0), atol=1e-3)
               for k in range(4) if expected[k].sum() <= lowest + 1e-3):
            continue
        matches = [next((i for i in range(4) if np.allclose(p, expected[i], atol=1e-3)), None) for p in answer]
        if None not in matches and len(set(matches)) < 4:
            twice = next(m for m in matches if matches.count(m) > 1)
            return _verdict(False, f"For {name}, order_corners returned the point {expected[twice].tolist()} "
                                   f"{matches.count(twice)} times and left out another one: {answer.tolist()}. "
                                   "Taking the smallest and largest x + y and y - x picks one point twice when "
                                   "two corners tie, as here; sort the points by their angle around the centre "
                                   "instead (np.arctan2), then start at the smallest x + y.")
        if None in matches or sorted(matches) != [0, 1, 2, 3]:
            return _verdict(False, f"For {name}, order_corners returned {answer.tolist()}, which are not the four "
                                   f"points it was given ({given.tolist()}) in a new order: return the same points, "
                                   "reordered.")
        if matches == [0, 3, 2, 1]:
            return _verdict(False, f"For {name} the order goes anticlockwise on screen. Remember that image y "
                                   "points down: after top-left comes top-right, then bottom-right.")
        steps = (matches[0]) % 4
        if all(m == (i + steps) % 4 for i, m in enumerate(matches)):
            return _verdict(False, f"For {name} the order is clockwise but starts at the {names[matches[0]]} "
                                   "corner: start at the top-left one (the corner with the smallest x + y).")
        return _verdict(False, f"For {name} you returned the corners as "
                               f"{', '.join(names[m] for m in matches)}; expected {', '.join(names)}.")
    return _verdict(True, "order_corners puts four corners in the order top-left, top-right, bottom-right, "
                          "bottom-left, for tilted and perspective shapes too.")


def _exercise_node(node_or_class, class_name: str, hint: str):
    """(node added to the session, None) or (None, a Verdict) for a student's Node class or instance."""
    from rclpy.node import Node

    from course_lib import session

    if (result := _not_done(node_or_class, hint)) is not None:
        return None, result
    if isinstance(node_or_class, type) and issubclass(node_or_class, Node):
        try:
            node = node_or_class()
        except Exception as error:  # a check never raises on a wrong answer
            return None, _verdict(False, f"Creating {node_or_class.__name__}() raised {type(error).__name__}: {error}")
    elif isinstance(node_or_class, Node):
        node = node_or_class
    else:
        return None, _verdict(False, f"Pass the node class itself ({class_name}, without brackets), not a "
                                     f"{type(node_or_class).__name__}.")
    return session.add_node(node), None


def _message_type_name(cls) -> str:
    module = cls.__module__.split(".")
    return f"{module[0]}/{module[1]}/{cls.__name__}" if len(module) > 1 else cls.__name__


def _seconds(value: float) -> str:
    return f"{value:g} s"


def _depth_problem(endpoint, asked: int, what: str, call: str) -> Verdict | None:
    """A Verdict when a publisher's or subscription's queue is not the asked depth (found vs asked)."""
    from rclpy.qos import HistoryPolicy

    qos = endpoint.qos_profile
    if qos.history == HistoryPolicy.KEEP_ALL:
        return _verdict(False, f"The {what} keeps all messages (KEEP_ALL history); the exercise asks for a queue "
                               f"depth of {asked}: pass the depth as the last argument of {call}.")
    if qos.depth != asked:
        return _verdict(False, f"The {what} has queue depth {qos.depth}; the exercise asks for {asked}: pass "
                               f"{asked} as the last argument of {call}.")
    return None


def publisher_exercise(node_or_class, topic: str = "/announcements", prefix: str = "Announcement ",
                       period: float = 0.5, depth: int = 10) -> Verdict:
    """Exercise (lesson 01): a node that publishes std_msgs/String "Announcement N" (N = 0, 1, ...)
    on /announcements (queue depth 10) every 0.5 s. The period is read from the node's timers; then
    the check runs the node until it published three times and listens to it."""
    from std_msgs.msg import String

    from course_lib import session
    from course_lib.checks.context import scaled

    hint = (f"Pass your node class; in __init__ create a publisher of String on {topic.lstrip('/')!r} and a "
            f"timer that calls a method every {_seconds(period)}; the method publishes '{prefix}0', '{prefix}1', ...")
    node, problem = _exercise_node(node_or_class, "Announcer", hint)
    if problem is not None:
        return problem
    tool = session.tool_node()
    heard: list[str] = []
    listener = None
    try:
        publishers = [p for p in node.publishers if p.topic_name != "/parameter_events"]
        if not publishers:
            return _verdict(False, "Not done yet: the node has no publisher. In __init__, create one with "
                                   "self.create_publisher, giving it the message type, the topic and the queue "
                                   "depth, as the talker of §2 does.")
        mine = [p for p in publishers if p.topic_name == topic]
        if not mine:
            names = ", ".join(p.topic_name for p in publishers)
            return _verdict(False, f"The node publishes on {names}, not on {topic}: check the topic name you pass "
                                   "to create_publisher.")
        if mine[0].msg_type is not String:
            return _verdict(False, f"The publisher sends {_message_type_name(mine[0].msg_type)}; the exercise asks "
                                   "for std_msgs/msg/String (from std_msgs.msg import String).")
        if (problem := _depth_problem(mine[0], depth, "publisher", "create_publisher")) is not None:
            return problem
        timers = list(node.timers)
        if not timers:
            return _verdict(False, "Not done yet: the node has no timer. In __init__, create one with "
                                   "self.create_timer, giving it the period in seconds and the method to call, as "
                                   "the talker of §2 does.")
        periods = [timer.timer_period_ns * 1e-9 for timer in timers]
        on_time = [timer for timer, p in zip(timers, periods) if abs(p - period) < 1e-3]
        if not on_time:
            found = " and every ".join(_seconds(p) for p in sorted(set(periods)))
            return _verdict(False, f"The node's timer fires every {found}; the exercise asks for every "
                                   f"{_seconds(period)}: the first argument of create_timer is the period in seconds.")
        ticks = _count_calls(on_time[0])
        listener = tool.create_subscription(String, topic, lambda msg: heard.append(msg.data), depth)
        session.wait_for(lambda: mine[0].get_subscription_count() > 0, timeout=scaled(5.0))
        ticks.clear()
        # Three messages, or a timer that fired four times without one (one tick's grace for delivery).
        session.wait_for(lambda: len(heard) >= 3 or (not heard and len(ticks) >= 4), timeout=scaled(6 * period + 2))
        if not heard:
            return _verdict(False, f"The node's timer fires every {_seconds(period)}, but no message arrived on "
                                   f"{topic} after {len(ticks)} of its calls: does the method the timer calls "
                                   "publish a String with the node's publisher?")
        numbers = [text[len(prefix):] for text in heard if text.startswith(prefix)]
        if len(numbers) != len(heard) or not all(n.isdigit() for n in numbers):
            return _verdict(False, f"The node sent {heard[0]!r}; the exercise asks for '{prefix}0', then "
                                   f"'{prefix}1', and so on: put the count into the text.")
        counts = [int(n) for n in numbers]
        if any(b != a + 1 for a, b in zip(counts, counts[1:])):
            return _verdict(False, f"The numbers go {counts}: count up by one per message, starting from 0.")
        return _verdict(True, f"The node's timer fires every {_seconds(period)} and it publishes {heard[0]!r}, "
                              f"{heard[1] if len(heard) > 1 else '...'!r} ... on {topic}. In a terminal: "
                              f"ros2 topic echo {topic}.")
    finally:
        if listener is not None:
            tool.destroy_subscription(listener)
        try:
            session.remove_node(node)
        except ValueError:  # the student's code removed it already
            pass


def _count_calls(timer) -> list:
    """A list that gets an entry each time `timer`'s callback has run (the executor reads
    timer.callback at every call)."""
    calls: list = []
    callback = timer.callback

    def counted(*args):
        try:
            return callback(*args)
        finally:
            calls.append(None)

    timer.callback = counted
    return calls


def subscriber_exercise(node_or_class, msg_type, topic: str = "/ros_tutorial_msg", depth: int = 100) -> Verdict:
    """Exercise (lesson 01b): a node subscribed to ros_tutorial_msg (MsgTutorial, depth 100) that
    appends (stamp in seconds, data) to self.received for every message. The check sends it three
    messages of its own, marked by negative data, and looks at what the node kept."""
    from rclpy.qos import QoSProfile

    from course_lib import session

    hint = (f"Pass your node class; in __init__ set self.received = [] and subscribe to {topic.lstrip('/')!r}; "
            "the callback appends (stamp in seconds, data) for each message.")
    node, problem = _exercise_node(node_or_class, "TutorialListener", hint)
    if problem is not None:
        return problem
    fields = msg_type.get_fields_and_field_types()
    sent = []
    for i in range(3):
        msg = msg_type()
        msg.stamp.sec, msg.stamp.nanosec = 1000 + i, 250_000_000
        value = -1001 - i
        if "data" in fields:
            msg.data = value
        else:  # std_msgs/Header, the stand-in where MsgTutorial could not be built: counter in frame_id
            msg.frame_id = str(value)
        sent.append((msg, (1000.25 + i, value)))
    tool = session.tool_node()
    publisher = None
    try:
        subscriptions = [s for s in node.subscriptions]
        if not subscriptions:
            return _verdict(False, "Not done yet: the node has no subscription. In __init__, create one with "
                                   "self.create_subscription, giving it the message type, the topic, the method "
                                   "to call for each message and the queue depth, as topic_subscriber does.")
        mine = [s for s in subscriptions if s.topic_name == topic]
        if not mine:
            names = ", ".join(s.topic_name for s in subscriptions)
            return _verdict(False, f"The node subscribes to {names}, not to {topic}: check the topic name.")
        if mine[0].msg_type is not msg_type:
            return _verdict(False, f"The subscription takes {_message_type_name(mine[0].msg_type)}; the publisher "
                                   f"sends {_message_type_name(msg_type)}, so nothing would ever arrive.")
        if (problem := _depth_problem(mine[0], depth, "subscription", "create_subscription")) is not None:
            return problem
        if not isinstance(getattr(node, "received", None), list):
            return _verdict(False, "Keep what arrives in a list self.received, created empty in __init__ "
                                   "(self.received = []).")
        publisher = tool.create_publisher(msg_type, topic, QoSProfile(depth=depth))
        session.wait_for(lambda: publisher.get_subscription_count() > 0, timeout=3.0)
        for msg, _ in sent:
            publisher.publish(msg)
        expected = [pair for _, pair in sent]
        marks = {value for _, value in expected}

        def kept():
            return [entry for entry in list(node.received)
                    if isinstance(entry, (tuple, list)) and any(v in marks for v in entry if isinstance(v, int))]

        session.wait_for(lambda: len(kept()) >= 3, timeout=2.0)
        got = kept()
        if not got:
            shown = f": it holds {node.received[-1]!r}" if node.received else " and stays empty"
            return _verdict(False, f"The check sent three messages (data -1001, -1002, -1003), but self.received "
                                   f"has none of them{shown}. The callback should append (stamp in seconds, data) "
                                   "for every message.")
        first, want = got[0], expected[0]
        if len(first) != 2:
            return _verdict(False, f"For a message stamped {want[0]} with data {want[1]} the node kept {first!r}; "
                                   "keep a pair (stamp in seconds, data).")
        if first[0] == want[1]:
            return _verdict(False, f"The node kept {tuple(first)!r}: the pair goes (stamp, data), not (data, stamp).")
        if first[0] == int(want[0]):
            return _verdict(False, f"The node kept {tuple(first)!r}: the stamp lost its nanoseconds ({want[0]} was "
                                   "sent). Use msg.stamp.sec + msg.stamp.nanosec * 1e-9.")
        if len(got) < 3:
            return _verdict(False, f"Of three messages sent, {len(got)} reached self.received: append every one.")
        if not all(len(a) == 2 and abs(a[0] - b[0]) < 1e-6 and a[1] == b[1] for a, b in zip(got, expected)):
            return _verdict(False, f"For the messages {expected} (stamp, data) the node kept "
                                   f"{[tuple(e) for e in got]}.")
        return _verdict(True, f"The node kept {[tuple(e) for e in got]} for the three messages the check sent: "
                              "stamp and data, in order.")
    finally:
        if publisher is not None:
            tool.destroy_publisher(publisher)
        try:
            session.remove_node(node)
        except ValueError:
            pass


#: What ros2 launch (launch_ros) logs, and skips, for a <param from=...> that is no file.
_NOT_A_FILE = "Parameter file path is not a file: "


def _parameter_file(path, temp_dir) -> str:
    """A --params-file of a node as the launch file says it: ``$(find-pkg-share PKG)/...`` for a
    file in a package's share folder, else its path; the parameters themselves, as one line of YAML,
    for a file the launch wrote (a <param name= value=>)."""
    from pathlib import Path

    import yaml

    from course_lib import ament

    path = Path(path)
    if path.is_relative_to(temp_dir):
        return "parameters " + yaml.safe_dump(yaml.safe_load(path.read_text()), default_flow_style=True).strip()
    for package, prefix in ament.packages().items():
        share = prefix / "share" / package
        if path.is_relative_to(share):
            return f"$(find-pkg-share {package})/{path.relative_to(share).as_posix()}"
    return str(path)


def _launch_nodes(path) -> tuple[list[dict], list[str]]:
    """What each node of a launch file would start with, without starting it; and the parameter
    files it names that are no files (ros2 launch warns and skips them)."""
    from pathlib import Path

    from course_lib.launch.actions import run_launch_file

    context = run_launch_file(path)
    try:
        nodes = []
        for node in context.nodes:
            command = list(node.command)
            ros_args = command[command.index("--ros-args") + 1:] if "--ros-args" in command else []
            remaps, params = [], []
            for flag, value in zip(ros_args, ros_args[1:]):
                if flag == "-r" and not value.startswith("__"):
                    remaps.append(value)
                elif flag == "--params-file":
                    params.append(_parameter_file(value, context.temp_dir()))
            nodes.append({"executable": "/".join(Path(command[0]).parts[-2:]), "output": node.output,
                          "name": node.node_name, "namespace": node.namespace, "remaps": sorted(remaps),
                          "parameter files": params})
        missing = [message[len(_NOT_A_FILE):] for _, message in context.warnings if message.startswith(_NOT_A_FILE)]
        return nodes, missing
    finally:
        context.remove_files()


def _listed(values) -> str:
    return ", ".join(map(str, values)) if values else "none"


def task_launch_yaml(yaml_file, xml_file) -> Verdict:
    """Lesson 02b: a YAML launch file starts the same nodes as the XML one (command lines, output)."""
    from course_lib.launch import LaunchFileError

    hint = ("Write the YAML file as a list under `launch:`, one `- node:` per <node> tag, with the keys pkg, "
            "exec, output, and lists `param:` and `remap:`.")
    try:
        wanted, _ = _launch_nodes(xml_file)
    except (LaunchFileError, LookupError, OSError) as error:
        return _verdict(False, f"The XML launch file does not run ({error}); build the workspace and call "
                               "workspace.use_workspace(WS) first.")
    try:
        given, missing = _launch_nodes(yaml_file)
    except (LaunchFileError, LookupError, OSError) as error:
        return _verdict(False, f"Your YAML launch file cannot run: {error}")
    if not given:
        return _verdict(False, "Not done yet: your launch file starts no node. " + hint)
    by_package = sorted({f for node in wanted for f in node["parameter files"] if f.startswith("$(find-pkg-share")})
    why = ("$(find-pkg-share) finds the installed file wherever ros2 launch runs; a relative path is relative to "
           "the folder it runs in, not to the launch file's")
    if missing:
        return _verdict(False, f"Your launch file names the parameter file {missing[0]}, which is no file (ros2 "
                               "launch warns and starts the node without it)."
                               + (f" The XML file names {by_package[0]}: {why}." if by_package else ""))
    if len(given) != len(wanted):
        return _verdict(False, f"Your launch file starts {len(given)} node(s); the XML file starts {len(wanted)}.")
    for index, (mine, theirs) in enumerate(zip(given, wanted), start=1):
        if mine["executable"] != theirs["executable"]:
            return _verdict(False, f"Node {index} runs {mine['executable']}; the XML file's node {index} runs "
                                   f"{theirs['executable']} (pkg and exec, in the same order).")
        for key in ("output", "name", "namespace", "remaps", "parameter files"):
            if mine[key] != theirs[key]:
                if isinstance(mine[key], list):
                    said = f"{key} are {_listed(mine[key])}, the XML file gives {_listed(theirs[key])}"
                else:
                    said = f"{key} is {mine[key]!r}, the XML file gives {theirs[key]!r}"
                if key == "parameter files" and any(f in by_package for f in theirs[key]):
                    said += f": {why}"
                return _verdict(False, f"Node {index} ({theirs['executable']}): {said}.")
    return _verdict(True, f"Your YAML launch file starts the same {len(given)} nodes as the XML one.")


def _board_views():
    """(name, {marker id: corners}, {picture: corners}) of the board seen upright, turned and in perspective."""
    import numpy as np

    from course_lib import boards, marker_board

    board = boards.default_board()
    bw, bh = board.size
    views = []
    for name, degrees, tilt in (("an upright board", 0, 0.0), ("a board turned by 120 degrees", 120, 0.0),
                                ("a board seen in perspective", -25, 0.0006)):
        a = np.radians(degrees)
        H = np.array([[np.cos(a), -np.sin(a), 320], [np.sin(a), np.cos(a), 240], [tilt, 0, 1]]) @ \
            np.array([[0.5, 0, -0.25 * bw], [0, 0.5, -0.25 * bh], [0, 0, 1]])

        def project(points, H=H):
            p = np.column_stack([points, np.ones(len(points))]) @ H.T
            return (p[:, :2] / p[:, 2:]).astype(np.float32)

        markers = {i: project(board.marker_square(i)) for ids in marker_board.PICTURES.values() for i in ids}
        pictures = {picture: project(board.picture_slot(picture)) for picture in marker_board.PICTURES}
        views.append((name, markers, pictures))
    return views


def task_picture_corners(function) -> Verdict:
    """Lesson 03: picture_corners_of(markers, picture) takes each framing marker's corner that touches the picture."""
    import numpy as np

    from course_lib import marker_board

    hint = ("Write picture_corners_of(markers, picture): for each marker of marker_board.PICTURES[picture] (top-left, "
            "top-right, bottom-right, bottom-left), take the one of its four corners that touches the picture, and "
            "return the four points as a (4, 2) array.")
    if (result := _not_done(function, hint)) is not None:
        return result
    if not callable(function):
        return _verdict(False, f"Pass the function itself (picture_corners_of), not a {type(function).__name__}.")
    places = ("top-left", "top-right", "bottom-right", "bottom-left")
    for view, markers, pictures in _board_views():
        for picture, expected in pictures.items():
            answer, problem = _four_points(function, ({i: c.copy() for i, c in markers.items()}, picture),
                                           "picture_corners_of", hint, f"the {picture}")
            if problem is not None:
                return problem
            for place, marker_id, point, want in zip(places, marker_board.PICTURES[picture], answer, expected):
                if np.allclose(point, want, atol=1e-2):
                    continue
                which = [(i, k) for i, corners in markers.items() for k in range(4)
                         if np.allclose(point, corners[k], atol=1e-2)]
                if which and which[0][0] != marker_id:
                    return _verdict(False, f"For the {picture}'s {place} corner ({view}) you took a corner of marker "
                                           f"{which[0][0]}; that corner lies on marker {marker_id} "
                                           f"(marker_board.PICTURES[{picture!r}] lists the markers top-left first).")
                if which:
                    return _verdict(False, f"For the {picture}'s {place} corner ({view}) you took corner "
                                           f"{which[0][1]} of marker {marker_id}, which does not touch the picture: "
                                           "take the corner of the marker that points at the picture (OpenCV "
                                           "numbers a marker's corners 0 top-left, 1 top-right, 2 bottom-right, "
                                           "3 bottom-left of the upright marker, whatever way it is turned).")
                return _verdict(False, f"For the {picture}'s {place} corner ({view}) you returned {point.tolist()}, "
                                       "which is no corner of a marker: return marker corners as they are.")
    return _verdict(True, "picture_corners_of takes the right corner of each marker, also for turned and tilted "
                          "boards.")


# ---- lesson 02: the brightness node as a package -----------------------------------------------

#: The package and executable of lesson 02's exercise (the brightness assignment asks for the
#: same package, in its own notebook).
BRIGHTNESS_PACKAGE = "brightness"
BRIGHTNESS_EXECUTABLE = "brightness_node"
BRIGHTNESS_ENTRY_POINT = f"{BRIGHTNESS_EXECUTABLE} = {BRIGHTNESS_PACKAGE}.{BRIGHTNESS_EXECUTABLE}:main"

#: Python modules a node may import that are no ROS packages, and the package.xml (rosdep) key of each.
PYTHON_DEPENDENCIES = {"numpy": "python3-numpy", "cv2": "python3-opencv", "yaml": "python3-yaml"}

#: The topic the check remaps /image to: not the lesson's /camera/image_raw, so that a node that
#: names the camera topic itself instead of subscribing `image` is caught.
CHECK_CAMERA_TOPIC = "/selfcheck/camera"

_BUILD_COMMAND = "cd {ws} && colcon build --symlink-install --packages-select brightness"


def _calls(tree, attribute: str) -> bool:
    import ast

    return any(isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == attribute
               for node in ast.walk(tree))


def _package_files(ws) -> Verdict | None:
    """The static part of the brightness package check: files, imports against package.xml, the entry point."""
    import ast

    from course_lib import ament, package_files

    package_dir = ws / "src" / BRIGHTNESS_PACKAGE
    node_file = package_dir / BRIGHTNESS_PACKAGE / f"{BRIGHTNESS_EXECUTABLE}.py"
    if not (package_dir / "package.xml").is_file():
        return _verdict(False, f"Not done yet: there is no package {BRIGHTNESS_PACKAGE} in {ws / 'src'}. Run the cell "
                               "with `ros2 pkg create` (in the workspace's src/ folder).")
    if not node_file.is_file():
        return _verdict(False, f"Not done yet: {node_file.relative_to(ws)} does not exist. Run the %%writefile cell "
                               "of the node (the node file goes in the package's inner folder of the same name).")
    try:
        tree = ast.parse(node_file.read_text(), str(node_file))
    except SyntaxError as error:
        return _verdict(False, f"{node_file.name} has a syntax error in line {error.lineno}: {error.msg}.")
    missing = [what for what, call in (("subscription", "create_subscription"), ("publisher", "create_publisher"))
               if not _calls(tree, call)]
    if missing:
        return _verdict(False, f"Not done yet: {node_file.name} creates no {' and no '.join(missing)} (the TODOs in "
                               "BrightnessNode.__init__).")
    try:
        declared = package_files.run_dependencies(package_dir / "package.xml")
    except Exception as error:  # ElementTree.ParseError, and what a mangled file may raise
        return _verdict(False, f"package.xml cannot be read ({error}): run `ros2 pkg create` again in a fresh folder, "
                               "or mend the line it names.")
    ros_packages = ament.packages()
    for module, line in package_files.imported_modules(tree).items():
        needed = module if module in ros_packages else PYTHON_DEPENDENCIES.get(module)
        if needed and module != BRIGHTNESS_PACKAGE and needed not in declared:
            return _verdict(False, f"{node_file.name} imports {module} (line {line}), but package.xml does not "
                                   f"declare it: add <depend>{needed}</depend> next to the others (`ros2 pkg create "
                                   "--dependencies ...` writes these lines). Without it the package builds here, "
                                   "but rosdep and colcon on a robot do not know the node needs it.")
    if not any(isinstance(node, ast.FunctionDef) and node.name == "main" for node in tree.body):
        return _verdict(False, f"{node_file.name} has no function main(args=None): the executable calls it.")
    try:
        scripts = package_files.console_scripts(package_dir / "setup.py")
    except (OSError, SyntaxError) as error:
        return _verdict(False, f"setup.py cannot be read: {error}.")
    wanted = f"{BRIGHTNESS_PACKAGE}.{BRIGHTNESS_EXECUTABLE}:main"
    if BRIGHTNESS_EXECUTABLE not in scripts:
        others = [name for name, target in scripts.items() if target == wanted]
        if others:
            return _verdict(False, f"setup.py calls the executable {others[0]!r}; `ros2 run {BRIGHTNESS_PACKAGE} "
                                   f"{BRIGHTNESS_EXECUTABLE}` needs it to be called {BRIGHTNESS_EXECUTABLE!r} (the name "
                                   "left of the = in console_scripts).")
        return _verdict(False, f"Not done yet: setup.py has no executable {BRIGHTNESS_EXECUTABLE}. Add an entry for "
                               "it to the list of 'console_scripts': 'executable = module:function', where the "
                               "module is the node file's (package folder, a dot, file name without .py) and the "
                               "function the one the executable calls.")
    target = scripts[BRIGHTNESS_EXECUTABLE]
    if target != wanted:
        module, colon, function = target.partition(":")
        if not colon:
            why = "it needs a colon between the module and the function"
        elif module != f"{BRIGHTNESS_PACKAGE}.{BRIGHTNESS_EXECUTABLE}":
            why = (f"the node file's module is {BRIGHTNESS_PACKAGE}.{BRIGHTNESS_EXECUTABLE} (package folder, then "
                   f"file name without .py), not {module}")
        else:
            why = f"the function to call is main, not {function}"
        return _verdict(False, f"setup.py runs {target!r} for {BRIGHTNESS_EXECUTABLE}: {why}.")
    return None


def _entries(scripts: dict[str, str]) -> str:
    return ", ".join(f"{name} = {target}" for name, target in sorted(scripts.items())) or "none"


def _build_state(ws) -> Verdict | None:
    """Is what ros2 run would start built from the current files?"""
    from course_lib import package_files

    install = ws / "install" / BRIGHTNESS_PACKAGE
    build = _BUILD_COMMAND.format(ws=ws)
    if not install.is_dir():
        return _verdict(False, f"The package is not built yet: run the colcon build cell ({build}).")
    script = install / "lib" / BRIGHTNESS_PACKAGE / BRIGHTNESS_EXECUTABLE
    if not script.is_file():
        return _verdict(False, f"setup.py names {BRIGHTNESS_EXECUTABLE}, but the last build did not install it: build "
                               f"again ({build}). A new or changed executable always needs a build, also with "
                               "--symlink-install.")
    source = ws / "src" / BRIGHTNESS_PACKAGE
    # A %%writefile cell run again rewrites setup.py with the same text: what counts is whether the
    # executables it declares are those the build installed.
    if (source / "setup.py").stat().st_mtime > script.stat().st_mtime + 0.5:
        declared = package_files.console_scripts(source / "setup.py")
        built = package_files.built_console_scripts(ws, BRIGHTNESS_PACKAGE)
        if built != declared:
            return _verdict(False, f"setup.py changed after the last build: its executables are "
                                   f"{_entries(declared)}, the build installed {_entries(built or {})}. Build again "
                                   f"({build}); changes to setup.py need a build, also with --symlink-install.")
    node_file = f"{BRIGHTNESS_EXECUTABLE}.py"
    for copy in install.glob(f"lib/python*/site-packages/{BRIGHTNESS_PACKAGE}/{node_file}"):
        if not copy.is_symlink() and copy.read_bytes() != (source / BRIGHTNESS_PACKAGE / node_file).read_bytes():
            return _verdict(False, f"The installed copy of {node_file} is not the one you wrote last: the workspace "
                                   f"was built without --symlink-install, so build again after every change "
                                   f"({build}).")
    return None


def _test_frames():
    """bgr8 frames 80 wide and 60 high whose centre pixels (row 30, column 40) differ, with what the exercise's
    node should answer for each: the first channel (blue) of the centre pixel."""
    import numpy as np

    rng = np.random.default_rng(2)
    frames = []
    for blue, green, red in ((17, 140, 230), (201, 33, 90), (90, 250, 5)):
        frame = rng.integers(0, 256, (60, 80, 3), dtype=np.uint8)
        frame[30, 40] = (blue, green, red)
        frames.append((frame, blue))
    return frames


def _wrong_value_hint(frame, value) -> str:
    """Why a node may have answered `value` for a frame: the answers of common slips."""
    import numpy as np

    slips = [
        (int(frame[40, 30, 0]), "the pixel at row 40, column 30: numpy indexes [row, column], so the centre is "
                                "frame[height // 2, width // 2]"),
        (int(frame[30, 40, 2]), "the red value, the last channel: bgr8 stores blue first, so take channel 0"),
        (int(frame[30, 40, 1]), "the green value: take channel 0 (blue)"),
        (int(frame.sum(dtype=np.uint64)) // frame.size, "the average brightness: that is the assignment's job; this "
                                                        "exercise publishes the centre pixel's first channel"),
        (int(round(float(frame.mean()))), "the average brightness: that is the assignment's job; this exercise "
                                         "publishes the centre pixel's first channel"),
    ]
    return next((f" {value} is {why}." for expected, why in slips if expected == value), "")


def _node_endpoints(probe, name: str, namespace: str) -> tuple[dict, dict]:
    """({topic: [types]} of the subscriptions, and of the publishers) of a node, without ROS's own topics."""
    own = ("/rosout", "/parameter_events")
    subscriptions = dict(probe.node.get_subscriber_names_and_types_by_node(name, namespace))
    publishers = dict(probe.node.get_publisher_names_and_types_by_node(name, namespace))
    return ({t: types for t, types in subscriptions.items() if t not in own},
            {t: types for t, types in publishers.items() if t not in own})


def _crash_text(process) -> str:
    log = process.log_tail(12).strip()
    hint = ""
    if "SystemError" in log and "publish" in log:
        hint = (" publish() raises this SystemError when a field holds a value of the wrong type: UInt8(data=...) "
                "takes a Python int, and a pixel read from a numpy array is a numpy.uint8, so wrap it in int(...).")
    elif "NotImplementedError" in log:
        hint = " Not done yet: replace the raise NotImplementedError with your code."
    return f"{hint}\nIts last output:\n{log}" if log else hint


def _run_brightness_node(ws) -> Verdict:
    """Start the built node as `ros2 run` would, with /image remapped, in a ROS domain of its own; send it frames."""
    from rclpy.qos import QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
    from sensor_msgs.msg import Image
    from std_msgs.msg import UInt8

    from course_lib import images, rosenv, workspace
    from course_lib.checks.probe import RosProbe

    command = (f"ros2 run {BRIGHTNESS_PACKAGE} {BRIGHTNESS_EXECUTABLE} --ros-args -r /image:={CHECK_CAMERA_TOPIC}")
    with rosenv.reserve_domain_id() as reservation, RosProbe(reservation.domain_id) as probe:
        try:
            process = workspace.run(ws, BRIGHTNESS_PACKAGE, BRIGHTNESS_EXECUTABLE,
                                    remap={"/image": CHECK_CAMERA_TOPIC}, domain_id=reservation.domain_id,
                                    name=f"{BRIGHTNESS_EXECUTABLE} (self-check)")
        except (OSError, RuntimeError) as error:  # FileNotFoundError names what the build lacks
            return _verdict(False, f"`{command}` could not start: {error}")
        try:
            def student_nodes():
                return [(n, ns) for n, ns in probe.node.get_node_names_and_namespaces() if n != probe.node.get_name()]

            probe.spin_until(lambda: student_nodes() or not process.running(), 25.0)
            if not student_nodes():
                if not process.running():
                    return _verdict(False, f"`{command}` ended ({process.describe_exit()}) before its node "
                                           f"appeared.{_crash_text(process)}")
                return _verdict(False, f"`{command}` runs, but no node appeared in 25 s: does main() call "
                                       "rclpy.init(args=args), create the node and spin it?")
            name, namespace = student_nodes()[0]
            if name != BRIGHTNESS_EXECUTABLE:
                return _verdict(False, f"The node is called {name!r}; call it {BRIGHTNESS_EXECUTABLE!r} "
                                       f"(super().__init__({BRIGHTNESS_EXECUTABLE!r})), the name the lesson waits for.")
            probe.spin_until(lambda: all(_node_endpoints(probe, name, namespace)) or not process.running(), 5.0)
            subscriptions, publishers = _node_endpoints(probe, name, namespace)
            if not subscriptions:
                return _verdict(False, "The node subscribes to nothing: create its subscription of 'image' in "
                                       "__init__, where rclpy.spin finds it.")
            if CHECK_CAMERA_TOPIC not in subscriptions:
                topic = next(iter(subscriptions))
                return _verdict(False, f"Started with -r /image:={CHECK_CAMERA_TOPIC}, the node still subscribes "
                                       f"{topic}: subscribe the topic 'image' and let the remap (-r /image:=...) choose "
                                       "the camera's topic, instead of naming the camera's topic in the code.")
            if subscriptions[CHECK_CAMERA_TOPIC] != ["sensor_msgs/msg/Image"]:
                return _verdict(False, f"The subscription takes {subscriptions[CHECK_CAMERA_TOPIC][0]}; camera "
                                       "frames are sensor_msgs/msg/Image.")
            if "/brightness" not in publishers:
                shown = ", ".join(publishers) or "nothing"
                return _verdict(False, f"The node publishes {shown}, not /brightness: create its publisher "
                                       "of 'brightness' in __init__.")
            if publishers["/brightness"] != ["std_msgs/msg/UInt8"]:
                return _verdict(False, f"The node publishes {publishers['/brightness'][0]} on /brightness; the "
                                       "exercise (and the assignment) publish std_msgs/msg/UInt8, a number 0-255.")
            reliable = [what for what, infos in (
                ("subscription", probe.node.get_subscriptions_info_by_topic(CHECK_CAMERA_TOPIC)),
                ("publisher", probe.node.get_publishers_info_by_topic("/brightness")))
                if any(i.node_name == name and i.qos_profile.reliability == ReliabilityPolicy.RELIABLE for i in infos)]
            if reliable:
                return _verdict(False, f"The node's {' and '.join(reliable)} is reliable; camera frames and what is "
                                       "measured from them use the sensor-data QoS (best effort), as §5 explains: "
                                       "pass qos_profile_sensor_data instead of a depth.")
            replies: list[int] = []
            probe.node.create_subscription(UInt8, "/brightness", lambda msg: replies.append(msg.data),
                                           qos_profile_sensor_data)
            camera = probe.node.create_publisher(Image, CHECK_CAMERA_TOPIC, QoSProfile(depth=5))
            probe.wait_for_subscriber(camera, 5.0)
            answers = []
            for frame, expected in _test_frames():
                msg = images.image_to_msg(frame, "bgr8")
                replies.clear()
                for _ in range(6):  # sent again until answered: the first frames may come before discovery ends
                    camera.publish(msg)
                    if probe.spin_until(lambda: replies or not process.running(), 0.5):
                        break
                if replies and replies[0] != expected:
                    # publish() with a numpy integer in UInt8.data sends 255 before it raises: wait for the crash
                    probe.spin_until(lambda: not process.running(), 1.0)
                if not process.running():
                    return _verdict(False, f"The node crashed on the first frame the check sent "
                                           f"({process.describe_exit()}).{_crash_text(process)}")
                if not replies:
                    return _verdict(False, "The check sent frames on the remapped topic, but nothing came back on "
                                           "/brightness in 3 s: does on_image publish a UInt8 with the node's "
                                           "publisher?")
                if replies[0] != expected:
                    return _verdict(False, f"For a frame 80 wide and 60 high whose centre pixel (row 30, column 40) is "
                                           f"(blue, green, red) = {tuple(int(v) for v in frame[30, 40])}, the node "
                                           f"published {replies[0]}; expected {expected}, the first channel of the "
                                           f"centre pixel.{_wrong_value_hint(frame, replies[0])}")
                answers.append(replies[0])
        finally:
            process.stop(timeout=2.0)
    return _verdict(True, f"`{command}` answers frames on the remapped topic with their centre pixels' first channel "
                          f"({', '.join(map(str, answers))}) on /brightness, as std_msgs/msg/UInt8. The package is "
                          "ready for the brightness assignment, which replaces centre_value with the average.")


def brightness_package_exercise(ws_dir) -> Verdict:
    """Exercise (lesson 02): the brightness package, built, and its node run as `ros2 run brightness
    brightness_node --ros-args -r /image:=...`: package.xml declares what the node imports, setup.py has
    the executable, the build is current, and the node answers frames with the centre pixel's first channel.
    The static problems are named before anything is started."""
    from pathlib import Path

    ws = Path(ws_dir).absolute()
    for step in (_package_files, _build_state):  # (a failing Verdict is false: no `or` here)
        problem = step(ws)
        if problem is not None:
            return problem
    return _run_brightness_node(ws)
