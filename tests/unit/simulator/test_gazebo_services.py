"""simulator.gazebo_services: the /gazebo service handlers without a ROS master, called with gazebo_msgs' own
request objects against a PyBullet world (the loop's ``call`` runs them at once): spawning SDF models and robots,
model and link states in frames, deleting, wrenches, properties, joint positions. Poses are judged by the bodies
PyBullet holds, not by what the services answer about them."""
import math
import os
from types import SimpleNamespace

import genpy
import pytest
import rospy
from gazebo_msgs import srv as gsrv
from geometry_msgs.msg import Point, Pose, Quaternion, Twist, Vector3, Wrench

from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.physics import World
from diffbot_sim.simulator.gazebo_services import GazeboApi

DT = 1.0 / 240.0
S = math.sqrt(0.5)
YAW90 = Quaternion(0.0, 0.0, S, S)
UPRIGHT = Quaternion(0.0, 0.0, 0.0, 1.0)
ARM = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "data",
                   "robots", "arm_position_nogains.urdf")


def box_sdf(name, size=0.5, static=False, pose="0 0 0 0 0 0", collision=True):
    inertial = "" if static else ("<inertial><mass>5</mass><inertia><ixx>0.2</ixx><iyy>0.2</iyy><izz>0.2</izz>"
                                  "</inertia></inertial>")
    geometry = f"<geometry><box><size>{size} {size} {size}</size></box></geometry>"
    shape = f'<collision name="c">{geometry}</collision>' if collision else f'<visual name="v">{geometry}</visual>'
    return (f'<sdf version="1.6"><model name="{name}"><static>{str(static).lower()}</static><pose>{pose}</pose>'
            f'<link name="link">{inertial}{shape}</link></model></sdf>')


class Sim:
    """The simulator as the /gazebo services use it: a PyBullet world, its robots, sim time, the loop's
    ``call`` (run at once: the test is the loop)."""

    def __init__(self):
        self.world = World(DT)
        self.robots = []
        self.actors = None
        self.sim_time = 0.0
        self.paused = False
        self.cfg = SimpleNamespace(gazebo_namespace="/gazebo", time_step=DT, real_time_factor=1.0, real_time=True)
        self.warned = []

    def call(self, action, timeout=None):
        return action()

    def post(self, action):
        action()

    def warn(self, key, text):
        self.warned.append(text)

    def stamp(self):
        return rospy.Time.from_sec(self.sim_time)

    def remove_robot(self, runtime):
        self.robots.remove(runtime)
        self.world.remove_robot(runtime.ctx.robot)


@pytest.fixture
def api():
    """A GazeboApi on an empty world; ``api.spawned`` records what the URDF spawn callback was handed."""
    sim = Sim()
    spawned = []

    def spawn_urdf(name, text, source, pose):
        model = parse_urdf(text, source)
        robot = sim.world.load_robot(text, model, pose[0], orientation=pose[1])
        runtime = SimpleNamespace(name=name, ctx=SimpleNamespace(robot=robot, model=model, sim=sim))
        sim.robots.append(runtime)
        spawned.append((name, text, source, pose))
        return runtime
    service = GazeboApi(sim, spawn_urdf)
    service.spawned = spawned
    yield service
    service.close()
    for handle in (service.model_states_pub, service.link_states_pub):
        handle.unregister()
    sim.world.close()


def spawn(api, name, xml, x=0.0, y=0.0, z=0.0, orientation=UPRIGHT, frame="", kind="sdf", namespace=""):
    request = gsrv.SpawnModelRequest(model_name=name, model_xml=xml, robot_namespace=namespace,
                                     initial_pose=Pose(Point(x, y, z), orientation), reference_frame=frame)
    return api._spawn(request, kind)


def body_pose(api, name):
    """Where PyBullet holds model ``name``'s (first) body: its link frame, world axes."""
    entity = api.models()[name]
    uid, body = entity.bodies[0]
    return api.sim.world.body_pose(uid, body.inertial_pose)


def steps(api, seconds):
    """The loop's side: the API's per-step work, then a physics step."""
    for _ in range(round(seconds / DT)):
        api.before_step(api.sim.sim_time)
        api.sim.world.step()
        api.sim.sim_time += DT


# -- spawn, list, delete --------------------------------------------------------------------------------------

