"""The pillar assignment: its spec, its notebook's words and its checks (``find_pillar``, and the
node driving the simulated robot to the pillar).

The contract is the notebook's introduction (PILLAR_INTRO). The drives run in lock-step with the
course's simulator (course_lib.robot.simulator_node) in the check's own process, on a fresh seed:
the simulation knows the truth (where the pillar stands, where the robot is, whether it touches),
waits for each scan's /cmd_vel as long as the node computes (course_lib.checks.lock_step: bounded
by its processor time, never passed over), and counts in simulated seconds, so the verdict does
not depend on how busy the machine is.
"""

from __future__ import annotations

import ast
import math

from course_lib.checks import packages
from course_lib.checks.context import Context, scaled
from course_lib.checks.registry import check
from course_lib.checks.spec import Assignment, NotebookText

# --- the notebook's words (markdown) and the spec ----------------------------------------

PILLAR_INTRO = """
# Assignment: drive to the pillar

The robot of Lesson 06 stands in the pillar world: an open floor and one pillar (radius 0.2 m)
somewhere 3-7 m in front of it. You write the node of the lecture's Husky exercise: it finds the
pillar in the laser scan, shows it as a marker, and drives there with a P-controller, all set by
a parameter file; and a launch file that starts it with the simulated robot.

**Contract** (this is exactly what is graded). Your workspace `ros2_ws/src` holds the package
**`pillar`** (`ament_python`; `package.xml` declares every ROS package its code imports) with:

1. `pillar/pillar_node.py`: `find_pillar(ranges, angle_min, angle_increment)`: the nearest return
   of a scan, `(distance, angle)` as Python floats: the smallest *finite* range (`+inf`, `-inf`
   and `nan` are no returns, REP 117) and its beam's angle, `angle_min + i * angle_increment`
   (radians, counter-clockwise: positive to the left); `None` when no range is finite.
2. The node **`pillar_node`** (executable `pillar_node`, class `PillarNode`), with the parameters
   `scan_topic`, `queue_size`, `linear_gain`, `angular_gain`, `max_linear_speed`,
   `max_angular_speed` and `stop_distance`, all read from its parameter file. It subscribes the
   `sensor_msgs/LaserScan` on `scan_topic` (queue `queue_size`) and answers **every scan** with
   one `geometry_msgs/Twist` on **`/cmd_vel`**: for the pillar at `(distance, angle)`,
   `linear.x = linear_gain * (distance - stop_distance)` (never below 0) and
   `angular.z = angular_gain * angle`, each clamped to its maximum (`±max_angular_speed`); a zero
   Twist when no pillar is seen. For every scan with a pillar it publishes a
   `visualization_msgs/Marker` on **`pillar_marker`** at the pillar's **centre** (the nearest
   return plus the radius, 0.2 m, along the beam) in the **`odom`** frame: TF gives the laser's
   pose there (`lookup_transform("odom", scan.header.frame_id, ...)`).
3. `config/pillar.yaml` with those parameters (`scan_topic: /scan`, your gains), and
   `launch/pillar.launch.xml`, which starts the simulator (robot_sim's `husky.launch.xml` with
   `world:=pillar`) and `pillar_node` with the parameter file; both installed by `setup.py`
   (`share/pillar/config`, `share/pillar/launch`): `ros2 launch pillar pillar.launch.xml`.

The grader builds your workspace and runs `ros2 run pillar pillar_node --ros-args --params-file
<your installed pillar.yaml>` against the simulator in lock-step (it waits for each scan's answer
however busy the machine; the drive ends where your node spends 2 s of processor time on one scan,
or 30 s waiting, without answering it), with pillars placed by seeds you have not seen: the markers
must be within 0.15 m of the pillar, and the robot must come to a stop within 0.5 m of it (the
laser's distance to its surface) without touching it, within 25 simulated seconds, never
commanding more than the file's maximum speeds. Then it runs your node with other values
(another scan topic, other gains, speed limits and stop distance, given with `-p` after your file)
and sees whether the robot follows them.

A pitfall: a numpy `float32` put into a Twist field is sent as a tiny garbage number (about
5e-315): convert with `float(...)`.
"""

