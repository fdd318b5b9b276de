"""course_lib.notebook.rviz.transforms: quaternions, rigid transforms and the TF tree's lookups."""

import math

import numpy as np
import pytest

from course_lib.notebook.rviz.transforms import (
    NoTransform,
    TransformTree,
    inverse,
    matrix,
    quaternion_from_yaw,
    rotation_matrix,
    transform_points,
)


def test_a_quarter_turn_about_z_takes_x_to_y():
    turned = rotation_matrix(*quaternion_from_yaw(math.pi / 2)) @ [1, 0, 0]
    assert np.allclose(turned, [0, 1, 0])


def test_an_unnormalised_or_zero_quaternion_still_gives_a_rotation():
    assert np.allclose(rotation_matrix(0, 0, 0, 2), np.eye(3))
    assert np.allclose(rotation_matrix(0, 0, 0, 0), np.eye(3))


def test_inverse_undoes_a_transform():
    t = matrix((1, 2, 3), (0.1, 0.2, 0.3, 0.9))
    assert np.allclose(inverse(t) @ t, np.eye(4))


def robot_tree():
    """odom -> base_link (x 2, turned 90°) -> laser (0.1 ahead of base_link)."""
    tree = TransformTree()
    tree.set("odom", "base_link", matrix((2, 0, 0), quaternion_from_yaw(math.pi / 2)))
    tree.set("/base_link", "laser", matrix((0.1, 0, 0)))
    return tree


def test_a_point_ahead_of_the_laser_lands_where_the_chain_puts_it():
    """1 m ahead of the laser, which is 0.1 ahead of a robot at (2, 0) facing +y: (2, 1.1)."""
    tree = robot_tree()
    point = transform_points(tree.lookup("odom", "laser"), [[1, 0, 0]])
    assert np.allclose(point, [[2, 1.1, 0]], atol=1e-6)


def test_a_lookup_down_and_across_the_tree_is_the_inverse_of_up():
    tree = robot_tree()
    tree.set("odom", "goal", matrix((5, 5, 0)))
    assert np.allclose(tree.lookup("laser", "goal") @ tree.lookup("goal", "laser"), np.eye(4))
    assert np.allclose(tree.lookup("odom", "odom"), np.eye(4))


def test_an_unknown_frame_is_named_as_rviz_names_it():
    tree = robot_tree()
    with pytest.raises(NoTransform, match=r"^No transform from \[camera\] to \[odom\]$"):
        tree.lookup("odom", "camera")


def test_two_separate_trees_have_no_transform_between_them():
    tree = robot_tree()
    tree.set("map", "marker_board", matrix())
    with pytest.raises(NoTransform, match=r"No transform from \[marker_board\] to \[laser\]"):
        tree.lookup("laser", "marker_board")
    assert tree.frames() == ["base_link", "laser", "map", "marker_board", "odom"]


def test_the_newest_transform_of_a_child_replaces_the_old_one():
    tree = robot_tree()
    tree.set("odom", "base_link", matrix((3, 0, 0)))
    assert np.allclose(tree.lookup("odom", "laser")[:3, 3], [3.1, 0, 0])
    assert tree.parent_of("laser") == "base_link"


def test_a_loop_or_a_self_parent_is_refused_with_the_reason():
    tree = robot_tree()
    with pytest.raises(ValueError, match="close a loop"):
        tree.set("laser", "odom", matrix())
    with pytest.raises(ValueError, match="must differ"):
        tree.set("odom", "/odom", matrix())


def test_a_rotation_matrix_gives_back_its_quaternion():
    from course_lib.notebook.rviz.transforms import quaternion_from_matrix, rotation_matrix

    rng = np.random.default_rng(3)
    for q in rng.normal(size=(50, 4)):
        q = q / np.linalg.norm(q) * np.sign(q[3])
        assert np.allclose(quaternion_from_matrix(rotation_matrix(*q)), q, atol=1e-9)
    assert quaternion_from_matrix(np.eye(3)) == (0.0, 0.0, 0.0, 1.0)