def test_a_spawned_sdf_model_stands_where_the_request_puts_its_own_pose(api):
    answer = spawn(api, "crate", box_sdf("crate", pose="0 0 0.25 0 0 0"), x=1.0, y=2.0, z=0.0,
                   orientation=YAW90)
    assert answer.success and answer.status_message == "SpawnModel: Successfully spawned entity 'crate' (1 bodies)"
    position, orientation = body_pose(api, "crate")
    assert position == pytest.approx((1.0, 2.0, 0.25), abs=1e-9)  # the file's pose composed on the request's
    assert orientation == pytest.approx((0.0, 0.0, S, S), abs=1e-7)  # PyBullet keeps it in single precision
    assert api._world_properties(gsrv.GetWorldPropertiesRequest()).model_names == ["crate"]


@pytest.mark.parametrize("name, message", [
    ("crate", "SpawnModel: Failure - entity 'crate' already exists."),
    ("a/b", "SpawnModel: model_name 'a/b' is not a valid model name"),
    ("", "SpawnModel: model_name '' is not a valid model name"),
])
def test_a_spawn_gazebo_refuses_is_refused_with_its_words(api, name, message):
    assert spawn(api, "crate", box_sdf("crate")).success
    answer = spawn(api, name, box_sdf("other"), x=3.0)
    assert not answer.success and answer.status_message == message
    assert len(api.sim.world.world_bodies) == 1  # nothing built


def test_a_spawn_relative_to_a_model_is_placed_in_its_frame(api):
    spawn(api, "wall", box_sdf("wall", static=True), x=1.0, y=0.0, z=0.5, orientation=YAW90)
    assert spawn(api, "crate", box_sdf("crate"), x=2.0, y=0.0, z=0.0, frame="wall").success
    assert body_pose(api, "crate")[0] == pytest.approx((1.0, 2.0, 0.5), abs=1e-9)  # 2 m along the wall's x = +y


def test_a_spawn_relative_to_an_unknown_frame_is_refused(api):
    answer = spawn(api, "crate", box_sdf("crate"), frame="nowhere")
    assert not answer.success and "reference_frame 'nowhere' not found" in answer.status_message


def test_delete_removes_the_bodies_from_the_physics(api):
    spawn(api, "crate", box_sdf("crate"), z=0.25)
    uid = api.sim.world.world_bodies[0][0]
    answer = api._delete(gsrv.DeleteModelRequest(model_name="crate"))
    assert answer.success and answer.status_message == "DeleteModel: successfully deleted model 'crate'"
    assert api.sim.world.world_bodies == [] and uid not in api.sim.world.ray_batch([(0, 0, 1)], [(0, 0, -1)])[1]
    gone = api._get_model_state(gsrv.GetModelStateRequest(model_name="crate"))
    assert not gone.success and gone.status_message == "GetModelState: model 'crate' does not exist"


def test_a_model_with_nothing_that_collides_is_a_model_without_a_body(api):
    answer = spawn(api, "marker", box_sdf("marker", collision=False), x=3.0, y=1.0, z=0.0)
    assert answer.success and answer.status_message.endswith("(0 bodies)")
    assert api.sim.world.world_bodies == []
    state = api._get_model_state(gsrv.GetModelStateRequest(model_name="marker"))
    assert (state.pose.position.x, state.pose.position.y) == (3.0, 1.0)
    moved = gsrv.SetModelStateRequest()
    moved.model_state.model_name, moved.model_state.pose = "marker", Pose(Point(5.0, 0.0, 0.0), UPRIGHT)
    assert api._set_model_state(moved).success
    assert api._get_model_state(gsrv.GetModelStateRequest(model_name="marker")).pose.position.x == 5.0
    api.reset()  # reset_world: back where it was spawned
    assert api._get_model_state(gsrv.GetModelStateRequest(model_name="marker")).pose.position.x == 3.0
    assert api._delete(gsrv.DeleteModelRequest(model_name="marker")).success and api.models() == {}


# -- states -----------------------------------------------------------------------------------------------

def test_a_model_state_relative_to_another_model_is_in_its_frame(api):
    spawn(api, "wall", box_sdf("wall", static=True), x=1.0, y=0.0, z=0.5, orientation=YAW90)
    spawn(api, "post", box_sdf("post", static=True), x=1.0, y=2.0, z=0.5)
    state = api._get_model_state(gsrv.GetModelStateRequest(model_name="post", relative_entity_name="wall"))
    assert state.success and state.header.frame_id == "wall"
    p, q = state.pose.position, state.pose.orientation
    assert (p.x, p.y, p.z) == pytest.approx((2.0, 0.0, 0.0), abs=1e-9)  # +y in the world is the wall's +x
    assert (q.x, q.y, q.z, q.w) == pytest.approx((0.0, 0.0, -S, S), abs=1e-9)