DRIVE_CHECK = """\
The check starts your node as `ros2 run pillar pillar_node --ros-args --params-file ...` (build
first) beside the simulator, in a ROS domain of its own, and drives one pillar of a seed you have
not seen. In a terminal: `ros2 launch pillar pillar.launch.xml`, then watch `/pillar_marker` in
the lesson's viewer.
"""

#: The spec: what assignments/build.py, the grader and the checks below read about it.
SPEC = Assignment("pillar", "06", {"pillar": ("pillar_node",)},
           NotebookText(intro=PILLAR_INTRO, plain_ros=(
               "In plain ROS 2 the package comes from `ros2 pkg create --build-type ament_python --dependencies "
               "rclpy sensor_msgs geometry_msgs visualization_msgs --node-name pillar_node pillar`, then the "
               "`config/` and `launch/` folders and their `data_files` in `setup.py`."),
               checks={"find_pillar": ("`find_pillar`",), "drive": ("the node drives to the pillar", DRIVE_CHECK),
                       "parameters": ("the parameters are used",)},
               imports="from course_lib.robot.simulation import Simulation\n", names="find_pillar",
               try_text="Try it on a scan of the simulated robot (this cell is yours to change):", try_code="""
sim = Simulation("pillar", seed=1)
try:
    print(find_pillar(sim.scan(), sim.laser.angle_min, sim.laser.angle_increment), "pillar at", sim.pillar)
except NotImplementedError:  # the stub: Run All goes on to the checks, which say what is missing
    print("Not done yet: find_pillar still raises NotImplementedError. Write it in the pillar_node.py "
          "cell above, run that cell and the import cell, then this one.")
"""),
           functions=("pillar", "pillar.pillar_node"))
selfcheck, grade = SPEC.selfcheck, SPEC.grade  # what the notebook calls: checks.selfcheck("...")

(PACKAGE,) = SPEC.packages
EXECUTABLE = SPEC.executable(PACKAGE)
NODE = "pillar_node"
MARKER_TOPIC = "/pillar_marker"
PILLAR_RADIUS = 0.2
#: What the drive is judged by: the markers' distance to the pillar's centre (m, for this share
#: of them), the laser's distance to the pillar's surface where the robot stops (m), how long it
#: may take (simulated s), and how slow (m/s) for how long (simulated s) counts as stopped.
MARKER_TOLERANCE, MARKER_SHARE = 0.15, 0.9
STOP_WITHIN = 0.5
TIME_LIMIT = 25.0
STILL_SPEED, STILL_SECONDS = 0.05, 1.0


# --- find_pillar ------------------------------------------------------------------------------

def _scan(seed: int):
    """A simulated scan of the pillar world and its angles: (ranges float32, angle_min, angle_increment)."""
    from course_lib.robot.simulation import Simulation

    sim = Simulation("pillar", seed=seed)
    return sim.scan(), float(sim.laser.angle_min), float(sim.laser.angle_increment)


def _seed_with_bearing(rng, left: bool) -> int:
    """A seed whose pillar stands clearly to the left (or right) of the robot."""
    from course_lib.robot.simulation import pillar_position

    while True:
        seed = int(rng.integers(0, 2**31))
        x, y = pillar_position(seed)
        if (math.atan2(y, x) > 0.1) if left else (math.atan2(y, x) < -0.1):
            return seed


def _nearest(ranges, angle_min: float, increment: float):
    """The scan's smallest finite range and its angle (what find_pillar must give), or None."""
    import numpy as np

    values = np.asarray(ranges, dtype=np.float64)
    finite = np.flatnonzero(np.isfinite(values))
    if finite.size == 0:
        return None
    beam = int(finite[np.argmin(values[finite])])  # the first of equal ranges, as min() of (value, beam)
    return float(values[beam]), angle_min + beam * increment


