"""physics.World.load_world on hand-built world descriptions: static meshes collide as their triangles (a
hollow ring stays hollow), map walls as one triangle mesh, dynamic bodies fall, rest and reset, and
``top_at`` finds what a robot would be spawned onto."""
import math

import numpy as np
import pybullet
import pytest

from diffbot_sim.description import mesh_formats
from diffbot_sim.physics import World
from diffbot_sim.world.bodies import Body, Shape, WorldDescription

DT = 1.0 / 240.0


def ring_obj(path, inner=1.0, outer=1.2, height=0.5, segments=24):
    """A hollow ring (a thick circular wall) as an .obj: its convex hull would be a solid disc."""
    verts, faces = [], []
    for i in range(segments):
        a = 2 * math.pi * i / segments
        for r in (inner, outer):
            for z in (0.0, height):
                verts.append((r * math.cos(a), r * math.sin(a), z))
    for i in range(segments):
        j = (i + 1) % segments
        ib, ob = 4 * i, 4 * j  # vertex blocks: inner-bottom, inner-top, outer-bottom, outer-top
        for quad in ((ib + 0, ob + 0, ob + 1, ib + 1), (ib + 2, ib + 3, ob + 3, ob + 2),
                     (ib + 1, ob + 1, ob + 3, ib + 3), (ib + 0, ib + 2, ob + 2, ob + 0)):
            faces += [(quad[0], quad[1], quad[2]), (quad[0], quad[2], quad[3])]
    mesh_formats.write_obj(str(path), np.array(verts, float), np.array(faces, int))
    return str(path)


@pytest.fixture
def world():
    w = World(DT)
    yield w
    w.close()


def ball(world, x, y, z, radius=0.1):
    shape = pybullet.createCollisionShape(pybullet.GEOM_SPHERE, radius=radius, physicsClientId=world.client)
    return pybullet.createMultiBody(1.0, shape, basePosition=(x, y, z), physicsClientId=world.client)


def settle(world, seconds=2.0):
    for _ in range(int(seconds / DT)):
        world.step()


def z_of(world, uid):
    return pybullet.getBasePositionAndOrientation(uid, physicsClientId=world.client)[0][2]


def test_static_mesh_ring_stays_hollow(world, tmp_path):
    path = ring_obj(tmp_path / "ring.obj")
    desc = WorldDescription("w", "test", [Body("ring::link", "ring", ((0, 0, 0), (0, 0, 0, 1)), True,
                                               [Shape("mesh", mesh=path)])])
    assert world.load_world(desc, str(tmp_path / "cache")) == 1
    inside, on_wall = ball(world, 0.0, 0.0, 1.0), ball(world, 1.1, 0.0, 1.0)
    settle(world)
    assert z_of(world, inside) == pytest.approx(0.1, abs=0.01)  # fell through the hole to the ground
    assert z_of(world, on_wall) == pytest.approx(0.6, abs=0.02)  # rests on the ring's top


def test_trimesh_walls_and_top_at(world):
    # one 1 x 1 x 0.8 m block as a triangle mesh (what a map image becomes)
    lo, hi = np.array([2.0, -0.5, 0.0]), np.array([3.0, 0.5, 0.8])
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    tris = np.array([(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6),
                     (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)])
    desc = WorldDescription("map", "test", [Body("map::walls", "map", ((0, 0, 0), (0, 0, 0, 1)), True,
                                                 [Shape("trimesh", vertices=corners, indices=tris)])])
    world.load_world(desc, "/nonexistent")
    assert world.top_at(2.5, 0.0) == pytest.approx(0.8, abs=1e-6)
    assert world.top_at(0.0, 0.0) == pytest.approx(0.0, abs=1e-6)
    on_top = ball(world, 2.5, 0.0, 2.0)
    settle(world)
    assert z_of(world, on_top) == pytest.approx(0.9, abs=0.02)


def test_dynamic_box_falls_rests_and_resets(world):
    start = ((0.0, 0.0, 1.0), pybullet.getQuaternionFromEuler((0, 0, 0.3)))
    box = Body("box::link", "box", start, False, [Shape("box", size=(0.3, 0.3, 0.3), surface={"mu": 100.0})],
               mass=2.0, inertia=(0.03, 0.03, 0.03, 0, 0, 0))
    wall = Body("wall::link", "wall", ((0.0, 2.0, 0.5), (0, 0, 0, 1)), True, [Shape("box", size=(4, 0.1, 1))])
    world.load_world(WorldDescription("w", "test", [box, wall]), "/nonexistent")
    (uid, _), (wall_uid, _) = world.world_bodies
    assert pybullet.getDynamicsInfo(uid, -1, physicsClientId=world.client)[0] == pytest.approx(2.0)
    assert pybullet.getDynamicsInfo(wall_uid, -1, physicsClientId=world.client)[0] == 0.0
    assert pybullet.getDynamicsInfo(uid, -1, physicsClientId=world.client)[1] == pytest.approx(1.0)  # capped
    settle(world)
    rest = world.body_pose(uid, box.inertial_pose)
    assert rest[0][2] == pytest.approx(0.15, abs=0.01)
    world.reset()
    back = world.body_pose(uid, box.inertial_pose)
    assert back[0] == pytest.approx(start[0], abs=1e-6)
    assert world.body_pose(wall_uid, wall.inertial_pose)[0] == pytest.approx((0.0, 2.0, 0.5), abs=1e-6)


def test_world_ground_plane_replaces_ours(world):
    ground = Body("ground_plane::link", "ground_plane", ((0, 0, 0), (0, 0, 0, 1)), True,
                  [Shape("plane", size=(0, 0, 1), surface={"mu": 100.0, "mu2": 50.0})])
    world.load_world(WorldDescription("w", "test", [ground], has_ground=True), "/nonexistent")
    assert world.plane is None
    fall = ball(world, 0, 0, 1.0)
    settle(world)
    assert z_of(world, fall) == pytest.approx(0.1, abs=0.01)
