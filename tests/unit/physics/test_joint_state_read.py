"""Robot.joint_states reads every joint once per step and answers later calls from that read: what it answers must
always be what PyBullet reports now, after a step, a joint reset, a reset of the robot or a snapshot restored,
and motor commands given between steps must not make it stale."""
import pybullet
import pytest

from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.physics import World

PENDULUM = """<robot name="pendulums">
  <link name="base"><inertial><mass value="100"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    </link>
  <link name="a"><inertial><origin xyz="0 0 -0.2"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <link name="b"><inertial><origin xyz="0 0 -0.2"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="ja" type="continuous"><parent link="base"/><child link="a"/><origin xyz="0 0 1"/>
    <axis xyz="0 1 0"/></joint>
  <joint name="jb" type="continuous"><parent link="a"/><child link="b"/><origin xyz="0 0 -0.4"/>
    <axis xyz="0 1 0"/></joint>
</robot>"""


@pytest.fixture
def rig():
    world = World(1.0 / 240.0)
    robot = world.load_robot(PENDULUM, parse_urdf(PENDULUM))
    yield world, robot
    world.close()


def truth(robot, indices):
    states = pybullet.getJointStates(robot.body, indices, physicsClientId=robot.client)
    return [s[0] for s in states], [s[1] for s in states], [s[3] for s in states]


def test_answers_what_pybullet_reports_after_steps_resets_and_restores(rig):
    world, robot = rig
    idx = robot.indices(["ja", "jb"])
    robot.set_joint_positions(idx, [0.5, -0.3])
    assert robot.joint_states(idx) == truth(robot, idx)
    robot.set_efforts(idx, [0.2, -0.1])  # a command between steps: PyBullet reports the same until the step
    assert robot.joint_states(idx) == truth(robot, idx)
    snapshot = world.save_state()
    for _ in range(10):
        before = robot.joint_states(idx)
        robot.set_efforts(idx, [0.2, -0.1])
        world.step()
        assert robot.joint_states(idx) == truth(robot, idx) != before  # the torque bends them
    robot.set_joint_positions(idx[:1], [1.0])
    assert robot.joint_states(idx) == truth(robot, idx) and robot.joint_states(idx)[0][0] == 1.0
    robot.set_joint_velocities(idx[1:], [2.0])
    assert robot.joint_states(idx)[1][1] == pytest.approx(2.0)
    world.restore_state(snapshot)
    assert robot.joint_states(idx) == truth(robot, idx)
    assert robot.joint_states(idx)[0] == pytest.approx([0.5, -0.3])
    robot.reset()
    assert robot.joint_states(idx)[0] == [0.0, 0.0] == truth(robot, idx)[0]
    assert robot.joint_positions([idx[1], idx[0]]) == [0.0, 0.0]
    robot.set_efforts(idx, [1.0, -1.0])  # the robot falls freely: only a torque bends it
    world.step(5)  # a batch of steps
    assert robot.joint_positions(idx) == truth(robot, idx)[0] != [0.0, 0.0]
