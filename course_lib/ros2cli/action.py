"""``ros2 action list|info|type|send_goal``, on the session's tool node as ros2action does it."""

from __future__ import annotations

from course_lib.ros2cli.common import (
    DEFAULT_SPIN_TIME,
    Verb,
    print_names,
    print_types,
    print_types_of,
    run_group,
    wait_for_answer,
    wait_for_whole_graph,
    wait_until,
)

#: ros2action's words for the states of action_msgs/msg/GoalStatus.
STATUS_WORDS = {1: "ACCEPTED", 2: "EXECUTING", 3: "CANCELING", 4: "SUCCEEDED", 5: "CANCELED", 6: "ABORTED"}


def action_pairs() -> list[tuple[str, list[str]]]:
    """(name, [type, ...]) of every action in the graph, sorted."""
    from rclpy.action import get_action_names_and_types

    from course_lib.ros import session

    return sorted((name, list(kinds)) for name, kinds in get_action_names_and_types(session.tool_node()))


# --- ros2 action list / type -------------------------------------------------------------

def _list_arguments(parser) -> None:
    parser.add_argument("-t", "--show-types", action="store_true", help="Additionally show the action type")
    parser.add_argument("-c", "--count-actions", action="store_true",
                        help="Only display the number of actions discovered")


def _pairs_of(args) -> list[tuple[str, list[str]]]:
    """action_pairs from the daemon, else from this process's graph after discovery."""
    from course_lib.ros2cli import daemon

    pairs = daemon.graph_answer(args, "actions")
    if pairs is not daemon.DIRECT:
        return [(name, kinds) for name, kinds in pairs]
    wait_for_whole_graph(DEFAULT_SPIN_TIME)  # ros2action's verbs have no --spin-time
    return action_pairs()


def _list(args) -> None:
    print_names(_pairs_of(args), args.show_types, args.count_actions)


def _type_arguments(parser) -> None:
    parser.add_argument("action_name", help="Name of the ROS action to get info (e.g. '/fibonacci')")


def _type(args) -> int:
    from course_lib.ros2cli import daemon

    pairs = daemon.graph_answer(args, "actions")
    if pairs is not daemon.DIRECT:
        return print_types(dict(pairs).get(args.action_name, []))
    return print_types_of(args.action_name, action_pairs, DEFAULT_SPIN_TIME)


# --- ros2 action info --------------------------------------------------------------------

def _info_arguments(parser) -> None:
    parser.add_argument("action_name", help="Name of the ROS action to get info (e.g. '/fibonacci')")
    parser.add_argument("-t", "--show-types", action="store_true", help="Additionally show the action type")
    parser.add_argument("-c", "--count", action="store_true",
                        help="Only display the number of action clients and action servers")


def action_ends(action_name: str) -> dict[str, list[tuple[str, list[str]]]]:
    """{"clients": [(node, [type, ...]), ...], "servers": [...]} of an action, as the graph shows them.

    Raises:
        ValueError: the name is not a valid one (rclpy's words).
    """
    from rclpy.action import get_action_client_names_and_types_by_node, get_action_server_names_and_types_by_node
    from rclpy.exceptions import InvalidTopicNameException

    from course_lib.ros import session

    node = session.tool_node()
    try:
        name = node.resolve_topic_name(action_name)
    except InvalidTopicNameException as error:
        raise ValueError(str(error)) from None
    ends = {"clients": [], "servers": []}
    for node_name, namespace in node.get_node_names_and_namespaces():
        full = namespace.rstrip("/") + "/" + node_name
        for side, by_node in (("clients", get_action_client_names_and_types_by_node),
                              ("servers", get_action_server_names_and_types_by_node)):
            ends[side] += [(full, kinds) for action, kinds in by_node(node, node_name, namespace) if action == name]
    return ends


def _info(args) -> str | None:
    from course_lib.ros2cli import daemon

    ends = daemon.graph_answer(args, "action_ends", action_name=args.action_name)
    if ends is daemon.DIRECT:
        from rclpy.exceptions import InvalidTopicNameException

        from course_lib.ros import session

        try:  # an invalid name fails before the wait
            session.tool_node().resolve_topic_name(args.action_name)
        except InvalidTopicNameException as error:
            return str(error)
        wait_for_whole_graph(DEFAULT_SPIN_TIME)  # all the clients and servers, not the first found
        ends = action_ends(args.action_name)
    print(f"Action: {args.action_name}")
    for side in ("clients", "servers"):
        print(f"Action {side}: {len(ends[side])}")
        for full, kinds in [] if args.count else ends[side]:
            print(f"    {full} [{', '.join(kinds)}]" if args.show_types else f"    {full}")
    return None


# --- ros2 action send_goal ---------------------------------------------------------------

