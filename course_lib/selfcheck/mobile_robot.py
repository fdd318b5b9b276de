"""The self-check of lesson 06's exercise: ``nearest_obstacle(scan)``, the nearest valid reading of a
``sensor_msgs/LaserScan`` as ``(distance, angle)``, or None when no beam has one.

The check's scans come from the course's simulated robot (course_lib.robot.simulation) for fixed
seeds, as the simulator's node publishes them on /scan: the Husky's 270° laser with the pillar to
the left and to the right, a 360° laser in the walls world with the nearest wall behind on the left, and the
same scans with what real drivers put into ``ranges`` besides distances: NaN for a failed reading,
0.0 or -inf for "too close to measure" (below ``range_min``), +inf for "no return" (REP 117). Each
scan's answer follows from its ranges; a wrong one is told what is wrong: a reading that is no
distance taken as one, the angle's sign, the angle of beam i (``angle_min + i * angle_increment``).
"""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np

from course_lib.selfcheck.verdicts import Verdict, _not_a_function, _verdict

#: How close an angle or a distance must be to count as the same (the scan's fields are float32).
TOLERANCE = 1e-4
#: The 360° laser of the walls scan: 720 beams from -π, half a degree apart.
FULL_CIRCLE = {"beams": 720, "angle_min": -math.pi, "angle_max": math.pi - 2 * math.pi / 720}


@dataclasses.dataclass(frozen=True)
class CheckScan:
    """One scan of the check: what it shows (said in a verdict) and the message."""

    words: str
    scan: object  # sensor_msgs.msg.LaserScan


def scan_message(ranges: np.ndarray, laser) -> object:
    """A sensor_msgs/LaserScan in the laser frame of `ranges` measured by `laser` (simulation.Laser)."""
    import array

    from sensor_msgs.msg import LaserScan

    scan = LaserScan()
    scan.header.frame_id = "laser"
    scan.angle_min, scan.angle_max, scan.angle_increment = laser.angle_min, laser.angle_max, laser.angle_increment
    scan.range_min, scan.range_max = laser.range_min, laser.range_max
    scan.ranges = array.array("f", np.asarray(ranges, dtype=np.float32).tobytes())
    return scan


def check_scans() -> list[CheckScan]:
    """The check's scans, in the order it tries them (the plain ones first)."""
    from course_lib.robot.simulation import Laser, Simulation

    left = Simulation("pillar", seed=5)   # the pillar ahead on the left (lesson 06's seed)
    right = Simulation("pillar", seed=7)  # ahead on the right
    room = Simulation("walls", seed=3, laser=Laser(**FULL_CIRCLE))
    room.command(-1.0, 0.4)               # back up while turning: the nearest wall ends up behind, on the left
    room.step(3.0)
    room.command(0.0, 0.0)
    room.step(0.5)
    scans = [CheckScan("the pillar ahead on the left", scan_message(left.scan(), left.laser)),
             CheckScan("the pillar ahead on the right", scan_message(right.scan(), right.laser)),
             CheckScan("a 360° laser (angle_min = -π) in a room", scan_message(room.scan(), room.laser))]
    ranges = left.scan()
    ranges[[0, 40, 334, 335, 336, 540]] = np.nan        # failed readings, some where the pillar is
    scans.append(CheckScan("the pillar on the left with NaN readings (failed measurements)",
                           scan_message(ranges, left.laser)))
    ranges = right.scan()
    ranges[[3, 100, 300]] = 0.0                          # a driver's "too close to measure"
    ranges[[5, 200]] = -np.inf                           # REP 117's
    scans.append(CheckScan("the pillar on the right with readings of 0.0 and -inf (closer than range_min)",
                           scan_message(ranges, right.laser)))
    scans.append(CheckScan("an empty field (every range +inf: no return)",
                           scan_message(np.full(left.laser.beams, np.inf), left.laser)))
    return scans


def nearest_reading(scan) -> tuple[float, float, int] | None:
    """(distance, angle, beam index) of the nearest reading within [range_min, range_max]; None if none."""
    ranges = np.asarray(scan.ranges, dtype=float)
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(ranges) & (ranges >= scan.range_min) & (ranges <= scan.range_max)
    if not valid.any():
        return None
    beam = int(np.flatnonzero(valid)[np.argmin(ranges[valid])])
    return float(ranges[beam]), scan.angle_min + beam * scan.angle_increment, beam