def _returned(outcome):
    """(values, type names) of what find_pillar returned: a pair of numbers, None, or (None, why)."""
    if outcome.value is None:
        return None, ["NoneType"]
    if outcome.pytype not in ("tuple", "list"):
        return None, [outcome.pytype]
    try:
        tree = ast.parse(str(outcome.value), mode="eval").body
        values, types = [], []
        for element in tree.elts:
            if isinstance(element, ast.Call):  # np.float32(2.5)
                types.append(ast.unparse(element.func).removeprefix("np."))
                element = element.args[0]
            else:
                types.append("float")
            text = ast.unparse(element)
            values.append(float(text) if text in ("inf", "-inf", "nan") else float(ast.literal_eval(element)))
        return values, types
    except (SyntaxError, ValueError, TypeError, AttributeError, IndexError):
        return None, [f"{outcome.pytype} {outcome.value}"]


@check(points=3, timeout=60)
def find_pillar(ctx: Context) -> None:
    """find_pillar gives the smallest finite range and its beam's angle, as floats, and None without one."""
    left, right = _scan(_seed_with_bearing(ctx.rng, True)), _scan(_seed_with_bearing(ctx.rng, False))
    broken = left[0].copy()  # REP 117: -inf (too close) and nan (no reading) are not returns
    beams = ctx.rng.choice(len(broken), size=12, replace=False)
    broken[beams[:6]], broken[beams[6:]] = -math.inf, math.nan
    empty = right[0].copy()
    empty[:] = math.inf
    empty[ctx.rng.choice(len(empty), size=5, replace=False)] = math.nan
    cases = [("the pillar to the left", left), ("the pillar to the right", right),
             ("a scan with -inf and nan readings", (broken, *left[1:])),
             ("a scan without a return", (empty, *right[1:]))]
    outcomes = ctx.call("find_pillar", [((ranges,), {"angle_min": low, "angle_increment": step})
                                        for _, (ranges, low, step) in cases], labels=[label for label, _ in cases])
    types = set()
    for (label, (ranges, low, step)), outcome in zip(cases, outcomes, strict=True):
        if not outcome.ok:
            stub = "NotImplementedError" in outcome.error
            hint = " (replace `raise NotImplementedError()` with your code)" if stub else ""
            ctx.item(False, f"{label}: find_pillar failed: {outcome.error}{hint}")
            continue
        expected = _nearest(ranges, low, step)
        got, kinds = _returned(outcome)
        types.update(kinds)
        if expected is None:
            ctx.item(got is None and kinds == ["NoneType"], f"{label}: None" if kinds == ["NoneType"] else
                     f"{label}: returned {outcome.value}; with no finite range (all +inf or nan) return None")
        elif got is None or len(got) != 2:
            ctx.item(False, f"{label}: returned {outcome.pytype} {outcome.value}; return (distance, angle)")
        elif math.isclose(got[0], expected[0], abs_tol=1e-5) and math.isclose(got[1], expected[1], abs_tol=1e-5):
            ctx.item(True, f"{label}: ({got[0]:.3f} m, {got[1]:.3f} rad)")
        else:
            ctx.item(False, f"{label}: returned ({got[0]:.3f}, {got[1]:.3f}), expected ({expected[0]:.3f} m, "
                            f"{expected[1]:.3f} rad)" + _find_hint(got, expected))
    wrong = sorted(types - {"float", "float64", "NoneType"})
    if not any(o.ok for o in outcomes):
        ctx.consequence("the types returned: not tested, find_pillar returned nothing")
    else:
        ctx.item(not wrong, "returns Python floats" if not wrong else
                 f"returns {', '.join(wrong)}: a numpy float32 put into a Twist is sent as garbage (about 5e-315); "
                 "return float(...) values")


def _find_hint(got, expected) -> str:
    if math.isclose(got[1], -expected[1], abs_tol=1e-5):
        return " (the angle's sign is wrong: angle_min + i * angle_increment, positive to the left)"
    if not math.isfinite(got[0]):
        return " (that is not a finite range: leave out inf, -inf and nan, e.g. with np.isfinite)"
    return ""


# --- the drives -------------------------------------------------------------------------------

