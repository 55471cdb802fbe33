"""A robot bolted to the world (a URDF link named ``world``, as arm descriptions write it): PyBullet holds its
first real link where the spawn put it (the model pose composed with the bolt's origin), gravity, a push and a
swinging arm never move it, nothing is lumped into ``world`` and nothing lifts it out of the ground, and a
reset puts it back. A free robot is unchanged."""
import math

import pytest

from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.physics import World

DT = 0.001
#: a 4 kg base and a 2-link arm whose 3 kg forearm sticks out sideways: a free base tips over
ARM = """<robot name="tipping_arm">
  <link name="world"/>
  <joint name="world_joint" type="fixed"><parent link="world"/><child link="link_base"/>
    <origin xyz="0.1 0 0.05" rpy="0 0 0.3"/></joint>
  <link name="link_base"><inertial><mass value="4"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>
    </inertial><collision><origin xyz="0 0 0.05"/><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="flange"><inertial><mass value="0.1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/>
    </inertial></link>
  <joint name="flange_joint" type="fixed"><parent link="link_base"/><child link="flange"/>
    <origin xyz="0 0 0.1"/></joint>
  <link name="upper_arm"><inertial><origin xyz="0.25 0 0"/><mass value="3"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.06" iyz="0" izz="0.06"/></inertial>
    <collision><origin xyz="0.25 0 0"/><geometry><box size="0.5 0.05 0.05"/></geometry></collision></link>
  <joint name="shoulder" type="revolute"><parent link="flange"/><child link="upper_arm"/><origin xyz="0 0 0.05"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="50" velocity="2"/></joint>
</robot>"""


def load(urdf, position=(0.0, 0.0, 0.0), yaw=0.0):
    world = World(DT)
    return world, world.load_robot(urdf, parse_urdf(urdf), position, yaw)


def test_the_first_link_is_the_root_and_is_held_where_the_spawn_and_the_bolt_put_it():
    world, robot = load(ARM, (1.0, 2.0, 0.5), yaw=0.2)
    try:
        model = robot.model
        assert model.root == "link_base" and model.anchor.name == "world_joint"
        assert model.gazebo_links() == ["link_base", "upper_arm"]  # flange lumped into link_base, not into world
        (x, y, z), q = robot.link_pose("link_base")
        # model pose (1, 2, 0.5) turned 0.2, then the bolt: 0.1 m along the turned x, 0.05 up, turned 0.3 more
        assert (x, y, z) == pytest.approx((1.0 + 0.1 * math.cos(0.2), 2.0 + 0.1 * math.sin(0.2), 0.55), abs=1e-6)
        assert 2 * math.atan2(q[2], q[3]) == pytest.approx(0.5, abs=1e-6)
        start = robot.link_pose("flange")
        for step in range(2000):  # the arm swings hard and the base is pushed: it must not move
            robot.set_efforts(robot.indices(["shoulder"]), [50.0 if step < 1000 else -50.0])
            world.apply_wrench(robot.body, -1, (200.0, 0.0, 0.0), (0.0, 0.0, 0.0))
            world.step()
        assert robot.link_pose("flange")[0] == pytest.approx(start[0], abs=1e-6)
        assert robot.link_pose("flange")[1] == pytest.approx(start[1], abs=1e-6)
        assert abs(robot.joint_states(robot.indices(["shoulder"]))[0][0]) > 0.5  # the arm did move
    finally:
        world.close()


def test_a_bolted_robot_spawned_into_the_ground_is_not_lifted_out_and_a_reset_puts_it_back():
    world, robot = load(ARM, (0.0, 0.0, -0.2))
    try:
        assert robot not in world.landing
        assert robot.link_pose("link_base")[0][2] == pytest.approx(-0.15, abs=1e-6)
        robot.set_efforts(robot.indices(["shoulder"]), [20.0])
        for _ in range(500):
            world.step()
        world.reset()
        assert robot.link_pose("link_base")[0] == pytest.approx((0.1, 0.0, -0.15), abs=1e-6)
        assert robot.joint_states(robot.indices(["shoulder"]))[0][0] == pytest.approx(0.0, abs=1e-12)
    finally:
        world.close()


def test_without_the_bolt_the_same_robot_is_free_and_tips():
    """The control case: the same model with its world link removed is set down and falls over (its 3 kg
    arm out sideways over a 4 kg base on a 0.1 m foot)."""
    free = ARM.replace('<link name="world"/>', "").replace(
        ARM[ARM.index('  <joint name="world_joint"'):ARM.index('  <link name="link_base">')], "")
    world, robot = load(free, (0.0, 0.0, 0.0))
    try:
        assert not robot.model.fixed_to_world and robot.model.root == "link_base"
        for _ in range(3000):
            world.step()
        roll, pitch, _ = __import__("pybullet").getEulerFromQuaternion(robot.link_pose("link_base")[1])
        assert max(abs(roll), abs(pitch)) > 0.15  # measured: 0.27 rad, the arm on the ground
    finally:
        world.close()
