"""simulator.gazebo_models: the models /gazebo names, each answering links, motion, set_motion and body_of
(fake robots, worlds and actors: no physics, no master)."""
import math
from types import SimpleNamespace

import pytest

from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.gazebo.world_api import RequestError
from diffbot_sim.simulator.gazebo_models import (
    ActorModelEntity,
    GhostModelEntity,
    RobotModelEntity,
    WorldModelEntity,
)
from diffbot_sim.world.bodies import Body

ZERO = (0.0, 0.0, 0.0)
IDENTITY = (ZERO, (0.0, 0.0, 0.0, 1.0))
YAW90 = (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))


def approx_pose(pose):
    return pytest.approx(list(pose[0]) + list(pose[1]), abs=1e-12)


def flat(pose):
    return list(pose[0]) + list(pose[1])


# -- a model without bodies ------------------------------------------------------------------------------------

def test_a_ghost_stays_where_it_is_set_and_goes_back_on_reset():
    spawn = ((1.0, 2.0, 0.0), YAW90)
    ghost = GhostModelEntity("goal", spawn, ["marker"])
    assert ghost.static and ghost.links() == ["marker"]
    assert ghost.motion() == (spawn, ZERO, ZERO) and ghost.motion("marker")[0] == spawn
    moved = ((3.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    ghost.set_motion(moved, (1.0, 0.0, 0.0), ZERO)
    assert ghost.motion() == (moved, ZERO, ZERO)  # a pose, never a velocity: nothing simulates it
    ghost.reset()
    assert ghost.motion()[0] == spawn


def test_a_ghost_without_links_has_gazebos_one_link_and_no_body():
    ghost = GhostModelEntity("visual_only", IDENTITY, [])
    assert ghost.links() == ["link"]
    ghost.links().append("x")  # a copy: callers cannot change the model
    assert ghost.links() == ["link"]
    with pytest.raises(KeyError):
        ghost.motion("nope")
    with pytest.raises(RequestError, match="'visual_only' has no body to push"):
        ghost.body_of("link")


# -- an actor ----------------------------------------------------------------------------------------------

class FakeActor:
    name = "walker"

    def __init__(self):
        self.pose = ((1.0, 1.0, 1.2), YAW90)
        self.set_to = []

    def set_pose(self, pose):
        self.set_to.append(pose)
        self.pose = pose


def test_an_actor_is_a_static_one_link_model_at_its_movers_pose():
    actor = FakeActor()
    entity = ActorModelEntity(actor)
    assert (entity.name, entity.static, entity.links()) == ("walker", True, ["link"])
    assert entity.motion() == (actor.pose, ZERO, ZERO)
    actor.pose = ((2.0, 0.0, 0.0), YAW90)  # its script moved it
    assert entity.motion()[0] == actor.pose
    entity.set_motion(IDENTITY, (1.0, 0.0, 0.0), ZERO)
    assert actor.set_to == [IDENTITY]
    with pytest.raises(RequestError, match="actor 'walker' is moved by its script"):
        entity.body_of("link")


# -- a world-file model -----------------------------------------------------------------------------------------

class FakeWorld:
    """Bodies at their link-frame poses; what was set is recorded."""

    def __init__(self):
        self.poses, self.set = {}, []

    def body_motion(self, uid, inertial_pose):
        return self.poses[uid], (0.1, 0.0, 0.0), (0.0, 0.0, 0.2)

    def set_body_motion(self, uid, inertial_pose, pose, linear, angular):
        self.set.append((uid, pose, linear, angular))
        self.poses[uid] = pose


def table_model():
    """A model 'table' at (5, 0, 0) turned 90 degrees, with links top (1 m up) and leg (0.5 m along its x)."""
    model_pose = ((5.0, 0.0, 0.0), YAW90)
    top = Body("table::top", "table", ((5.0, 0.0, 1.0), YAW90), False, model_pose=model_pose)
    leg = Body("table::leg", "table", ((5.0, 0.5, 0.0), YAW90), False, model_pose=model_pose)
    world = FakeWorld()
    world.poses = {7: top.pose, 8: leg.pose}
    return WorldModelEntity("table", [(7, top), (8, leg)], world), world


def test_a_world_model_frame_is_carried_by_its_first_link():
    entity, world = table_model()
    assert entity.links() == ["top", "leg"] and not entity.static
    pose, linear, angular = entity.motion()
    assert flat(pose) == approx_pose(((5.0, 0.0, 0.0), YAW90))
    assert (linear, angular) == ((0.1, 0.0, 0.0), (0.0, 0.0, 0.2))
    assert entity.motion("leg")[0] == ((5.0, 0.5, 0.0), YAW90)
    assert entity.body_of("leg") == (8, -1)
    with pytest.raises(KeyError):
        entity.motion("drawer")


def test_moving_a_world_model_moves_its_links_rigidly():
    entity, world = table_model()
    entity.set_motion(((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)), (1.0, 0.0, 0.0), ZERO)
    (top_uid, top, *_), (leg_uid, leg, *_) = world.set
    assert (top_uid, leg_uid) == (7, 8)
    assert flat(top) == approx_pose(((0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 1.0)))
    assert flat(leg) == approx_pose(((0.5, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)))  # 0.5 m along the model's x
    world.set.clear()
    entity.set_motion(IDENTITY, ZERO, ZERO, "leg")  # one link alone
    assert [uid for uid, *_ in world.set] == [8]


def test_a_world_model_is_static_only_when_every_link_is():
    world = FakeWorld()
    fixed = Body("shelf::a", "shelf", IDENTITY, True)
    loose = Body("shelf::b", "shelf", IDENTITY, False)
    assert WorldModelEntity("shelf", [(1, fixed)], world).static
    assert not WorldModelEntity("shelf", [(1, fixed), (2, loose)], world).static


# -- a robot ---------------------------------------------------------------------------------------------------

ROBOT_URDF = """<robot name="robot1">
  <link name="base_link"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>
    </inertial></link>
  <link name="wheel"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>
    </inertial></link>
  <link name="laser"/>
  <joint name="wheel_joint" type="continuous"><parent link="base_link"/><child link="wheel"/></joint>
  <joint name="laser_joint" type="fixed"><parent link="base_link"/><child link="laser"/></joint>
</robot>"""
#: the same robot bolted to the world 0.5 m up, as arm descriptions bolt theirs (a URDF link named world)
FIXED_URDF = ROBOT_URDF.replace('<link name="laser"/>', '<link name="laser"/><link name="world"/>'
                                '<joint name="bolt" type="fixed"><parent link="world"/><child link="base_link"/>'
                                '<origin xyz="0 0 0.5"/></joint>')


class FakeRobot:
    body = 3

    def __init__(self):
        self.base, self.asked = None, []

    def link_motion(self, link):
        self.asked.append(link)
        return IDENTITY, ZERO, ZERO

    def set_base_motion(self, pose, linear, angular):
        self.base = (pose, linear, angular)

    def link_carrier(self, link):
        return {"base_link": -1, "wheel": 0}[link]


class FakePhysics:
    def __init__(self):
        self.lifted = []

    def lift_out(self, robot):
        self.lifted.append(robot)


class Runtime:
    """A RobotRuntime as the entity reads it: name, ctx.robot, ctx.model, ctx.sim.world."""

    def __init__(self, urdf=ROBOT_URDF):
        self.name = "robot1"
        model = parse_urdf(urdf)
        self.ctx = SimpleNamespace(robot=FakeRobot(), model=model, sim=SimpleNamespace(world=FakePhysics()))


def test_a_robot_keeps_its_root_and_moving_links_and_is_moved_whole():
    runtime = Runtime()
    entity = RobotModelEntity(runtime)
    assert entity.links() == ["base_link", "wheel"]  # the laser is lumped into its parent
    entity.motion()
    entity.motion("laser")  # a lumped link still answers
    assert runtime.ctx.robot.asked == ["base_link", "laser"]
    entity.set_motion(((1.0, 0.0, 0.0), YAW90), (0.5, 0.0, 0.0), ZERO)
    assert runtime.ctx.robot.base == (((1.0, 0.0, 0.0), YAW90), (0.5, 0.0, 0.0), ZERO)
    assert runtime.ctx.sim.world.lifted == [runtime.ctx.robot]  # set down, not left in the ground
    with pytest.raises(RequestError, match="not the model's canonical link 'base_link'"):
        entity.set_motion(IDENTITY, ZERO, ZERO, "wheel")
    assert entity.body_of("wheel") == (3, 0)


def test_a_robot_bolted_to_the_world_keeps_its_first_link_and_stays_where_spawned():
    """A URDF ``world`` link is no link of the model: base_link is the canonical link (not lumped into world),
    the model frame sits 0.5 m below it (the bolt's origin), and a new pose does not move it (Gazebo's fixed
    joint to the world pulls it back)."""
    runtime = Runtime(FIXED_URDF)
    entity = RobotModelEntity(runtime)
    assert entity.links() == ["base_link", "wheel"]
    assert flat(entity.motion()[0]) == approx_pose(((0.0, 0.0, -0.5), (0.0, 0.0, 0.0, 1.0)))
    assert entity.motion("base_link")[0] == IDENTITY
    entity.set_motion(((1.0, 0.0, 0.0), YAW90), (0.5, 0.0, 0.0), ZERO)
    assert runtime.ctx.robot.base is None and runtime.ctx.sim.world.lifted == []