class _Record:
    """What one lock-step drive showed: per tick the truth, per /cmd_vel the command and the
    scan it answers, the markers, the node's endpoints."""

    def __init__(self):
        self.ticks: list[tuple[float, float, float, bool]] = []  # time, laser to surface, speed, touching
        self.commands: list[tuple[float, float, tuple]] = []  # linear, angular, the scan it answers
        self.markers: list[tuple[str, float, float]] = []  # frame, x, y
        self.scan = None  # the last scan published: (ranges, angle_min, angle_increment)
        self.pillar = (0.0, 0.0)
        self.scan_topics: list[str] = []
        self.publishes_cmd_vel = False
        self.failure: str | None = None  # why the simulation halted early (lock_step.JudgedSimulator)

    def tick(self, sim) -> None:
        from course_lib.robot import husky

        x, y, yaw = sim.pose()
        laser = (x + husky.LASER_OFFSET[0] * math.cos(yaw), y + husky.LASER_OFFSET[0] * math.sin(yaw))
        gap = math.dist(laser, self.pillar) - sim.pillar_radius
        self.ticks.append((sim.time, gap, sim.velocity()[0], sim.touching()))

    def stopped(self) -> bool:
        """Slower than STILL_SPEED for the last STILL_SECONDS (after the first second)."""
        if not self.ticks or self.ticks[-1][0] < STILL_SECONDS + 1.0:
            return False
        since = self.ticks[-1][0] - STILL_SECONDS
        for time, _, speed, _ in reversed(self.ticks):  # the newest first: a moving robot ends it at once
            if time < since:
                return True
            if abs(speed) >= STILL_SPEED:
                return False
        return True


def _simulator(context, proc, seed: int, scan_topic: str, record: _Record):
    """The course's simulator in lock-step, judging the node's process `proc`, its scan on
    `scan_topic`, recording into `record`."""
    import numpy as np
    from rclpy.parameter import Parameter

    from course_lib.checks.lock_step import JudgedSimulator

    class GradedSimulator(JudgedSimulator):
        def publish_state(self):
            super().publish_state()
            scan = self.last_scan  # its ranges are a new array every tick
            record.scan = (np.frombuffer(scan.ranges, dtype=np.float32), scan.angle_min, scan.angle_increment)
            record.tick(self.sim)

        def on_cmd_vel(self, msg):
            if self.awaiting_reply_since is not None and record.scan is not None:
                record.commands.append((msg.linear.x, msg.angular.z, record.scan))
            super().on_cmd_vel(msg)

        def fail(self, reason):
            record.failure = reason
            super().fail(reason)

    overrides = [Parameter(name, value=value) for name, value in {"world": "pillar", "seed": seed}.items()]
    sim = GradedSimulator(proc, context=context, parameter_overrides=overrides,
                          cli_args=["--ros-args", "-r", f"scan:={scan_topic}"])
    record.pillar = sim.sim.pillar
    return sim


