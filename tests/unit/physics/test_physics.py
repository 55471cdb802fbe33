"""physics (World, Robot) on PyBullet DIRECT: faithful mass, poses in the URDF link frame, REP 103 driving, passive
casters, reset, independent worlds. Every test gets fresh worlds, closed by the fixture; runs are short."""
import math
import os

import pybullet
import pytest

from diffbot_sim.control.gazebo_diff_drive import GazeboDiffDriveCore
from diffbot_sim.control.odometry import EncoderOdometry
from diffbot_sim.description import lumping
from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.physics import World
from diffbot_sim.transforms import yaw_from_quaternion

DT = 1.0 / 240.0
R, S, TORQUE = 0.032, 0.2, 30.0
WHEELS = ["left_wheel_joint", "right_wheel_joint"]
CASTERS = ["front_caster_joint", "back_caster_joint"]


@pytest.fixture
def make_world():
    """``make_world()`` -> a new World (DIRECT); every one is closed when the test ends."""
    worlds = []

    def _make(time_step=DT):
        world = World(time_step)
        worlds.append(world)
        return world

    yield _make
    for world in worlds:
        world.close()


@pytest.fixture
def seed(make_world, seed_urdf, seed_model):
    """(world, robot) with the seed robot spawned at the origin."""
    world = make_world()
    return world, world.load_robot(seed_urdf, seed_model)


def run(world, seconds):
    for _ in range(int(round(seconds / world.time_step))):
        world.step()


def pose2d(robot):
    (x, y, _), orientation = robot.base_pose()
    return x, y, yaw_from_quaternion(*orientation)


def angle_diff(a, b):
    return math.atan2(math.sin(a - b), math.cos(a - b))


# -------------------------------------------------------------------------------------------------- mass

def test_loaded_mass_equals_urdf_mass(seed, seed_model):
    _, robot = seed
    assert robot.total_mass() == pytest.approx(seed_model.total_mass(), abs=1e-5)
    assert robot.total_mass() == pytest.approx(1.44, abs=1e-5)


def test_without_lumping_pybullet_adds_a_phantom_kilogram(make_world, seed_urdf, seed_model, monkeypatch):
    monkeypatch.setattr(lumping, "lump", lambda text, root, surface: lumping.LumpedUrdf(text, {}))
    robot = make_world().load_robot(seed_urdf, seed_model)
    assert robot.total_mass() == pytest.approx(seed_model.total_mass() + 1.0, abs=1e-5)


def test_surface_friction_applied(seed):
    world, robot = seed
    links = {pybullet.getJointInfo(robot.body, i, physicsClientId=world.client)[12].decode(): i
             for i in range(pybullet.getNumJoints(robot.body, physicsClientId=world.client))}
    friction = {name: pybullet.getDynamicsInfo(robot.body, index, physicsClientId=world.client)[1]
                for name, index in links.items()}
    assert friction["left_wheel_link"] == pytest.approx(1.0)
    assert friction["front_caster_link"] == pytest.approx(0.0)


# ------------------------------------------------------------------------------------------------- poses

@pytest.mark.parametrize("x, y, yaw", [(0.0, 0.0, 0.0), (0.5, -0.2, 0.7), (-1.5, 2.0, -2.5), (3.0, 0.1, math.pi)])
def test_base_pose_right_after_load_is_spawn_pose(make_world, seed_urdf, seed_model, x, y, yaw):
    world = make_world()
    robot = world.load_robot(seed_urdf, seed_model, (x, y, 0.0), yaw)
    (px, py, pz), orientation = robot.base_pose()
    assert px == pytest.approx(x, abs=1e-3)
    assert py == pytest.approx(y, abs=1e-3)
    assert pz == pytest.approx(0.0, abs=1e-3)
    assert abs(angle_diff(yaw_from_quaternion(*orientation), yaw)) < 1e-3


def test_base_pose_in_link_frame_with_offset_inertial(make_world):
    text = """<robot name="block"><link name="base">
      <inertial><origin xyz="0.05 0.02 0.1" rpy="0 0 0.3"/><mass value="2"/>
        <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
      <collision><origin xyz="0 0 0.05"/><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
    </link></robot>"""
    world = make_world()
    robot = world.load_robot(text, parse_urdf(text, "block"), (1.0, 2.0, 0.0), 1.0)
    x, y, yaw = pose2d(robot)
    assert (x, y) == pytest.approx((1.0, 2.0), abs=1e-3)
    assert yaw == pytest.approx(1.0, abs=1e-3)
    assert robot.total_mass() == pytest.approx(2.0)
    run(world, 0.25)  # resting on its box, it stays put
    assert pose2d(robot) == pytest.approx((1.0, 2.0, 1.0), abs=2e-3)


# ----------------------------------------------------------------------------------------------- driving

