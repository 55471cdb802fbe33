"""messages/markers.py: a world's static shapes (world.markers specs) fill one MarkerArray for rviz."""
import math

import numpy as np
from visualization_msgs.msg import Marker

from diffbot_sim.messages.markers import marker_array
from diffbot_sim.world.bodies import Body, Shape, WorldDescription

Q90 = (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))


def world():
    return WorldDescription("w", "w.world", bodies=[
        Body("ground::link", "ground", ((0, 0, 0), (0, 0, 0, 1)), True, [Shape("plane", (0, 0, 1))]),
        Body("wall::link", "wall", ((3.0, 0.0, 0.5), Q90), True,
             [Shape("box", (6.0, 0.2, 1.0)), Shape("box", (1.0, 1.0, 1.0))], color=(1, 0, 0, 1)),
        Body("pillar::link", "pillar", ((0.5, 1.2, 0.5), (0, 0, 0, 1)), True, [Shape("cylinder", (0.2, 1.0))]),
        Body("ring::link", "ring", ((-1, 0, 0), (0, 0, 0, 1)), True, [Shape("mesh", mesh="/m/ring.dae",
                                                                            scale=(2, 2, 1))]),
        Body("ball::link", "ball", ((0, 2, 0.3), (0, 0, 0, 1)), True, [Shape("sphere", (0.3,))]),
        Body("box::link", "box", ((1, 1, 0.1), (0, 0, 0, 1)), False, [Shape("box", (0.2, 0.2, 0.2))]),
    ])


def test_the_array_starts_with_a_delete_all_in_the_frame():
    array = marker_array(world(), "map")
    clear = array.markers[0]
    assert clear.action == Marker.DELETEALL and clear.header.frame_id == "map"
    assert all(m.header.frame_id == "map" for m in array.markers)
    assert all(m.action == Marker.ADD for m in array.markers[1:])


def test_each_static_shape_is_one_marker_of_its_type_with_ids_per_body():
    markers = marker_array(world()).markers[1:]  # no plane, no dynamic box
    assert [(m.ns, m.id, m.type) for m in markers] == [
        ("wall::link", 0, Marker.CUBE), ("wall::link", 1, Marker.CUBE), ("pillar::link", 0, Marker.CYLINDER),
        ("ring::link", 0, Marker.MESH_RESOURCE), ("ball::link", 0, Marker.SPHERE)]
    wall, _, pillar, ring, ball = markers
    assert (wall.pose.position.x, wall.pose.position.z) == (3.0, 0.5)
    assert (wall.pose.orientation.z, wall.pose.orientation.w) == Q90[2:]
    assert (wall.scale.x, wall.scale.y, wall.scale.z) == (6.0, 0.2, 1.0)
    assert (wall.color.r, wall.color.g, wall.color.a) == (1, 0, 1)
    assert (pillar.scale.x, pillar.scale.z) == (0.4, 1.0)
    assert ring.mesh_resource == "file:///m/ring.dae" and not ring.mesh_use_embedded_materials
    assert (ring.scale.x, ring.scale.z) == (2, 1)
    assert ball.scale.x == ball.scale.y == 0.6
    assert all(m.header.stamp.to_sec() == 0 for m in markers)  # rviz draws them with the latest transform


def test_map_walls_become_triangle_list_points():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=float)
    w = WorldDescription("m", "m.yaml", bodies=[Body("map::walls", "map", ((0, 0, 0), (0, 0, 0, 1)), True,
                                                     [Shape("trimesh", vertices=vertices,
                                                            indices=np.array([[0, 1, 2]]))])])
    (wall,) = marker_array(w).markers[1:]
    assert wall.type == Marker.TRIANGLE_LIST
    assert [(p.x, p.y, p.z) for p in wall.points] == [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
    assert all(type(p.x) is float for p in wall.points)  # numpy numbers would not serialize