def _send_goal_arguments(parser) -> None:
    parser.add_argument("action_name", help="Name of the ROS action (e.g. '/fibonacci')")
    parser.add_argument("action_type", help="Type of the ROS action (e.g. 'example_interfaces/action/Fibonacci')")
    goal = parser.add_mutually_exclusive_group()
    goal.add_argument("goal", nargs="?", default="{}", help="Goal request values in YAML format (e.g. '{order: 10}')")
    goal.add_argument("--stdin", action="store_true", help="Read goal from standard input")
    parser.add_argument("-f", "--feedback", action="store_true", help="Echo feedback messages for the goal")


def _yaml(msg) -> str:
    from course_lib.ros import message_yaml

    return message_yaml.format_message(msg)


def _send_goal(args) -> str | None:
    import sys
    import threading

    from rclpy.action import ActionClient

    from course_lib.ros import message_yaml, session
    from course_lib.ros2cli.service import read_values

    try:
        action = message_yaml.message_class(args.action_type, kind="action")
        action.Goal  # noqa: B018 - a message or service type has none
    except (ValueError, AttributeError):
        return "The passed action type is invalid"
    values = read_values(sys.stdin.read() if args.stdin else args.goal, "goal")
    goal = action.Goal()
    try:
        message_yaml.fill_message(goal, values)
    except ValueError as error:
        return f"Failed to populate message fields: {error!r}"
    # Made only now: an action client destroyed while the session's executor waits on it makes that
    # executor report "action client pointer is invalid" (a bad goal did, under load).
    client = ActionClient(session.tool_node(), action, args.action_name)
    handle = None
    # Feedback comes in the session's thread, and may come before this thread has seen the goal
    # accepted: held until then, it is printed after "Goal accepted", as ros2action's one thread does.
    # Once the goal has ended ("Goal finished", "Goal canceled.") it is dropped: ros2action stops
    # spinning there, so nothing follows those lines.
    printing = threading.Lock()
    held: list | None = []
    ended = False

    def show_feedback(feedback):
        with printing:
            if ended:
                return
            if held is None:
                print(f"Feedback:\n    {_yaml(feedback.feedback)}")
            else:
                held.append(feedback)

    try:
        print("Waiting for an action server to become available...")
        # With --feedback, also until the server's feedback publisher is discovered: the server is
        # "ready" when its services are, and feedback published before the two endpoints match is
        # lost (rcl's feedback topic is volatile).
        feedback_topic = f"{args.action_name.rstrip('/')}/_action/feedback"

        def ready() -> bool:
            return client.server_is_ready() and (
                not args.feedback or session.tool_node().count_publishers(feedback_topic) > 0)

        if not wait_until(ready):  # as long as it takes, like wait_for_server()
            return f"No action server for '{args.action_name}' (time limit under test or grading)"
        print(f"Sending goal:\n     {_yaml(goal)}")
        sent = client.send_goal_async(goal, show_feedback if args.feedback else None)
        if not wait_for_answer(sent.done):
            return "The goal was not answered (time limit under test or grading)"
        handle = sent.result()
        if handle is None:
            return f"Exception while sending goal: {sent.exception()!r}"
        if not handle.accepted:
            print("Goal was rejected.")
            handle = None
            return None
        with printing:
            print(f"Goal accepted with ID: {bytes(handle.goal_id.uuid).hex()}\n")
            early, held = held, None
            for feedback in early:
                print(f"Feedback:\n    {_yaml(feedback.feedback)}")
        finished = handle.get_result_async()
        if not wait_for_answer(finished.done):
            return "The goal did not finish (time limit under test or grading)"
        result = finished.result()
        if result is None:
            return f"Exception while getting result: {finished.exception()!r}"
        handle = None
        with printing:
            print(f"Result:\n    {_yaml(result.result)}")
            print(f"Goal finished with status: {STATUS_WORDS.get(result.status, 'UNKNOWN')}")
            ended = True
        return None
    finally:
        if handle is not None and STATUS_WORDS.get(handle.status) in ("ACCEPTED", "EXECUTING"):
            # Ctrl-C while the goal runs: like ros2action, cancel it
            _cancel(handle)
            with printing:
                print("Goal canceled.")
                ended = True
        # The client is not destroyed here: the command's process ends, and the session's stop
        # destroys its tool node (the client with it) once the executor no longer waits on it.


def _cancel(handle) -> None:
    """Ask the server to cancel the goal and wait until it accepts (the caller says so)."""
    print("Canceling goal...")
    canceling = handle.cancel_goal_async()
    if not wait_until(canceling.done, DEFAULT_SPIN_TIME * 10):
        raise RuntimeError("Exception while canceling goal: no answer")
    goals = canceling.result().goals_canceling
    if len(goals) != 1 or goals[0].goal_id != handle.goal_id:
        raise RuntimeError("Failed to cancel goal")


VERBS = {
    "info": Verb("Print information about an action", _info_arguments, _info),
    "list": Verb("Output a list of action names", _list_arguments, _list),
    "send_goal": Verb("Send an action goal", _send_goal_arguments, _send_goal),
    "type": Verb("Print a action's type", _type_arguments, _type),
}


def main(argv: list[str]):
    return run_group("ros2 action", "Various action related sub-commands", VERBS, argv)