def test_positive_wheel_velocity_drives_forward(seed):
    world, robot = seed
    v = 0.2
    robot.set_velocities(robot.indices(WHEELS), [v / R, v / R], [TORQUE, TORQUE])
    run(world, 0.5)
    x, y, yaw = pose2d(robot)
    assert x == pytest.approx(v * 0.5, rel=0.15)  # ~0.1 m forward (+x, REP 103)
    assert abs(y) < 0.005 and abs(yaw) < 0.02
    (vx, vy, _), _ = robot.base_twist()
    assert vx == pytest.approx(v, rel=0.1) and abs(vy) < 0.01
    _, velocities, _ = robot.joint_states(robot.indices(WHEELS))
    assert velocities == pytest.approx([v / R, v / R], rel=0.05)


def test_forward_follows_spawn_heading(make_world, seed_urdf, seed_model):
    world = make_world()
    robot = world.load_robot(seed_urdf, seed_model, (1.0, 1.0, 0.0), math.pi / 2)
    robot.set_velocities(robot.indices(WHEELS), [5.0, 5.0], [TORQUE, TORQUE])
    run(world, 0.5)
    x, y, _ = pose2d(robot)
    assert abs(x - 1.0) < 0.005
    assert y - 1.0 == pytest.approx(5.0 * R * 0.5, rel=0.15)  # along +y, the spawn heading


def test_positive_differential_turns_left(seed):
    world, robot = seed
    w = 1.0  # body rad/s
    rim = w * S / 2
    robot.set_velocities(robot.indices(WHEELS), [-rim / R, rim / R], [TORQUE, TORQUE])
    run(world, 0.5)
    x, y, yaw = pose2d(robot)
    assert yaw == pytest.approx(w * 0.5, rel=0.15)  # +yaw: counter-clockwise, REP 103
    assert math.hypot(x, y) < 0.01
    assert robot.base_twist()[1][2] == pytest.approx(w, rel=0.15)


def test_passive_caster_is_free(seed):
    world, robot = seed
    casters = robot.indices(CASTERS)
    robot.set_velocities(robot.indices(WHEELS), [5.0, 5.0], [TORQUE, TORQUE])
    for index in casters:
        pybullet.resetJointState(robot.body, index, 0.0, 8.0, physicsClientId=world.client)
    run(world, 0.05)
    _, velocities, efforts = robot.joint_states(casters)
    assert efforts == [0.0, 0.0]  # the free_joints motor has force 0
    assert all(abs(v) > 4.0 for v in velocities)  # a braking motor would have stopped the spin


def test_caster_with_motor_force_brakes(seed):
    # the counter-check: what test_passive_caster_is_free would see if the casters were not freed
    world, robot = seed
    casters = robot.indices(CASTERS)
    robot.set_velocities(casters, [0.0, 0.0], [1.0, 1.0])
    for index in casters:
        pybullet.resetJointState(robot.body, index, 0.0, 8.0, physicsClientId=world.client)
    run(world, 0.05)
    _, velocities, _ = robot.joint_states(casters)
    assert all(abs(v) < 0.5 for v in velocities)


def test_reset_returns_to_spawn(make_world, seed_urdf, seed_model):
    world = make_world()
    robot = world.load_robot(seed_urdf, seed_model, (0.3, -0.4, 0.0), 0.6)
    robot.set_velocities(robot.indices(WHEELS), [4.0, 8.0], [TORQUE, TORQUE])
    run(world, 0.5)
    moved = pose2d(robot)
    assert math.hypot(moved[0] - 0.3, moved[1] + 0.4) > 0.05
    world.reset()
    assert pose2d(robot) == pytest.approx((0.3, -0.4, 0.6), abs=1e-3)
    positions, velocities, _ = robot.joint_states(robot.indices(WHEELS + CASTERS))
    assert positions == [0.0] * 4 and velocities == [0.0] * 4
    linear, angular = robot.base_twist()
    assert max(map(abs, linear + angular)) < 1e-9


def test_two_worlds_are_independent(make_world, seed_urdf, seed_model):
    first, second = make_world(), make_world()
    assert first.client != second.client
    a = first.load_robot(seed_urdf, seed_model)
    b = second.load_robot(seed_urdf, seed_model, (1.0, 0.0, 0.0))
    a.set_velocities(a.indices(WHEELS), [6.0, 6.0], [TORQUE, TORQUE])
    for _ in range(120):
        first.step()
        second.step()
    assert pose2d(a)[0] > 0.05
    assert pose2d(b) == pytest.approx((1.0, 0.0, 0.0), abs=2e-3)
    first.close()
    assert first.client is None
    run(second, 0.05)  # the other world still works
    assert pose2d(b)[0] == pytest.approx(1.0, abs=2e-3)