def nearest_obstacle_exercise(nearest_obstacle) -> Verdict:
    """Check ``nearest_obstacle(scan)`` on the check's scans: the nearest valid reading's
    ``(distance, angle)`` in m and rad (counter-clockwise, from ``angle_min``), None when there is none."""
    hint = "Write nearest_obstacle(scan) in the cell above and run it."
    if (result := _not_a_function(nearest_obstacle, "nearest_obstacle", hint)) is not None:
        return result
    scans = check_scans()
    for each in scans:
        try:
            with warnings.catch_warnings(), np.errstate(all="ignore"):  # NaN comparisons: the verdict explains
                warnings.simplefilter("ignore", RuntimeWarning)
                got = nearest_obstacle(each.scan)
        except NotImplementedError:
            return _verdict(False, "Not done yet: replace the raise NotImplementedError with your code.")
        except Exception as error:  # a check never raises on a wrong answer
            return _verdict(False, f"On {each.words}: nearest_obstacle(scan) raised {type(error).__name__}: {error}")
        problem = answer_problem(got, each.scan)
        if problem:
            return _verdict(False, f"On {each.words}: {problem}")
    return _verdict(True, f"nearest_obstacle finds the nearest valid reading and its beam's angle in all {len(scans)} "
                          "scans: it skips NaN, 0.0, -inf and +inf, and counts angles from angle_min, left positive.")


def answer_problem(got, scan) -> str | None:
    """What is wrong with nearest_obstacle's answer for `scan` (None: nothing)."""
    expected = nearest_reading(scan)
    if expected is None:
        if got is None:
            return None
        return (f"returned {got!r:.60}, but no beam has a valid reading (every range is +inf): return None, "
                "so that a caller can tell \"nothing in range\" from a distance.")
    distance, angle, beam = expected
    if got is None:
        return f"returned None, but beam {beam} reads {distance:.3f} m."
    try:
        got_distance, got_angle = (float(value) for value in got)
    except (TypeError, ValueError):
        return f"returned {got!r:.60}; return a pair of numbers, (distance, angle)."
    if _same(got_distance, angle) and _same(got_angle, distance):
        return "returned (angle, distance); return (distance, angle)."
    problem = _distance_problem(got_distance, scan, distance, beam)
    if problem is None:
        problem = _angle_problem(got_angle, scan, distance, angle, beam)
    return problem


def _same(a: float, b: float) -> bool:
    return math.isclose(a, b, rel_tol=TOLERANCE, abs_tol=TOLERANCE)


def _distance_problem(got: float, scan, distance: float, beam: int) -> str | None:
    if math.isnan(got):
        return ("the distance is NaN: a NaN range is a failed reading, not a distance, and min() or np.argmin "
                "over ranges with NaN gives NaN or its index. Skip every value that is not finite (np.isfinite).")
    if got == math.inf:
        return ("the distance is inf: +inf means \"no return\", not an obstacle; skip it (and return None only "
                "when no reading is left).")
    if got < scan.range_min:
        return (f"the distance is {got:g}, below range_min ({scan.range_min:g} m): 0.0 and -inf mean \"too close to "
                "measure\" and are no distances. Keep only readings from range_min to range_max.")
    if not _same(got, distance):
        return f"the distance is {got:.4f} m, but the nearest valid reading is {distance:.4f} m (beam {beam})."
    return None


def _angle_problem(got: float, scan, distance: float, angle: float, beam: int) -> str | None:
    if _same(got, angle):
        return None
    ranges = np.asarray(scan.ranges, dtype=float)
    same_range = np.flatnonzero(np.isclose(ranges, distance, rtol=0.0, atol=1e-6))
    if any(_same(got, scan.angle_min + other * scan.angle_increment) for other in same_range):
        return None  # another beam with exactly the nearest reading
    said = f"the angle is {got:.4f}, but beam {beam}'s is angle_min + {beam} × angle_increment = {angle:.4f} rad"
    if _same(got, -angle):
        return (f"{said}: the sign is wrong. Angles count counter-clockwise from the front, so an obstacle on "
                "the left has a positive angle (REP 103), and beam i is at angle_min + i × angle_increment.")
    if _same(got, beam * scan.angle_increment):
        return f"{said}: beam 0 is at angle_min ({scan.angle_min:.4f} rad), not at 0; add angle_min."
    if _same(got, float(beam)):
        return f"{said}: that is the beam's index; turn it into its angle."
    if _same(got, math.degrees(angle)):
        return f"{said}: that is in degrees; ROS angles are in radians."
    if any(_same(got, angle + step * scan.angle_increment) for step in (-1, 1)):
        return f"{said}: one beam off; the first beam (index 0) is at angle_min itself."
    return f"{said}."
