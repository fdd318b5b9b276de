"""course_lib.notebook.rviz.geometry: scans, colours, arrows, axes, grid and path in the fixed frame."""

import math
from types import SimpleNamespace

import numpy as np

from course_lib.notebook.rviz import geometry
from course_lib.notebook.rviz.transforms import matrix, quaternion_from_yaw


def wall_scan(distance=2.0, beams=720):
    """A scan of a wall `distance` ahead (x = distance), beams within ±59.5°; the rest out of range."""
    angle_min, increment = -math.pi, 2 * math.pi / beams
    angles = angle_min + increment * np.arange(beams)
    ranges = np.where(np.abs(angles) < math.radians(59.75), distance / np.cos(angles), np.inf)
    return SimpleNamespace(ranges=ranges.tolist(), angle_min=angle_min, angle_increment=increment,
                           range_min=0.1, range_max=10.0)


def test_every_valid_beam_of_a_wall_scan_lies_on_the_wall():
    points, ranges = geometry.scan_points(**vars(wall_scan()))
    assert len(points) == 239  # beams within ±60° (angles -59.5° to 59.5°)
    assert np.allclose(points[:, 0], 2.0) and np.allclose(points[:, 2], 0.0)
    assert np.allclose(np.hypot(points[:, 0], points[:, 1]), ranges)


def test_beams_out_of_range_or_not_finite_are_left_out():
    points, _ = geometry.scan_points([0.05, 1.0, 11.0, float("nan"), float("inf"), 10.0], 0.0, 0.1, 0.1, 10.0)
    assert len(points) == 2


def test_a_scan_is_drawn_where_its_frame_is_in_the_fixed_frame():
    """A laser at (1, 0) facing +y sees the wall 2 m ahead at y = 2."""
    items = geometry.laser_scan(wall_scan(), matrix((1, 0, 0), quaternion_from_yaw(math.pi / 2)))
    (item,) = items
    assert item["type"] == "points" and item["positions"].dtype == np.float32
    assert np.allclose(item["positions"][:, 1], 2.0, atol=1e-5)
    assert item["colors"].shape == (239, 4)


def test_rainbow_runs_from_red_at_the_lowest_through_green_to_magenta_at_the_highest():
    colors = geometry.rainbow([0.0, 0.4, 1.0])
    assert colors[0].tolist() == [255, 0, 0, 255]
    assert colors[1].tolist() == [0, 255, 0, 255]
    assert colors[2].tolist() == [255, 0, 255, 255]
    assert geometry.rainbow([3.0, 3.0]).tolist() == [[255, 0, 0, 255]] * 2  # one value: no division by 0


def test_a_pose_arrow_is_the_unit_arrow_scaled_along_the_pose():
    (item,) = geometry.pose_arrows([matrix((1, 2, 0), quaternion_from_yaw(math.pi / 2))], length=0.5, width=0.1)
    tip = item["matrices"][0] @ [1, 0, 0, 1]
    assert item["shape"] == "arrow" and np.allclose(tip[:3], [1, 2.5, 0], atol=1e-6)


def test_tf_frames_draws_three_coloured_axes_and_a_name_per_frame():
    lines, texts = geometry.tf_frames({"odom": np.eye(4), "laser": matrix((1, 0, 0))}, length=0.5)
    assert lines["positions"].shape == (12, 3)
    assert np.allclose(lines["positions"][7], [1.5, 0, 0])  # the laser's x axis ends 0.5 ahead of it
    assert lines["colors"][7].tolist() == [255, 0, 0, 255]
    assert texts["texts"] == ["odom", "laser"]


def test_a_grid_of_ten_cells_has_eleven_lines_each_way_centred_on_its_frame():
    (item,) = geometry.grid(matrix((1, 0, 0)), cell_size=1.0, cells=10)
    assert item["positions"].shape == (44, 3)
    assert item["positions"][:, 0].min() == -4 and item["positions"][:, 0].max() == 6


def test_a_path_joins_its_poses_in_order():
    (item,) = geometry.path([matrix((0, 0, 0)), matrix((1, 0, 0)), matrix((1, 1, 0))])
    assert item["positions"][:, :2].tolist() == [[0, 0], [1, 0], [1, 0], [1, 1]]
    assert geometry.path([matrix()]) == []
