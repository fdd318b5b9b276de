"""Zoo submissions of the pillar assignment: the reference and the typical mistakes of the
lecture's drive-to-the-pillar exercise (wrong sign of the angle, no clamping, inf taken for a range,
a hard-coded topic; the last two, which cost different checks, in one submission). Each entry has
edits of the reference package (see tests/support/zoo/__init__.py), the expected points per check (a number
or a (low, high) range) and phrases the feedback page must show.
"""

from __future__ import annotations

#: The typical mistakes, as edits of the reference package.
SIGN = ("float(angle_min + beam * angle_increment)", "float(-(angle_min + beam * angle_increment))")
UNCLAMPED = ("    return (float(min(linear, max_linear_speed)),\n"
             "            float(min(max(angular, -max_angular_speed), max_angular_speed)))",
             "    return float(linear), float(angular)")
WITH_INF = ("    returns = np.flatnonzero(np.isfinite(values))", "    returns = np.arange(values.size)")
HARD_CODED = ("self.settings['scan_topic']", "'/scan'")


def entries(course_dir: str = "") -> dict[str, dict]:
    return {
        "pillar_full": dict(edits=[], scores={"find_pillar": 3, "drive": 5, "parameters": 3}, reasons=[]),
        # angle_min - ...: find_pillar's three scans with a pillar (3 of its 5 items); the robot turns
        # away, keeping only its clamped speeds (the markers, mirrored, may pass when the pillar stands
        # nearly straight ahead), and with the grader's values only its scan topic is right.
        "pillar_sign": dict(edits=[SIGN], scores={"find_pillar": 1.2, "drive": (1, 2), "parameters": 1},
                            reasons=["the angle's sign is wrong"]),
        # Gains without clamping: the simulator clamps to the robot's limits, the check sees the commands.
        "pillar_unclamped": dict(edits=[UNCLAMPED], scores={"find_pillar": 3, "drive": 4, "parameters": 2},
                                 reasons=["clamp both", "follow linear_gain * (distance - stop_distance)"]),
        # Two mistakes apart: inf, -inf and nan taken for returns (only the scans that hold them
        # show it: 2 of find_pillar's 5 items), and the scan topic written in the code (the grader's
        # topic is never read, so its simulator never starts: the parameters check earns nothing).
        "pillar_inf_and_topic": dict(edits=[WITH_INF, HARD_CODED],
                                     scores={"find_pillar": 1.8, "drive": 5, "parameters": 0},
                                     reasons=["leave out inf, -inf and nan", "do not write it in the code"]),
    }
