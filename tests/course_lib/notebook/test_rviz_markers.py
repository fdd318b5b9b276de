"""course_lib.notebook.rviz.markers: each Marker type's shapes, and the markers alive over time."""

import math

import numpy as np
import pytest
from builtin_interfaces.msg import Duration
from geometry_msgs.msg import Point
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker

from course_lib.notebook.rviz import markers
from course_lib.notebook.rviz.transforms import matrix


def marker(kind, ns="test", id_=0, x=1.0, yaw=0.0, scale=(1.0, 0.5, 0.25), points=(), action=Marker.ADD,
           lifetime=0.0, text=""):
    m = Marker(type=kind, ns=ns, id=id_, action=action, text=text)
    m.header.frame_id = "odom"
    m.pose.position.x = x
    m.pose.orientation.z, m.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    m.scale.x, m.scale.y, m.scale.z = scale
    m.color = ColorRGBA(r=1.0, g=0.5, b=0.0, a=1.0)
    m.points = [Point(x=float(px), y=float(py), z=0.0) for px, py in points]
    m.lifetime = Duration(sec=int(lifetime), nanosec=int((lifetime % 1) * 1e9))
    return m


def test_the_constants_are_those_of_the_message():
    for name in markers.TYPE_NAMES:
        assert getattr(markers, name) == getattr(Marker, name)
    assert (markers.ADD, markers.DELETE, markers.DELETEALL) == (Marker.ADD, Marker.DELETE, Marker.DELETEALL)


@pytest.mark.parametrize("kind, shape", [(Marker.CUBE, "cube"), (Marker.SPHERE, "sphere"),
                                         (Marker.CYLINDER, "cylinder"), (Marker.ARROW, "arrow")])
def test_a_solid_is_its_unit_shape_scaled_at_the_pose_in_the_fixed_frame(kind, shape):
    """Pose x = 1 turned 90°, frame 2 m along x of the fixed frame: the unit x end is at (3, 1)."""
    (item,) = markers.marker_items(marker(kind, yaw=math.pi / 2), matrix((2, 0, 0)))
    assert item["shape"] == shape and item["colors"].tolist() == [[255, 128, 0, 255]]
    assert np.allclose((item["matrices"][0] @ [1, 0, 0, 1])[:3], [3, 1, 0], atol=1e-6)


def test_an_arrow_by_two_points_goes_from_the_first_to_the_second():
    (item,) = markers.marker_items(marker(Marker.ARROW, x=0.0, points=[(1, 1), (1, 3)]), np.eye(4))
    m = item["matrices"][0]
    assert np.allclose((m @ [0, 0, 0, 1])[:3], [1, 1, 0]) and np.allclose((m @ [1, 0, 0, 1])[:3], [1, 3, 0])


def test_line_strip_joins_points_and_line_list_pairs_them():
    corners = [(0, 0), (1, 0), (1, 1)]
    (strip,) = markers.marker_items(marker(Marker.LINE_STRIP, x=0.0, points=corners), np.eye(4))
    (pairs,) = markers.marker_items(marker(Marker.LINE_LIST, x=0.0, points=corners), np.eye(4))
    assert strip["positions"][:, :2].tolist() == [[0, 0], [1, 0], [1, 0], [1, 1]]
    assert pairs["positions"][:, :2].tolist() == [[0, 0], [1, 0]]


def test_points_take_a_colour_per_point_when_given_one():
    m = marker(Marker.POINTS, points=[(0, 0), (0, 1)])
    m.colors = [ColorRGBA(r=1.0, a=1.0), ColorRGBA(b=1.0, a=1.0)]
    (item,) = markers.marker_items(m, np.eye(4))
    assert item["colors"].tolist() == [[255, 0, 0, 255], [0, 0, 255, 255]]
    assert np.allclose(item["positions"][:, 0], 1.0) and item["size"] == 1.0


def test_text_stands_at_the_pose_with_its_height():
    (item,) = markers.marker_items(marker(Marker.TEXT_VIEW_FACING, text="cat"), np.eye(4))
    assert item["texts"] == ["cat"] and item["heights"].tolist() == [0.25]


def test_a_mesh_resource_is_named_as_unsupported():
    with pytest.raises(ValueError, match="MESH_RESOURCE"):
        markers.marker_items(marker(Marker.MESH_RESOURCE), np.eye(4))


def test_add_replaces_by_namespace_and_id_delete_removes_one_deleteall_all():
    store = markers.MarkerStore()
    for ns, id_ in (("a", 0), ("a", 1), ("b", 0), ("a", 0)):
        store.apply(marker(Marker.CUBE, ns=ns, id_=id_), now=0.0)
    assert store.namespaces() == {"a": 2, "b": 1}
    store.apply(marker(Marker.CUBE, ns="a", id_=1, action=Marker.DELETE), now=0.0)
    assert store.namespaces() == {"a": 1, "b": 1}
    store.apply(marker(Marker.CUBE, ns="b", action=Marker.DELETEALL), now=0.0)
    assert store.namespaces() == {"a": 1}
    store.apply(marker(Marker.CUBE, ns="", action=Marker.DELETEALL), now=0.0)
    assert store.namespaces() == {}


def test_a_marker_with_a_lifetime_expires_and_one_without_stays():
    store = markers.MarkerStore()
    store.apply(marker(Marker.CUBE, id_=0, lifetime=0.5), now=10.0)
    store.apply(marker(Marker.CUBE, id_=1), now=10.0)
    assert not store.expire(10.4) and len(store.kept) == 2
    assert store.expire(10.5) and list(store.kept) == [("test", 1)]
