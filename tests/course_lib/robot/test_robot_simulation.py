"""course_lib.robot.simulation: the robot drives, turns and sees as MuJoCo simulates it (no ROS)."""

import dataclasses
import math

import numpy as np
import pytest

from course_lib.robot import husky
from course_lib.robot.simulation import Laser, Simulation, pillar_position, world_path, worlds

NOISELESS = Laser(noise=0.0)


def beam(sim: Simulation, angle: float) -> int:
    return int(np.argmin(np.abs(sim.laser.angles() - angle)))


def test_the_course_has_the_pillar_world_walls_and_a_maze():
    assert worlds() == ["maze", "pillar", "walls"]
    with pytest.raises(FileNotFoundError, match="maze, pillar, walls"):
        world_path("moon")


def test_driving_straight_covers_speed_times_time():
    sim = Simulation("pillar")
    sim.command(0.5, 0.0)
    sim.step(4.0)
    x, y, yaw = sim.pose()
    assert sim.time == pytest.approx(4.0)
    # 2 m, less what the start from rest costs (the motors' torque: about 3 m/s²)
    assert x == pytest.approx(2.0, abs=0.06)
    assert abs(y) < 0.01 and abs(yaw) < 0.01
    assert sim.velocity() == pytest.approx((0.5, 0.0), abs=0.01)


def test_turning_in_place_turns_at_the_commanded_rate():
    sim = Simulation("pillar")
    sim.command(0.0, 1.0)
    sim.step(1.0)
    assert sim.velocity()[1] == pytest.approx(1.0, abs=0.02)
    x, y, yaw = sim.pose()
    assert yaw == pytest.approx(1.0, abs=0.06)
    assert math.hypot(x, y) < 0.01


def test_an_arc_has_radius_speed_over_turn_rate():
    sim = Simulation("pillar")
    sim.command(0.5, 0.5)
    sim.step(math.pi / 0.5)  # half a circle of radius 1 m
    x, y, yaw = sim.pose()
    assert y == pytest.approx(2.0, abs=0.1)
    assert abs(x) < 0.15
    assert abs(abs(yaw) - math.pi) < 0.1


def test_commands_beyond_the_limits_are_clamped():
    sim = Simulation("pillar")
    assert sim.command(5.0, -9.0) == (husky.MAX_LINEAR, -husky.MAX_ANGULAR)
    sim.step(3.0)
    assert sim.velocity()[0] == pytest.approx(husky.MAX_LINEAR, abs=0.05)


@pytest.mark.parametrize("linear, angular", [(math.nan, 0.0), (0.0, math.inf), (-math.inf, 1.0)])
def test_a_command_that_is_not_finite_is_refused_and_the_last_one_stays(linear, angular):
    sim = Simulation("pillar")
    sim.command(0.3, 0.0)
    with pytest.raises(ValueError, match="not finite"):
        sim.command(linear, angular)
    assert sim.commanded == (0.3, 0.0)


def test_the_scan_sees_the_walls_at_their_distance_and_angle():
    sim = Simulation("walls", laser=NOISELESS)
    ranges = sim.scan()
    laser_x = husky.LASER_OFFSET[0]
    assert ranges.dtype == np.float32 and len(ranges) == sim.laser.beams >= 360
    assert ranges[beam(sim, 0.0)] == pytest.approx(5.0 - laser_x, abs=1e-3)       # east wall's face at x = 5
    assert ranges[beam(sim, math.pi / 2)] == pytest.approx(4.0, abs=1e-3)         # north wall's face at y = 4
    assert ranges[beam(sim, -math.pi / 2)] == pytest.approx(4.0, abs=1e-3)
    # 45° to the left the beam meets the north wall: 4 / sin 45°
    assert ranges[beam(sim, math.pi / 4)] == pytest.approx(4.0 / math.sin(math.pi / 4), abs=0.02)


def test_the_scan_turns_with_the_robot():
    sim = Simulation("walls", laser=NOISELESS)
    sim.command(0.0, 1.0)
    while sim.pose()[2] < math.pi / 2 - 0.01:
        sim.step(0.002)
    sim.command(0.0, 0.0)
    sim.step(0.5)
    x, y, yaw = sim.pose()
    # facing the north wall (y = 4) from the laser 0.35 m ahead of base_link
    ahead = sim.scan()[beam(sim, 0.0)]
    assert ahead == pytest.approx(4.0 - y - husky.LASER_OFFSET[0] * math.sin(yaw), abs=0.02)


