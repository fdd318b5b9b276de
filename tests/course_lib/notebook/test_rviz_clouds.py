"""course_lib.notebook.rviz.clouds: a PointCloud2's points and colours read from its bytes."""

from types import SimpleNamespace

import numpy as np
import pytest

from course_lib.notebook.rviz import clouds
from course_lib.notebook.rviz.transforms import matrix


def cloud(xyz, rgb, width=None, height=1, padding=0):
    """A PointCloud2 look-alike of PCL's x, y, z, rgb layout, with `padding` bytes after each row."""
    fields, data, step = clouds.xyz_rgb_cloud_bytes(np.asarray(xyz, float), np.asarray(rgb))
    width = width or len(xyz) // height
    rows = np.frombuffer(data, np.uint8).reshape(height, width * step)
    data = np.hstack([rows, np.zeros((height, padding), np.uint8)]).tobytes()
    return SimpleNamespace(fields=[SimpleNamespace(name=n, offset=o, datatype=t, count=1) for n, o, t in fields],
                           data=data, point_step=step, width=width, height=height,
                           row_step=width * step + padding, is_bigendian=False)


def drawn_positions(item):
    """An item's positions in the fixed frame: moved by its pose."""
    pose = np.asarray(item["pose"])
    return item["positions"] @ pose[:3, :3].T + pose[:3, 3]


def test_points_and_packed_rgb_come_out_as_given_and_moved_into_the_fixed_frame():
    msg = cloud([[1, 2, 3], [4, 5, 6]], [[255, 0, 0], [10, 20, 30]])
    (item,) = clouds.point_cloud(msg, matrix((10, 0, 0)), size=0.05)
    assert np.allclose(item["positions"], [[1, 2, 3], [4, 5, 6]]) and item["positions"].dtype == np.float32
    assert np.allclose(drawn_positions(item), [[11, 2, 3], [14, 5, 6]])
    assert item["colors"].tolist() == [[255, 0, 0, 255], [10, 20, 30, 255]] and item["size"] == 0.05


def test_rows_with_padding_are_read_row_by_row():
    xyz = np.arange(12, dtype=float).reshape(4, 3)
    (item,) = clouds.point_cloud(cloud(xyz, np.zeros((4, 3), int), height=2, padding=8), np.eye(4))
    assert np.allclose(drawn_positions(item), xyz)


def test_points_with_a_nan_coordinate_are_left_out():
    (item,) = clouds.point_cloud(cloud([[1, 1, 1], [np.nan, 0, 0]], [[1, 2, 3], [4, 5, 6]]), np.eye(4))
    assert len(item["positions"]) == 1 and item["colors"][0, :3].tolist() == [1, 2, 3]


def test_a_cloud_without_colours_is_coloured_along_z_red_lowest():
    msg = cloud([[0, 0, 0], [0, 0, 5]], [[0, 0, 0], [0, 0, 0]])
    msg.fields = msg.fields[:3]
    (item,) = clouds.point_cloud(msg, np.eye(4))
    assert item["colors"][0].tolist() == [255, 0, 0, 255] and item["colors"][1].tolist() == [255, 0, 255, 255]


def test_a_short_cloud_or_one_without_z_says_what_is_wrong():
    msg = cloud([[0, 0, 0], [1, 1, 1]], [[0, 0, 0], [0, 0, 0]])
    msg.data = msg.data[:-1]
    with pytest.raises(ValueError, match="31 bytes but row_step×height is 32"):
        clouds.point_cloud(msg, np.eye(4))
    msg.fields = msg.fields[:2]
    with pytest.raises(ValueError, match="x, y and z are needed"):
        clouds.point_cloud(msg, np.eye(4))


def test_other_layouts_give_the_points_and_colours_of_pcls_usual_one():
    """PCL's x, y, z, rgb (little-endian) is read the quick way; an rgba first, a field between the
    coordinates, big-endian bytes go through cloud_array to the same points and colours."""
    xyz = np.random.default_rng(1).uniform(-1, 1, (5, 3))
    rgb = np.random.default_rng(2).integers(0, 256, (5, 3))
    (usual,) = clouds.point_cloud(cloud(xyz, rgb), np.eye(4))
    record = np.dtype({"names": ["rgba", "x", "intensity", "y", "z"], "formats": ["<u4", "<f4", "<f4", "<f4", "<f4"],
                       "offsets": [0, 4, 8, 12, 16], "itemsize": 24})
    for order in "<>":
        data = np.zeros(5, record.newbyteorder(order))
        data["x"], data["y"], data["z"] = xyz.T
        data["rgba"] = (rgb[:, 0] << 16) | (rgb[:, 1] << 8) | rgb[:, 2]
        fields = [SimpleNamespace(name=n, offset=record.fields[n][1], datatype=6 if n == "rgba" else 7, count=1)
                  for n in record.names]
        other = SimpleNamespace(fields=fields, data=data.tobytes(), point_step=24, width=5, height=1, row_step=120,
                                is_bigendian=order == ">")
        (item,) = clouds.point_cloud(other, np.eye(4))
        assert np.allclose(item["positions"], usual["positions"]) and item["positions"].dtype == np.float32
        assert item["colors"].tolist() == usual["colors"].tolist()
    assert usual["colors"][:, :3].tolist() == rgb.tolist()