def test_set_model_state_teleports_the_body(api):
    spawn(api, "crate", box_sdf("crate"), z=0.25)
    request = gsrv.SetModelStateRequest()
    request.model_state.model_name = "crate"
    request.model_state.pose = Pose(Point(-1.0, 0.5, 0.25), YAW90)
    request.model_state.twist = Twist(Vector3(0.0, 0.0, 0.0), Vector3(0.0, 0.0, 0.0))
    answer = api._set_model_state(request)
    assert answer.success and answer.status_message == "SetModelState: set model state done"
    position, orientation = body_pose(api, "crate")
    assert position == pytest.approx((-1.0, 0.5, 0.25), abs=1e-9)
    assert orientation == pytest.approx((0.0, 0.0, S, S), abs=1e-7)  # PyBullet keeps it in single precision


def test_a_non_finite_pose_is_refused_and_nothing_moves(api):
    spawn(api, "crate", box_sdf("crate"), z=0.25)
    request = gsrv.SetModelStateRequest()
    request.model_state.model_name = "crate"
    request.model_state.pose = Pose(Point(math.nan, 0.0, 0.0), UPRIGHT)
    answer = api._set_model_state(request)
    assert not answer.success and "nan" in answer.status_message
    assert body_pose(api, "crate")[0] == pytest.approx((0.0, 0.0, 0.25), abs=1e-9)


def test_link_states_name_model_and_link(api):
    spawn(api, "crate", box_sdf("crate"), x=1.0, z=0.25)
    state = api._get_link_state(gsrv.GetLinkStateRequest(link_name="crate::link", reference_frame="world"))
    assert state.success and state.link_state.pose.position.x == pytest.approx(1.0)
    request = gsrv.SetLinkStateRequest()
    request.link_state.link_name, request.link_state.pose = "crate::link", Pose(Point(2.0, 0.0, 0.25), UPRIGHT)
    assert api._set_link_state(request).success
    assert body_pose(api, "crate")[0] == pytest.approx((2.0, 0.0, 0.25), abs=1e-9)
    missing = api._get_link_state(gsrv.GetLinkStateRequest(link_name="crate::lid"))
    assert not missing.success and missing.status_message == "GetLinkState: link 'crate::lid' does not exist"


# -- wrenches ---------------------------------------------------------------------------------------------

def test_a_wrench_pushes_the_body_for_its_duration_from_its_start(api):
    spawn(api, "crate", box_sdf("crate"), z=0.25)
    steps(api, 0.5)  # settled on the ground
    start = body_pose(api, "crate")[0]
    push = gsrv.ApplyBodyWrenchRequest(body_name="crate::link", reference_frame="world",
                                       wrench=Wrench(Vector3(0.0, 0.0, 100.0), Vector3()),
                                       start_time=genpy.Time.from_sec(api.sim.sim_time + 0.1),
                                       duration=genpy.Duration.from_sec(0.2))
    assert api._apply_wrench(push).success
    steps(api, 0.1 - DT / 2)
    assert body_pose(api, "crate")[0][2] == pytest.approx(start[2], abs=1e-3)  # not yet
    steps(api, 0.2)
    # 100 N up on 5 kg: (20 - 9.81) m/s^2 for 0.2 s, as Gazebo's wrench is applied each step of its duration
    rise = body_pose(api, "crate")[0][2] - start[2]
    assert rise == pytest.approx(0.5 * (100.0 / 5.0 - 9.81) * 0.2 ** 2, rel=0.1)
    assert len(api.wrenches) == 0  # over


def test_clear_body_wrenches_stops_a_push(api):
    spawn(api, "crate", box_sdf("crate"), z=0.25)
    steps(api, 0.5)
    push = gsrv.ApplyBodyWrenchRequest(body_name="crate::link", wrench=Wrench(Vector3(0.0, 0.0, 100.0), Vector3()),
                                       duration=genpy.Duration(-1))  # until cleared
    api._apply_wrench(push)
    steps(api, 0.1)
    api._clear_wrenches(gsrv.BodyRequestRequest(body_name="crate::link"))
    steps(api, 0.05)
    rising = body_pose(api, "crate")[0][2]
    steps(api, 0.05)
    assert body_pose(api, "crate")[0][2] < rising + 0.05 * 1.1  # no more push: decelerating under gravity


def test_a_wrench_on_an_unknown_body_is_refused(api):
    push = gsrv.ApplyBodyWrenchRequest(body_name="ghost::link", wrench=Wrench(Vector3(1, 0, 0), Vector3()))
    answer = api._apply_wrench(push)
    assert not answer.success and answer.status_message == "ApplyBodyWrench: body 'ghost' does not exist"


