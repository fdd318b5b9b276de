"""course_lib.notebook.rviz.config: RViz2 .rviz files (rviz_files/ beside this file, written in the layout
public ROS 2 packages' configs use) and the course's own YAML read into what a view shows, and what it
cannot named."""

from pathlib import Path

import pytest

from course_lib.notebook.rviz import config, displays

FILES = Path(__file__).with_name("rviz_files")


def test_a_mobile_robots_rviz_file_gives_its_fixed_frame_displays_topics_and_top_down_view():
    plan = config.load(FILES / "mobile_robot.rviz")
    assert plan.fixed_frame == "odom"
    assert [(d["kind"], d["name"], d["topic"]) for d in plan.displays] == [
        ("Grid", "Grid", None), ("TF", "TF", None), ("RobotModel", "RobotModel", None),
        ("LaserScan", "LaserScan", "/scan"), ("PointCloud2", "Depth points", "/camera/depth/points"),
        ("Odometry", "Odometry", "/odom"), ("MarkerArray", "MarkerArray", "/obstacles"),
        ("Image", "Image", "/camera/image_raw")]
    options = {d["name"]: d["options"] for d in plan.displays}
    assert options["Grid"] == {"cell_size": 0.5, "cells": 20} and options["LaserScan"] == {"size": 0.03}
    assert options["Odometry"] == {"keep": 50}
    assert plan.camera == {"mode": "top", "target": [1.5, -0.5, 0.0], "scale": 40.0}
    assert plan.unsupported == ["RobotModel: drawn as the Husky's box; the robot description is not read",
                                "Map (rviz_default_plugins/Map: no such display in this view)"]
    assert all(d["kind"] in displays.KINDS for d in plan.displays)


def test_groups_plain_string_topics_disabled_and_unknown_displays_of_an_older_file():
    plan = config.load(FILES / "grouped_older.rviz")
    assert plan.fixed_frame == "map"
    assert [(d["kind"], d["name"], d["topic"]) for d in plan.displays] == [
        ("Path", "Planning/Global plan", "/plan"), ("PoseStamped", "Planning/Goal", "/goal_pose"),
        ("Marker", "Marker", "/visualization_marker")]
    assert plan.unsupported == [
        "Planning/Debug marker (rviz_default_plugins/Marker, disabled in the file: not shown)",
        "Camera (rviz_default_plugins/Camera: no such display in this view)",
        "Particles (nav2_rviz_plugins/ParticleCloud: no such display in this view)",
        "panel Camera panel (rviz_default_plugins/Camera)"]
    assert plan.camera == {"mode": "orbit", "target": [1.0, 2.0, 0.0], "distance": 12.5, "yaw": 3.1, "pitch": 0.6}


def test_the_courses_own_format_reads_back_what_was_saved(tmp_path):
    shown = [{"kind": "LaserScan", "name": "LaserScan", "topic": "/scan", "options": {"size": 0.1}}]
    path = config.save(tmp_path / "view.yaml", "odom", {"mode": "top", "scale": 50}, shown)
    assert path.read_text().startswith("format: course_lib rviz view\nversion: 1\n")
    plan = config.load(path)
    assert (plan.fixed_frame, plan.camera, plan.displays, plan.unsupported) == (
        "odom", {"mode": "top", "scale": 50}, shown, [])


def test_a_file_of_neither_format_says_which_it_is_not(tmp_path):
    (tmp_path / "other.yaml").write_text("a: 1\n")
    with pytest.raises(ValueError, match="neither an RViz2 .rviz file"):
        config.load(tmp_path / "other.yaml")