def test_the_pillar_is_where_the_seed_puts_it_and_the_scan_sees_it_there():
    sim = Simulation("pillar", seed=7, laser=NOISELESS)
    px, py = sim.pillar
    assert (px, py) == pytest.approx(pillar_position(7))
    assert sim.pillar != Simulation("pillar", seed=8).pillar
    ranges = sim.scan()
    nearest = int(np.argmin(ranges))
    laser_x = husky.LASER_OFFSET[0]
    assert ranges[nearest] == pytest.approx(math.hypot(px - laser_x, py) - sim.pillar_radius, abs=0.01)
    assert sim.laser.angles()[nearest] == pytest.approx(math.atan2(py, px - laser_x), abs=2 * sim.laser.angle_increment)
    assert np.isinf(ranges).sum() > 0.9 * len(ranges)  # nothing else within 20 m


def test_beams_that_return_nothing_are_inf_and_too_close_ones_minus_inf():
    sim = Simulation("pillar", seed=1, laser=dataclasses.replace(NOISELESS, range_min=30.0, range_max=40.0))
    ranges = sim.scan()
    assert np.isneginf(ranges).sum() > 0 and np.isposinf(ranges).sum() > 0
    assert not np.isfinite(ranges).any()


def test_the_noise_is_gaussian_and_the_seeds_own():
    noisy, exact = Simulation("walls", seed=5), Simulation("walls", laser=NOISELESS)
    error = noisy.scan().astype(float) - exact.scan()
    noise = np.random.default_rng(np.random.SeedSequence(5).spawn(2)[1])
    expected = noise.normal(0, noisy.laser.noise, noisy.laser.beams)
    assert np.allclose(error, expected, atol=1e-5)  # float32 ranges
    assert error.std() == pytest.approx(noisy.laser.noise, rel=0.15)
    assert not np.allclose(Simulation("walls", seed=6).scan(), noisy.scan(), atol=1e-4)


def test_the_same_seed_and_commands_give_the_same_run():
    def run():
        sim = Simulation("pillar", seed=11)
        scans = []
        for linear, angular in [(0.8, 0.3), (0.2, -1.5), (-0.5, 0.0)]:
            sim.command(linear, angular)
            sim.step(0.7)
            scans.append(sim.scan())
        return sim.pose(), np.array(scans)
    (pose_a, scans_a), (pose_b, scans_b) = run(), run()
    assert pose_a == pose_b
    assert np.array_equal(scans_a, scans_b)


def test_reset_puts_the_robot_back_and_restarts_time_and_noise():
    sim = Simulation("pillar", seed=2)
    first_scan = sim.scan()
    sim.command(1.0, 0.5)
    sim.step(2.0)
    sim.reset()
    assert sim.time == 0.0 and sim.commanded == (0.0, 0.0)
    assert sim.pose() == pytest.approx((0.0, 0.0, 0.0), abs=1e-9)
    assert np.array_equal(sim.scan(), first_scan)
    sim.reset(seed=3)
    assert sim.pillar == pytest.approx(pillar_position(3))


def test_driving_into_a_wall_is_touching_it():
    sim = Simulation("walls")
    assert not sim.touching()
    sim.command(1.0, 0.0)
    sim.step(7.0)  # the east wall's face is 5 m ahead, the robot's front 0.5 m ahead of base_link
    assert sim.touching()
    assert sim.pose()[0] == pytest.approx(4.5, abs=0.1)


def test_the_maze_start_has_walls_close_on_three_sides_and_a_passage_ahead():
    sim = Simulation("maze", laser=NOISELESS)
    ranges = sim.scan()
    assert ranges[beam(sim, 0.0)] > 5.0                                     # east through cell (1, 0) to (2, 0)
    assert ranges[beam(sim, math.pi / 2)] == pytest.approx(1.15, abs=0.01)  # wall to cell (0, 1)
    assert ranges[beam(sim, -math.pi / 2)] == pytest.approx(1.25, abs=0.01)  # outer south wall


def test_the_model_has_the_sizes_husky_py_gives():
    """husky.xml and husky.py agree: the wheels, the laser's place and the Husky's 50 kg."""
    model = Simulation("walls").model
    left, right = model.body("left_wheel"), model.body("right_wheel")
    assert left.pos[1] == pytest.approx(husky.TRACK / 2) and right.pos[1] == pytest.approx(-husky.TRACK / 2)
    wheel_geoms = [g for g in range(model.ngeom) if model.geom_bodyid[g] == left.id]
    assert model.geom_size[wheel_geoms[0]][0] == pytest.approx(husky.WHEEL_RADIUS)
    laser = model.site_pos[model.site("laser").id] + (0, 0, husky.WHEEL_RADIUS)  # base_link is on the ground
    assert laser == pytest.approx(husky.LASER_OFFSET)
    assert model.body("base_link").subtreemass[0] == pytest.approx(50.0, abs=1.0)