# -- robots -------------------------------------------------------------------------------------------------

URDF_WITH_PLUGIN = open(ARM).read().replace(
    "</robot>", '<gazebo><plugin name="p3d" filename="libgazebo_ros_p3d.so"><bodyName>tool_link</bodyName>'
                "<topicName>tool_pose</topicName></plugin></gazebo></robot>")


def test_a_spawned_urdf_is_renamed_namespaced_and_placed_in_its_reference_frame(api):
    spawn(api, "wall", box_sdf("wall", static=True), x=1.0, z=0.5, orientation=YAW90)
    answer = spawn(api, "arm1", URDF_WITH_PLUGIN, x=1.0, frame="wall", kind="urdf", namespace="/arm1")
    assert answer.success and answer.status_message == "SpawnModel: Successfully spawned entity 'arm1'"
    ((name, text, source, pose),) = api.spawned
    assert name == "arm1" and source == "/gazebo/spawn_urdf_model(arm1)"
    assert '<robot name="arm1">' in text and "<robotNamespace>/arm1</robotNamespace>" in text
    assert pose[0] == pytest.approx((1.0, 1.0, 0.5), abs=1e-9)  # 1 m along the wall's x: +y
    assert api._world_properties(gsrv.GetWorldPropertiesRequest()).model_names == ["wall", "arm1"]


def test_model_properties_of_a_robot_and_of_a_world_model(api):
    spawn(api, "arm1", open(ARM).read(), kind="urdf")
    spawn(api, "wall", box_sdf("wall", static=True), z=2.0)
    robot = api._model_properties(gsrv.GetModelPropertiesRequest(model_name="arm1"))
    assert robot.success and robot.canonical_body_name == "base_link" and not robot.is_static
    assert robot.joint_names == ["joint_1", "joint_2", "joint_3"]  # tool_joint is fixed
    assert robot.body_names == ["base_link", "link_1", "link_2", "link_3"]  # tool_link lumped into link_3
    wall = api._model_properties(gsrv.GetModelPropertiesRequest(model_name="wall"))
    assert wall.is_static and wall.body_names == ["link"] and wall.joint_names == []


def test_set_model_configuration_puts_the_joints_there_clamped_to_their_limits(api):
    spawn(api, "arm1", open(ARM).read(), kind="urdf")
    request = gsrv.SetModelConfigurationRequest(model_name="arm1", joint_names=["joint_1", "joint_2", "nope"],
                                                joint_positions=[0.4, 5.0, 1.0])
    answer = api._set_configuration(request)
    assert answer.success and answer.status_message == "SetModelConfiguration: success"
    robot = api.sim.robots[0].ctx.robot
    positions, velocities, _ = robot.joint_states(robot.indices(["joint_1", "joint_2"]))
    assert positions == pytest.approx([0.4, 2.0], abs=1e-9) and velocities == [0.0, 0.0]  # <limit upper="2.0">
    uneven = gsrv.SetModelConfigurationRequest(model_name="arm1", joint_names=["joint_1"], joint_positions=[])
    assert api._set_configuration(uneven).status_message == ("SetModelConfiguration: joint name and position "
                                                              "list have different lengths")


def test_deleting_a_robot_removes_its_body(api):
    spawn(api, "arm1", open(ARM).read(), x=3.0, kind="urdf")
    body = api.sim.robots[0].ctx.robot.body
    assert api._delete(gsrv.DeleteModelRequest(model_name="arm1")).success
    assert api.sim.robots == [] and api.sim.world.robots == []
    hits = api.sim.world.ray_batch([(3.0, 0.0, 2.0)], [(3.0, 0.0, -1.0)])[1]
    assert body not in hits.tolist()  # the ray finds the ground where the arm stood


def test_a_wrench_on_a_model_without_a_body_is_refused_and_the_loop_goes_on(api):
    """A visual-only model (nothing collides, so nothing for the physics to push) is refused when asked, not on
    the loop's next step, where the error took the loop down."""
    spawn(api, "marker", box_sdf("marker", collision=False), z=1.0)
    push = gsrv.ApplyBodyWrenchRequest(body_name="marker::link", wrench=Wrench(Vector3(1, 0, 0), Vector3()),
                                       duration=genpy.Duration(-1))
    answer = api._apply_wrench(push)
    assert not answer.success and "no body to push" in answer.status_message
    assert len(api.wrenches) == 0
    steps(api, 0.01)  # the loop's steps raise nothing