@pytest.mark.slow
def test_controller_and_encoder_odometry_track_physics(seed):
    """Closed loop as the node runs it: controller -> motors -> wheel angles -> odometry vs physics pose."""
    world, robot = seed
    wheels = robot.indices(WHEELS)
    ctrl = GazeboDiffDriveCore(S, R, 40.0, max_wheel_acceleration=1.8)
    odom = EncoderOdometry(R, S)
    ctrl.set_command(0.2, 0.8, 0.0)
    t = 0.0
    for step in range(int(2.0 / DT)):
        positions, velocities, _ = robot.joint_states(wheels)
        if step % 2 == 0:  # 120 Hz control
            robot.set_velocities(wheels, list(ctrl.update(t, velocities[0], velocities[1], 2 * DT)), [TORQUE] * 2)
        odom.update(positions[0], positions[1], t)
        world.step()
        t += DT
    x, y, yaw = pose2d(robot)
    assert yaw == pytest.approx(0.8 * 2.0, rel=0.1)
    assert odom.x == pytest.approx(x, abs=0.02)
    assert odom.y == pytest.approx(y, abs=0.02)
    assert abs(angle_diff(odom.yaw, yaw)) < 0.05


# --------------------------------------------------------------------------------- setting a robot down
# tests/data/robots/inertial_link_4wd.urdf: an inertia-less base_link whose geometry rests at z 0.13228 (the
# wheels, radius 0.1651, hang 0.03282 above base_link), stiff undamped wheel contacts (kp 1e7, kd 1).

FOUR_WD = os.path.join(os.path.dirname(__file__), "..", "..", "data", "robots", "inertial_link_4wd.urdf")
REST_Z = 0.13228


def heights(world, robot, seconds):
    out = []
    for _ in range(int(round(seconds / world.time_step))):
        world.step()
        out.append(robot.base_pose()[0][2])
    return out


@pytest.fixture
def four_wd():
    with open(FOUR_WD) as handle:
        text = handle.read()
    return text, parse_urdf(text, FOUR_WD)


def test_a_robot_spawned_into_the_ground_is_set_on_it_and_stays(make_world, four_wd):
    # Spawned at z 0, as its Gazebo launch file does: the wheels 0.132 m deep. Bullet alone threw such a robot
    # 18 m up (each contact pushed it out in one step); Gazebo pushes it out at <max_vel> and ends resting.
    world = make_world()
    robot = world.load_robot(*four_wd, position=(0.0, 0.0, 0.0))
    assert robot.base_pose()[0][2] == pytest.approx(REST_Z, abs=1e-4)
    zs = heights(world, robot, 2.0)
    assert max(zs) < REST_Z + 0.002 and min(zs) > REST_Z - 0.002


@pytest.mark.parametrize("z", [1.0, 1.5])
def test_a_robot_spawned_in_the_air_lands_and_settles_within_a_second(make_world, four_wd, z):
    world = make_world()
    robot = world.load_robot(*four_wd, position=(0.0, 0.0, z))
    zs = heights(world, robot, 2.0)
    after = zs[round(1.0 / world.time_step):]  # from 1 s of sim time on
    assert max(after) - min(after) < 0.002 and abs(after[-1] - REST_Z) < 0.002
    landed = next(i for i, h in enumerate(zs) if h < REST_Z + 0.01)
    assert max(zs[landed:]) < REST_Z + 0.02  # no rebound (kp 1e7, kd 1 as given: 0.26 m from 1 m)
    assert robot not in world.landing  # its own contacts back once at rest


def test_a_robot_teleported_into_the_ground_or_reset_is_set_down_again(make_world, four_wd):
    world = make_world()
    robot = world.load_robot(*four_wd)
    run(world, 0.5)
    robot.set_base_motion(((1.0, 0.0, -0.05), (0, 0, 0, 1)), (0, 0, 0), (0, 0, 0))
    assert world.lift_out(robot) == pytest.approx(REST_Z + 0.05, abs=1e-4)
    assert max(heights(world, robot, 1.0)) < REST_Z + 0.002
    world.reset()
    assert robot.base_pose()[0] == pytest.approx((0.0, 0.0, REST_Z), abs=1e-4)


def test_lifting_only_counts_what_the_robot_stands_in(make_world, seed_urdf, seed_model):
    # Above the ground nothing is touched: the spawn height is kept, and the robot falls as in Gazebo.
    world = make_world()
    robot = world.load_robot(seed_urdf, seed_model, position=(0.0, 0.0, 0.3))
    assert robot.base_pose()[0][2] == pytest.approx(0.3, abs=1e-6)
    run(world, 0.1)
    assert robot.base_pose()[0][2] < 0.3 - 0.5 * 9.81 * 0.09 ** 2
