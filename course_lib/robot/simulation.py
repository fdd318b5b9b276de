"""The mobile robot in a world, simulated by MuJoCo: plain Python, no ROS.

    sim = Simulation("pillar", seed=3)      # robot_sim/worlds/pillar.xml, the pillar placed by the seed
    sim.command(0.5, 0.0)                   # m/s forward, rad/s turning (clamped to the limits)
    sim.step(2.0)                           # two simulated seconds
    sim.pose()                              # (x, y, yaw) of base_link in the world (= odom)
    sim.scan()                              # the laser's ranges (m), REP 117's ±inf where no return

MuJoCo integrates the robot's body, its wheels (hinge joints driven by velocity motors) and their
contacts with the floor; the laser's beams are MuJoCo rays (``mj_multiRay``) from the laser's site.
Everything random comes from the seed: where the pillar stands, and the scan's noise, drawn in
order, so that two simulations of one seed given the same commands give the same numbers.
"""

from __future__ import annotations

import dataclasses
import importlib
import math
import os
from pathlib import Path

import numpy as np

from course_lib.robot import husky


def _import_mujoco():
    """mujoco without its OpenGL part (the course never renders with it: the laser's rays need no
    GL): unless MUJOCO_GL says otherwise, importing it would load GLFW and look for its library with
    subprocesses, 0.06 of the 0.1 processor seconds the import costs. The variable is set for the
    import only, so that processes started later see the environment as it was."""
    if "MUJOCO_GL" in os.environ:
        return importlib.import_module("mujoco")
    os.environ["MUJOCO_GL"] = "disable"
    try:
        return importlib.import_module("mujoco")
    finally:
        del os.environ["MUJOCO_GL"]


mujoco = _import_mujoco()

WORLDS_DIR = Path(__file__).parent / "robot_sim" / "worlds"
#: Model files in WORLDS_DIR that are parts of worlds, not worlds.
_PARTS = ("husky",)

#: Where the pillar world's pillar may stand (m from the start): in front of the robot, within the
#: laser's view, far enough that driving there takes a controller a few seconds.
PILLAR_DISTANCE = (3.0, 7.0)
PILLAR_BEARING = (-math.pi / 3, math.pi / 3)

#: The geom group of walls and obstacles: the only one the laser's beams hit (husky.xml).
_SEEN_BY_LASER = np.array([1, 0, 0, 0, 0, 0], dtype=np.uint8)


@dataclasses.dataclass(frozen=True)
class Laser:
    """A 2D laser scanner's geometry and noise; the defaults are those of a SICK LMS1xx, the
    scanner on the lecture's Husky: 270° in 0.5° steps (541 beams), 0.1-20 m, σ 1 cm."""

    beams: int = 541
    angle_min: float = -3 * math.pi / 4
    angle_max: float = 3 * math.pi / 4
    range_min: float = 0.1
    range_max: float = 20.0
    noise: float = 0.01

    @property
    def angle_increment(self) -> float:
        return (self.angle_max - self.angle_min) / (self.beams - 1)

    def angles(self) -> np.ndarray:
        """Each beam's angle in the laser frame (rad, counter-clockwise from straight ahead)."""
        return np.linspace(self.angle_min, self.angle_max, self.beams)


def worlds() -> list[str]:
    """The names of the worlds the simulation can load (their files are WORLDS_DIR/<name>.xml)."""
    return sorted(p.stem for p in WORLDS_DIR.glob("*.xml") if p.stem not in _PARTS)


def world_path(world: str) -> Path:
    """The MJCF file of a world given by name ("pillar") or by path.

    Raises:
        FileNotFoundError: no such world; the message lists the course's worlds.
    """
    path = Path(world) if world.endswith(".xml") else WORLDS_DIR / f"{world}.xml"
    if not path.is_file():
        raise FileNotFoundError(f"No world {world!r}: the course's worlds are {', '.join(worlds())}, "
                                "or give the path of an MJCF file that includes husky.xml")
    return path


def pillar_position(seed: int) -> tuple[float, float]:
    """Where the pillar of the pillar world stands for `seed` (x, y in m from the robot's start)."""
    rng = np.random.default_rng(np.random.SeedSequence(seed).spawn(2)[0])
    distance, bearing = rng.uniform(*PILLAR_DISTANCE), rng.uniform(*PILLAR_BEARING)
    return distance * math.cos(bearing), distance * math.sin(bearing)


def _yaw(quaternion) -> float:
    w, x, y, z = quaternion
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


