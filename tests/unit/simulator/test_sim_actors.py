"""simulator.actors with a PyBullet world (DIRECT, no master): an actor's box follows its script or its
libActorPlugin.so walk where rays meet it, a walker steers around every model origin, set_model_state and the
resets."""
import math
import xml.etree.ElementTree as ET
from types import SimpleNamespace

import pytest

from diffbot_sim.physics import World
from diffbot_sim.simulator.actors import Actors
from diffbot_sim.world.actor_sdf import read_actor
from diffbot_sim.world.actor_walk import PERSON_SIZE, WALK_ROOT_HEIGHT
from diffbot_sim.world.bodies import Body, Shape, WorldDescription

#: walks +x from (0, 0) to (4, 0) in 4 s, facing +x
SCRIPTED = """<actor name="walker"><pose>0 0 0 0 0 0</pose><script><loop>false</loop>
  <trajectory id="0" type="walking">
    <waypoint><time>0</time><pose>0 0 0 0 0 0</pose></waypoint>
    <waypoint><time>4</time><pose>4 0 0 0 0 0</pose></waypoint>
  </trajectory></script></actor>"""
#: cafe.world's walker, heading for (0, -5)
WALKER = """<actor name="cafe_walker"><pose>0 0 1.2138 0 0 0</pose>
  <plugin name="p" filename="libActorPlugin.so"><target>0 -5 1.2138</target>
    <ignore_obstacles><model>ground_plane</model></ignore_obstacles></plugin></actor>"""


def description(xml):
    return read_actor(ET.fromstring(xml), "test.world: /sdf/world/actor", [])


@pytest.fixture
def world():
    physics = World(0.001, gravity=0.0)
    yield physics
    physics.close()


def hit_x(world, y=0.0, z=0.9):
    """x of the first thing a ray along +x at height z meets, from x = -10 (None: nothing)."""
    fractions, bodies, _ = world.ray_batch([(-10.0, y, z)], [(10.0, y, z)])
    return None if bodies[0] < 0 else -10.0 + 20.0 * fractions[0]


def test_a_scripted_actor_is_a_person_sized_box_where_its_script_puts_it(world):
    actors = Actors(world, [description(SCRIPTED)], seed=0, robots=lambda: [])
    (actor,) = actors.actors
    assert len(actors) == 1 and actor.script is not None and actor.walker is None
    assert (actor.size_x, actor.size_y, actor.size_z) == PERSON_SIZE
    # Before the script's first frame (1/30 s in) Gazebo's actor stands at its <pose> with no body: the box
    # waits out of the way, so it cannot shove a robot spawned there
    assert hit_x(world) is None
    actors.before_step(0.04)  # the first frame is drawn once 1/30 s has passed
    assert 0.0 < actor.pose[0][0] < 0.05  # the first frame: near the script's start
    assert hit_x(world) == pytest.approx(actor.pose[0][0] - PERSON_SIZE[0] / 2, abs=1e-3)
    assert hit_x(world, z=PERSON_SIZE[2] + 0.05) is None  # no taller than a person
    actors.before_step(2.0)
    assert actor.pose[0] == pytest.approx((2.0, 0.0, 0.0), abs=1e-6)
    assert hit_x(world) == pytest.approx(2.0 - PERSON_SIZE[0] / 2, abs=1e-3)  # the body went with it


def test_set_pose_holds_until_the_script_moves_it_again(world):
    actors = Actors(world, [description(SCRIPTED)], seed=0, robots=lambda: [])
    (actor,) = actors.actors
    actor.set_pose(((-3.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)))
    assert hit_x(world) == pytest.approx(-3.0 - PERSON_SIZE[0] / 2, abs=1e-3)
    actors.before_step(1.0)
    assert 0.5 < actor.pose[0][0] < 1.5  # on its spline again
    assert hit_x(world) == pytest.approx(actor.pose[0][0] - PERSON_SIZE[0] / 2, abs=1e-3)


def test_reset_replays_the_script_from_its_start(world):
    actors = Actors(world, [description(SCRIPTED)], seed=0, robots=lambda: [])
    (actor,) = actors.actors
    actors.before_step(3.0)
    actors.reset(3.0)  # reset_world at sim time 3: back to the <pose>, the script again from now
    assert actor.pose[0] == (0.0, 0.0, 0.0)
    assert hit_x(world) is None  # until the first frame again
    actors.before_step(3.04)
    assert hit_x(world) == pytest.approx(actor.pose[0][0] - PERSON_SIZE[0] / 2, abs=1e-3)
    actors.before_step(5.0)
    assert actor.pose[0] == pytest.approx((2.0, 0.0, 0.0), abs=1e-6)  # half way, as 2 s after the start