def _drive(ctx: Context, seed: int, parameters: dict | None = None) -> _Record | None:
    """Run the student's node with its installed parameter file (and `parameters` given with -p
    after it) beside the simulator until the robot stops or TIME_LIMIT simulated seconds pass.
    None when the node did not run (the item that says why is recorded)."""
    from visualization_msgs.msg import Marker

    parameters = parameters or {}
    overrides = [arg for name, value in parameters.items() for arg in ("-p", f"{name}:={value}")]
    proc = packages.run(ctx, PACKAGE, EXECUTABLE, "--ros-args", "--params-file", str(_parameter_file(ctx)),
                        *overrides, tag="-" + "-".join(parameters)[:20] if parameters else "")
    packages.dependency_items(ctx, PACKAGE)
    record = _Record()
    scan_topic = parameters.get("scan_topic", "/scan")
    with ctx.probe() as probe:
        sim = _simulator(probe.context, proc, seed, scan_topic, record)
        probe.executor.add_node(sim)
        markers = probe.node.create_subscription(Marker, MARKER_TOPIC, lambda m: record.markers.append(
            (m.header.frame_id, m.pose.position.x, m.pose.position.y)), 100)
        try:
            if not packages.wait_node(ctx, probe, proc, NODE):
                return None
            ctx.waiting_on(f"{NODE}'s LaserScan subscription and /cmd_vel publisher")

            def endpoints() -> bool:
                subscribed = probe.node.get_subscriber_names_and_types_by_node(NODE, "/")
                record.scan_topics = sorted(t for t, types in subscribed if "sensor_msgs/msg/LaserScan" in types)
                published = probe.node.get_publisher_names_and_types_by_node(NODE, "/")
                record.publishes_cmd_vel = any(t == "/cmd_vel" for t, _ in published)
                return bool(record.scan_topics) and record.publishes_cmd_vel

            probe.spin_until(lambda: endpoints() or not proc.running(), scaled(10.0))
            if packages.node_ended(ctx, proc, NODE, "subscribed a scan and published /cmd_vel"):
                return None
            if scan_topic not in record.scan_topics or not record.publishes_cmd_vel:
                return record
            ctx.waiting_on(f"the robot to stop (simulated time {TIME_LIMIT:g} s at most)")
            sim.drive_until(lambda: not proc.running() or record.failure or record.stopped() or (
                record.ticks and record.ticks[-1][0] >= TIME_LIMIT), min(scaled(60.0), ctx.remaining() - 5.0),
                listeners=[markers])
            if packages.node_ended(ctx, proc, NODE, "drove to the pillar"):
                return None
        finally:
            sim.destroy_node()
            proc.stop(timeout=2)
    return record


def _parameter_file(ctx: Context):
    """The student's installed config/pillar.yaml (StudentError when it is not installed)."""
    from course_lib.checks.context import StudentError

    path = packages.require_build(ctx) / "install" / PACKAGE / "share" / PACKAGE / "config" / "pillar.yaml"
    if not path.is_file():
        raise StudentError(f"the parameter file is not installed ({path.relative_to(path.parents[4])} is missing): "
                           "write config/pillar.yaml and add ('share/' + package_name + '/config', "
                           "['config/pillar.yaml']) to data_files in setup.py, then build")
    return path


def _file_values(ctx: Context) -> dict:
    """The parameters of pillar_node in the student's parameter file ({} when unreadable)."""
    import yaml

    try:
        data = yaml.safe_load(_parameter_file(ctx).read_text()) or {}
        section = data.get(NODE) or data.get(f"/{NODE}") or data.get("/**") or {}
        return dict(section.get("ros__parameters") or {})
    except (OSError, yaml.YAMLError, AttributeError):
        return {}


def _endpoint_items(ctx: Context, record: _Record, scan_topic: str, weight: float = 0.0) -> bool:
    """The item "subscribes `scan_topic`" (of `weight`), and one when the node does not publish
    /cmd_vel (the simulator then never starts); True when it does both."""
    if not record.publishes_cmd_vel:
        ctx.item(False, f"{NODE} does not publish /cmd_vel: create_publisher(Twist, '/cmd_vel', 10)", weight=0.0)
    seen = f"it subscribes {record.scan_topics}" if record.scan_topics else "it subscribes no LaserScan"
    ctx.item(scan_topic in record.scan_topics, f"subscribes {scan_topic}" if scan_topic in record.scan_topics else
             f"{NODE} does not subscribe the parameter scan_topic's {scan_topic} ({seen}): read the topic from "
             "the parameter (self.declare_parameter('scan_topic', ...)), do not write it in the code", weight=weight)
    return record.publishes_cmd_vel and scan_topic in record.scan_topics


def _stop_words(record: _Record) -> tuple[bool, str]:
    """(stopped, words): where and when the robot stopped, or that it did not."""
    time, gap, _, _ = record.ticks[-1]
    if record.stopped():
        return True, f"stopped at {time:.1f} simulated s with its laser {gap:.2f} m from the pillar"
    words = f"had not stopped after {time:.1f} simulated s (the laser {gap:.2f} m from the pillar)"
    if record.failure:
        words += f"; the drive ended there: {record.failure.replace('the controller', NODE, 1)}"
    tiny = [c for c in record.commands if 0 < abs(c[0]) < 1e-300 or 0 < abs(c[1]) < 1e-300]
    if tiny:
        words += (f"; /cmd_vel carried {tiny[0][0]:.3g}, {tiny[0][1]:.3g}: a numpy float32 put into a Twist is "
                  "sent as such garbage, convert with float(...)")
    return False, words


