"""The robot's size, speed limits and frames, written once: the MuJoCo model
(``robot_sim/worlds/husky.xml``), the simulation and the ROS node all take them from here.

The numbers are Clearpath's public Husky A200 data (data sheet and user manual): mass 50 kg, outer
size 990 × 670 × 390 mm, top speed 1.0 m/s, 13 in (0.33 m) wheels, an effective track of 0.555 m.
The turn rate limit of 2.0 rad/s and the acceleration of about 3 m/s² are those of Clearpath's
ROS driver configuration (husky_control's diff-drive limits).
"""

from __future__ import annotations

import math

#: Outer size (m: length, width, height), the data sheet's 990 x 670 x 390 mm.
BODY_SIZE = (0.99, 0.67, 0.39)
#: Wheel radius (m): 13 in tyres.
WHEEL_RADIUS = 0.165
#: Distance between the wheels' contact points (m), the data sheet's effective track.
TRACK = 0.555
#: The fastest the robot drives forward or back (m/s) and turns (rad/s); faster commands are clamped.
MAX_LINEAR = 1.0
MAX_ANGULAR = 2.0

#: The frames of the robot's TF tree (REP 105): odom -> base_link -> laser. base_link is the point
#: on the ground midway between the wheels; the laser's beams are 0.4 m above the ground.
ODOM_FRAME = "odom"
BASE_FRAME = "base_link"
LASER_FRAME = "laser"
LASER_OFFSET = (0.35, 0.0, 0.4)


def clamp_velocity(linear: float, angular: float) -> tuple[float, float]:
    """The command (m/s, rad/s) within the robot's limits.

    Raises:
        ValueError: a value is NaN or infinite (the robot cannot do "infinitely fast", and a
            controller that sends it has a bug worth seeing).
    """
    if not (math.isfinite(linear) and math.isfinite(angular)):
        raise ValueError(f"velocity command linear={linear}, angular={angular} is not finite: "
                         "check the controller for a division by zero or a NaN reading")
    return (min(max(linear, -MAX_LINEAR), MAX_LINEAR), min(max(angular, -MAX_ANGULAR), MAX_ANGULAR))


def wheel_speeds(linear: float, angular: float) -> tuple[float, float]:
    """The (left, right) wheel speeds (rad/s) that drive the robot at `linear` m/s and `angular` rad/s."""
    half = TRACK / 2
    return (linear - angular * half) / WHEEL_RADIUS, (linear + angular * half) / WHEEL_RADIUS
