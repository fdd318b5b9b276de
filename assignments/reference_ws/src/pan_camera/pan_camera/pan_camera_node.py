"""``ros2 run pan_camera pan_camera_node``: the pan camera's service and action.

- service ``markers_in_view`` (camera_interfaces/srv/MarkersInView): the markers and pictures the
  camera sees at the pan angle asked for, without turning it;
- action ``find_pictures`` (camera_interfaces/action/FindPictures): turn the camera in steps of
  STEP_DEGREES until the pictures asked for are framed, feedback after every step; a goal can be
  canceled between steps.

The camera starts at the parameter ``start_pan`` (degrees). What it sees is course_lib.pan_camera's.
"""

import time

import rclpy
from camera_interfaces.action import FindPictures
from camera_interfaces.srv import MarkersInView
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.node import Node

from course_lib.imaging.pan_camera import (
    START_PAN,
    STEP_DEGREES,
    STEP_SECONDS,
    framed_at,
    markers_in_view,
    markers_of,
    wrap,
)
from course_lib.ros import sigterm

#: Steps of a whole turn: a search that has not framed the pictures by then gives up (aborts).
FULL_TURN = round(360 / STEP_DEGREES)


class PanCameraNode(Node):
    """The node ``pan_camera``: service markers_in_view, action find_pictures."""

    def __init__(self):
        super().__init__('pan_camera')
        self.pan = wrap(self.declare_parameter('start_pan', START_PAN).value)
        ### BEGIN SOLUTION
        # Reentrant: the service and cancel requests are answered while a goal executes
        # (main() spins a MultiThreadedExecutor).
        group = ReentrantCallbackGroup()
        self.service = self.create_service(MarkersInView, 'markers_in_view', self.on_markers_in_view,
                                           callback_group=group)
        self.action = ActionServer(self, FindPictures, 'find_pictures', self.execute,
                                   goal_callback=self.on_goal, cancel_callback=self.on_cancel,
                                   callback_group=group)
        ### END SOLUTION

    def on_markers_in_view(self, request, response):
        """Answer which markers and pictures are in view at request.pan (the camera does not turn)."""
        ### BEGIN SOLUTION
        try:
            pan = wrap(request.pan)
        except ValueError as error:
            response.success = False
            response.message = str(error)
            return response
        response.ids = list(markers_in_view(pan))
        response.framed = list(framed_at(pan))
        response.success = True
        response.message = f'{len(response.ids)} markers in view at {pan:g} degrees'
        return response
        ### END SOLUTION

    def on_goal(self, goal_request):
        """Accept a goal that names only pictures of the board ("cat", "dog")."""
        ### BEGIN SOLUTION
        try:
            markers_of(goal_request.pictures)
        except ValueError as error:
            self.get_logger().warning(f'goal rejected: {error}')
            return GoalResponse.REJECT
        return GoalResponse.ACCEPT
        ### END SOLUTION

    def on_cancel(self, goal_handle):
        """Accept every cancel request (the search stops before its next step)."""
        ### BEGIN SOLUTION
        return CancelResponse.ACCEPT
        ### END SOLUTION

    def execute(self, goal_handle):
        """Turn STEP_DEGREES at a time until the pictures are framed, feedback after each step."""
        ### BEGIN SOLUTION
        wanted = set(goal_handle.request.pictures) or {'cat', 'dog'}
        for _ in range(FULL_TURN):
            if wanted <= set(framed_at(self.pan)):
                goal_handle.succeed()
                return self.result()
            if goal_handle.is_cancel_requested:
                goal_handle.canceled()
                return self.result()
            time.sleep(STEP_SECONDS)  # the head turning: a step takes this long
            self.pan = wrap(self.pan + STEP_DEGREES)
            goal_handle.publish_feedback(FindPictures.Feedback(pan=self.pan, ids=list(markers_in_view(self.pan))))
        goal_handle.abort()
        return self.result()
        ### END SOLUTION

    def result(self):
        """Where the camera stopped and the pictures framed there."""
        return FindPictures.Result(pan=self.pan, framed=list(framed_at(self.pan)))


def main(args=None):
    sigterm.end_spin_as_ctrl_c()  # `kill` ends the node as Ctrl-C does (before rclpy.init: see its docstring)
    rclpy.init(args=args)
    node = None
    try:
        node = PanCameraNode()
        rclpy.spin(node, executor=MultiThreadedExecutor())
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