def _consequences(ctx: Context, cause: str, items) -> None:
    for label, weight in items:
        ctx.consequence(f"{label}: not tested, because {cause}", weight=weight)


#: The items of the drive check after the node runs, with their weights (points).
_DRIVE_ITEMS = (("markers", 1.0), ("stops near the pillar", 2.0), ("does not touch it", 1.0),
                ("speeds within the file's maxima", 1.0))


@check(points=5, timeout=120)
def drive(ctx: Context) -> None:
    """With its parameter file the node marks the pillar within 0.15 m and stops within 0.5 m of it, untouched, clamped."""  # noqa: E501 (the check's description, one line: registry.check)
    record = _drive(ctx, int(ctx.rng.integers(0, 2**31)))
    if record is None:
        return _consequences(ctx, f"{NODE} did not run", _DRIVE_ITEMS)
    if not _endpoint_items(ctx, record, "/scan"):
        return _consequences(ctx, "the simulator waits for a node on /scan and /cmd_vel", _DRIVE_ITEMS)
    if not record.ticks:
        return _consequences(ctx, "the simulation did not start", _DRIVE_ITEMS)
    _marker_item(ctx, record)
    stopped, words = _stop_words(record)
    gap = record.ticks[-1][1]
    ctx.item(stopped and gap <= STOP_WITHIN, words + ("" if stopped and gap <= STOP_WITHIN else
             f"; it must stop within {STOP_WITHIN} m in {TIME_LIMIT:g} s: linear.x = linear_gain * "
             "(distance - stop_distance), turning by angular_gain * angle"), weight=2.0)
    closest = min(gap for _, gap, _, _ in record.ticks)
    touched = next((time for time, _, _, touching in record.ticks if touching), None)
    if touched is not None:
        ctx.item(False, f"the robot touched the pillar at {touched:.1f} simulated s: stop earlier (stop_distance)")
    elif closest > 1.0:
        ctx.consequence(f"does not touch it: not tested, the robot came no nearer than {closest:.2f} m")
    else:
        ctx.item(True, f"never touched the pillar (the laser {closest:.2f} m from it at the closest)")
    _limit_item(ctx, record, _file_values(ctx))