def furniture(world, tmp_path):
    """A static table at (3, 0) and a loose box at (0, 3), as a world file's models."""
    bodies = [Body("table::top", "table", ((3.0, 0.0, 0.5), (0, 0, 0, 1)), True, [Shape("box", (1, 1, 1))]),
              Body("crate::link", "crate", ((0.0, 3.0, 0.5), (0, 0, 0, 1)), False, [Shape("box", (1, 1, 1))])]
    world.load_world(WorldDescription("w", "w.world", bodies=bodies), str(tmp_path))


def test_a_walker_steers_around_every_model_origin(world, tmp_path):
    furniture(world, tmp_path)
    robot = SimpleNamespace(name="robot1", ctx=SimpleNamespace(robot=SimpleNamespace(
        base_pose=lambda: ((1.0, -1.0, 0.1), (0.0, 0.0, 0.0, 1.0)))))
    actors = Actors(world, [description(SCRIPTED), description(WALKER)], seed=1, robots=lambda: [robot])
    scripted, walker = actors.actors
    assert walker.walker is not None and walker.script is None
    obstacles = actors.obstacles()
    assert set(obstacles) == {"table", "crate", "robot1", "walker", "cafe_walker"}
    assert obstacles["table"] == pytest.approx((3.0, 0.0, 0.5)) and obstacles["robot1"] == (1.0, -1.0, 0.1)
    assert obstacles["cafe_walker"] == (0.0, 0.0, 1.2138)
    alone = Actors(world, [description(WALKER)], seed=1, robots=lambda: [])
    for step in range(1, 200):
        actors.before_step(step * 0.001)
        alone.before_step(step * 0.001)
    assert walker.pose[0][2] == WALK_ROOT_HEIGHT  # the plugin holds the root bone's height
    assert walker.pose[1] != alone.actors[0].pose[1]  # the robot and the other actor changed its course
    actors.reset(0.2)
    assert walker.pose == walker.description.world_pose


def test_the_box_faces_the_walking_direction(world):
    yaw = math.pi / 2
    turned = SCRIPTED.replace("<pose>4 0 0 0 0 0</pose>", f"<pose>0 4 0 0 0 {yaw}</pose>").replace(
        "<time>0</time><pose>0 0 0 0 0 0</pose>", f"<time>0</time><pose>0 0 0 0 0 {yaw}</pose>")
    actors = Actors(world, [description(turned)], seed=0, robots=lambda: [])
    actors.before_step(0.1)
    # facing +y, along x the box is as wide as a person (0.5 m), not as deep (0.35 m)
    assert hit_x(world) == pytest.approx(-PERSON_SIZE[1] / 2, abs=1e-3)


CRATE_ROBOT = """<robot name="crate"><link name="base_link">
  <inertial><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
  <collision><geometry><box size="0.3 0.3 0.2"/></geometry></collision></link></robot>"""


def test_a_robot_in_the_walkers_path_is_not_shoved_and_rays_still_see_the_walker():
    """Gazebo's actors collide with nothing: a robot standing where a script walks is walked through, not shoved
    (a solid box shoved a robot that had stopped for a walker 0.6 m, and amcl lost it); lasers still see it."""
    import pybullet

    from diffbot_sim.description.urdf_model import parse_urdf

    world = World(1.0 / 240.0)
    try:
        actors = Actors(world, [description(SCRIPTED)], seed=0, robots=lambda: [])
        robot = world.load_robot(CRATE_ROBOT, parse_urdf(CRATE_ROBOT, "crate.urdf"), position=(2.0, 0.0, 0.0))
        now, seen = 0.0, []
        while now < 4.0:
            now += world.time_step
            actors.before_step(now)
            world.step()
            if 1.9 < actors.actors[0].pose[0][0] < 2.1:  # the walker inside the robot's box
                seen.append(hit_x(world, z=1.5))  # above the robot: the walker's front face
        (x, y, _), _ = pybullet.getBasePositionAndOrientation(robot.body, physicsClientId=world.client)
        assert math.hypot(x - 2.0, y) < 0.005, f"the walker shoved the robot to ({x:.3f}, {y:.3f})"
        assert seen and all(h is not None and 1.7 < h < 1.95 for h in seen), seen
    finally:
        world.close()
