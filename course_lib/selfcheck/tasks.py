"""The lessons' tasks: the student's answer is a value or a plain function (lessons 00, 01, 02
and 03).
"""

from __future__ import annotations

from course_lib.selfcheck.verdicts import Verdict, _call, _not_a_function, _not_done, _verdict


def task1_node_name(answer, expected_node: str = "my_node") -> Verdict:
    """Task 1 (lesson 00): the name of the student's node as `ros2 node list` prints it."""
    from course_lib.ros import graph

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


def task3_brightness_on_change(function) -> Verdict:
    """Task 3 (lesson 02): should_publish(last_sent, current, threshold), true when the change is more than
    threshold."""
    import numpy as np

    hint = ("Write should_publish(last_sent, current, threshold) so that it returns True when nothing was "
            "sent yet (last_sent is None) or the brightness moved by more than threshold, else False.")
    if (result := _not_a_function(function, "should_publish", hint)) is not None:
        return result
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
            # A numpy bool shows as Python's (np.True_ reads as a typo); the arguments keep their np.uint8.
            shown = answer.item() if hasattr(answer, "item") and hasattr(answer, "dtype") else answer
            return _verdict(False, f"should_publish({last_sent!r}, {current!r}, {threshold}) returned {shown!r}, "
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
    """Task 4 (lesson 03): order_corners(points) returns four points as top-left, top-right, bottom-right,
    bottom-left."""
    import math

    import numpy as np

    hint = ("Write order_corners(points): given 4 (x, y) points in any order, return them as a (4, 2) array in "
            "the order top-left, top-right, bottom-right, bottom-left (clockwise on screen).")
    if (result := _not_a_function(function, "order_corners", hint)) is not None:
        return result
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


def _board_views():
    """(name, {marker id: corners}, {picture: corners}) of the board seen upright, turned and in perspective."""
    import numpy as np

    from course_lib.imaging import boards, marker_board

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

    from course_lib.imaging import marker_board

    hint = ("Write picture_corners_of(markers, picture): for each marker of marker_board.PICTURES[picture] (top-left, "
            "top-right, bottom-right, bottom-left), take the one of its four corners that touches the picture, and "
            "return the four points as a (4, 2) array.")
    if (result := _not_a_function(function, "picture_corners_of", hint)) is not None:
        return result
    places = ("top-left", "top-right", "bottom-right", "bottom-left")
    for view, markers, pictures in _board_views():
        for picture, expected in pictures.items():
            answer, problem = _four_points(function, ({i: c.copy() for i, c in markers.items()}, picture),
                                           "picture_corners_of", hint, f"the {picture}")
            if problem is not None:
                return problem
            for place, marker_id, point, want in zip(places, marker_board.PICTURES[picture], answer, expected,
                                                     strict=True):
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