def _marker_item(ctx: Context, record: _Record) -> None:
    if not record.markers:
        ctx.item(False, f"no Marker arrived on {MARKER_TOPIC}: publish a visualization_msgs/Marker there for "
                        "every scan with a pillar")
        return
    frames = sorted({frame for frame, _, _ in record.markers})
    if frames != ["odom"]:
        ctx.item(False, f"the markers' frame_id is {frames}; the contract asks for odom: transform the pillar's "
                        "position from the laser frame with TF (lookup_transform('odom', scan.header.frame_id, ...))")
        return
    errors = sorted(math.dist((x, y), record.pillar) for _, x, y in record.markers)
    near = sum(error <= MARKER_TOLERANCE for error in errors) / len(errors)
    median = errors[len(errors) // 2]
    hint = (" (about the pillar's radius: the marker belongs at its centre, the nearest return plus 0.2 m)"
            if abs(median - PILLAR_RADIUS) < 0.06 else "")
    ctx.item(near >= MARKER_SHARE, f"{near:.0%} of {len(errors)} markers within {MARKER_TOLERANCE} m of the pillar "
             f"at ({record.pillar[0]:.2f}, {record.pillar[1]:.2f}), the median {median:.2f} m off"
             + ("" if near >= MARKER_SHARE else f"; at least {MARKER_SHARE:.0%} must be{hint}"))


def _limit_item(ctx: Context, record: _Record, values: dict) -> None:
    try:
        linear, angular = float(values["max_linear_speed"]), float(values["max_angular_speed"])
    except (KeyError, TypeError, ValueError):
        ctx.item(False, "config/pillar.yaml has no numbers max_linear_speed and max_angular_speed under "
                        f"{NODE}: ros__parameters:")
        return
    fast = [(lin, ang) for lin, ang, _ in record.commands if abs(lin) > linear + 1e-6 or abs(ang) > angular + 1e-6]
    ctx.item(not fast, f"every /cmd_vel within {linear:g} m/s and {angular:g} rad/s" if not fast else
             f"/cmd_vel asked for {fast[0][0]:.2f} m/s, {fast[0][1]:.2f} rad/s, beyond max_linear_speed {linear:g} "
             f"and max_angular_speed {angular:g}: clamp both ({len(fast)} of {len(record.commands)} commands)")


def _drawn_parameters(rng) -> dict:
    """Other values than any student's file holds: a scan topic, gains, speed limits, stop distance."""
    draw = lambda low, high: round(float(rng.uniform(low, high)), 2)  # noqa: E731
    return {"scan_topic": f"/grader_{int(rng.integers(100, 1000))}/scan", "queue_size": 5,
            "linear_gain": draw(0.6, 0.9), "angular_gain": draw(0.8, 1.3), "max_linear_speed": draw(0.5, 0.7),
            "max_angular_speed": draw(0.6, 0.9), "stop_distance": draw(0.35, 0.45)}


def _law(values: dict, nearest) -> tuple[float, float]:
    """The contract's command for the nearest return (distance, angle) under `values`."""
    distance, angle = nearest
    linear = min(values["linear_gain"] * max(distance - values["stop_distance"], 0.0), values["max_linear_speed"])
    turn = values["max_angular_speed"]
    return linear, min(max(values["angular_gain"] * angle, -turn), turn)


@check(points=3, timeout=120)
def parameters(ctx: Context) -> None:
    """Given another scan topic, gains, speed limits and stop distance, the node follows them."""
    values = _drawn_parameters(ctx.rng)
    record = _drive(ctx, int(ctx.rng.integers(0, 2**31)), values)
    given = " -p ".join(f"{name}:={value}" for name, value in values.items())
    later = (("commands follow the gains and maxima", 1.0), ("stops at stop_distance", 1.0))
    if record is None:
        return _consequences(ctx, f"{NODE} did not run", (("the scan topic", 1.0), *later))
    ctx.note(f"the node ran with --params-file <yours> -p {given}")
    if not _endpoint_items(ctx, record, values["scan_topic"], weight=1.0) or not record.ticks:
        return _consequences(ctx, "the simulator waits for a node on the scan topic and /cmd_vel", later)
    nearest = [(lin, ang, _nearest(*scan)) for lin, ang, scan in record.commands]  # only this check reads it
    answered = [(lin, ang, _law(values, near)) for lin, ang, near in nearest if near is not None]
    wrong = [(lin, ang, want) for lin, ang, want in answered
             if abs(lin - want[0]) > 0.01 + 0.02 * abs(want[0]) or abs(ang - want[1]) > 0.01 + 0.02 * abs(want[1])]
    share = 1 - len(wrong) / len(answered) if answered else 0.0
    ctx.item(answered and share >= 0.9, f"{share:.0%} of {len(answered)} commands follow the P-law with the given "
             "gains and maxima" if answered and share >= 0.9 else f"only {share:.0%} of {len(answered)} commands "
             "follow linear_gain * (distance - stop_distance) and angular_gain * angle, clamped to the given maxima"
             + (f"; e.g. ({wrong[0][0]:.3f}, {wrong[0][1]:.3f}) where ({wrong[0][2][0]:.3f}, {wrong[0][2][1]:.3f}) "
                "was due: read every value from the parameters" if wrong else ""))
    stopped, words = _stop_words(record)
    gap, stop = record.ticks[-1][1], values["stop_distance"]
    good = stopped and stop - 0.05 <= gap <= stop + 0.12 and not any(t[3] for t in record.ticks)
    ctx.item(good, words + ("" if good else f"; with stop_distance:={stop} it should stop with the laser "
                                            f"{stop} m from the pillar, untouched"))