class Simulation:
    """The robot in a world, advanced by :meth:`step`; its clock starts at 0 at every reset.

    Args:
        world: a world's name (see :func:`worlds`) or an MJCF file's path.
        seed: places the pillar (pillar world) and draws the scan's noise.
        laser: the scanner's geometry and noise.
    """

    def __init__(self, world: str = "pillar", seed: int = 0, laser: Laser | None = None):
        self.world = world
        self.laser = laser = Laser() if laser is None else laser
        self.model = mujoco.MjModel.from_xml_path(str(world_path(world)))
        self.data = mujoco.MjData(self.model)
        self._base = self.model.body("base_link").id
        self._laser_site = self.model.site("laser").id
        start = self.model.site("start").id
        self._start_position = self.model.site_pos[start].copy()
        self._start_quaternion = self.model.site_quat[start].copy()
        self._free_qpos = self.model.jnt_qposadr[self.model.joint("base").id]
        self._free_qvel = self.model.jnt_dofadr[self.model.joint("base").id]
        # Per geom: 1 for the robot's, 2 for walls and obstacles, 0 for the rest (the floor).
        self._geom_kind = np.where(self.model.geom_group == 1, 1, np.where(self.model.geom_group == 0, 2, 0))
        beam_angles = laser.angles()
        self._beams = np.stack([np.cos(beam_angles), np.sin(beam_angles), np.zeros_like(beam_angles)], axis=1)
        self._ray_geoms = np.zeros(laser.beams, dtype=np.int32)
        self._ray_distances = np.zeros(laser.beams, dtype=np.float64)
        self.reset(seed)

    # --- the world -----------------------------------------------------------------------------

    def reset(self, seed: int | None = None) -> None:
        """Put the robot at the world's start, at rest, the clock at 0; with a seed, place the
        pillar anew and restart the noise from it (without, the current seed's are restarted)."""
        if seed is not None:
            self.seed = int(seed)
        mujoco.mj_resetData(self.model, self.data)
        if self.has_pillar:
            pillar = self.model.geom("pillar").id
            self.model.geom_pos[pillar][:2] = pillar_position(self.seed)
        self._noise = np.random.default_rng(np.random.SeedSequence(self.seed).spawn(2)[1])
        qpos = self.data.qpos
        qpos[self._free_qpos:self._free_qpos + 3] = self._start_position + (0, 0, husky.WHEEL_RADIUS)
        qpos[self._free_qpos + 3:self._free_qpos + 7] = self._start_quaternion
        self.command(0.0, 0.0)
        mujoco.mj_forward(self.model, self.data)

    @property
    def has_pillar(self) -> bool:
        return mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, "pillar") >= 0

    @property
    def pillar(self) -> tuple[float, float] | None:
        """The pillar's centre (x, y) in the world, None in a world without one."""
        if not self.has_pillar:
            return None
        x, y, _ = self.model.geom_pos[self.model.geom("pillar").id]
        return float(x), float(y)

    @property
    def pillar_radius(self) -> float | None:
        return float(self.model.geom("pillar").size[0]) if self.has_pillar else None

    # --- time and motion -----------------------------------------------------------------------

    @property
    def time(self) -> float:
        """Simulated seconds since the last reset."""
        return float(self.data.time)

    @property
    def timestep(self) -> float:
        """MuJoCo's step (s): the simulation advances by whole steps."""
        return float(self.model.opt.timestep)

    def command(self, linear: float, angular: float) -> tuple[float, float]:
        """Drive at `linear` m/s and turn at `angular` rad/s (counter-clockwise) from now on, clamped
        to the robot's limits (husky.clamp_velocity). Returns the command as applied.

        Raises:
            ValueError: a value is NaN or infinite; the command in force does not change.
        """
        linear, angular = husky.clamp_velocity(float(linear), float(angular))
        self.data.ctrl[:] = husky.wheel_speeds(linear, angular)
        self.commanded = (linear, angular)
        return self.commanded

    def step(self, seconds: float) -> None:
        """Advance the simulation by `seconds` (rounded to whole MuJoCo steps, at least one)."""
        mujoco.mj_step(self.model, self.data, nstep=max(1, round(seconds / self.timestep)))  # the steps in one call

    def pose(self) -> tuple[float, float, float]:
        """base_link's (x, y, yaw) in the world, which is the odom frame: m, m, rad in (-π, π]."""
        qpos = self.data.qpos[self._free_qpos:self._free_qpos + 7]
        return float(qpos[0]), float(qpos[1]), _yaw(qpos[3:7])

    def velocity(self) -> tuple[float, float]:
        """The robot's forward speed (m/s) and turn rate (rad/s, counter-clockwise)."""
        qvel = self.data.qvel[self._free_qvel:self._free_qvel + 6]
        yaw = self.pose()[2]
        # A free joint's linear velocity is in the world frame, its angular velocity in the body's.
        return float(qvel[0] * math.cos(yaw) + qvel[1] * math.sin(yaw)), float(qvel[5])

    def touching(self) -> bool:
        """Whether the robot touches a wall or obstacle (contacts with the floor do not count)."""
        if self.data.ncon == 0:
            return False
        kinds = self._geom_kind[self.data.contact.geom]  # (contacts, 2): one row per contact
        return bool(((kinds[:, 0] | kinds[:, 1]) == 3).any())

    # --- the laser -----------------------------------------------------------------------------

    def scan(self) -> np.ndarray:
        """The laser's ranges now (m, float32), one per beam from angle_min to angle_max: the true
        distance plus Gaussian noise; +inf where a beam hits nothing within range_max, -inf where
        it hits something closer than range_min (REP 117)."""
        origin = self.data.site_xpos[self._laser_site]
        rotation = self.data.site_xmat[self._laser_site].reshape(3, 3)
        directions = np.ascontiguousarray(self._beams @ rotation.T).reshape(-1)
        mujoco.mj_multiRay(self.model, self.data, origin, directions, _SEEN_BY_LASER, 1, -1,
                           self._ray_geoms, self._ray_distances, None, self.laser.beams, self.laser.range_max)
        ranges = self._ray_distances + self._noise.normal(0.0, self.laser.noise, self.laser.beams)
        missed = (self._ray_geoms < 0) | (ranges > self.laser.range_max)
        ranges[ranges < self.laser.range_min] = -np.inf
        ranges[missed] = np.inf
        return ranges.astype(np.float32)
