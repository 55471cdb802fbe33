"""gazebo_ros_control's VELOCITY_PID on PyBullet: the explicit PID drives a wheel where its discrete loop is
stable, and the gains published robots carry (tuned for Gazebo's 1 ms step) are not, at ours."""
import pytest

from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.physics import World
from diffbot_sim.plugins.ros_control import STABLE_LOOP_GAIN, Pid, loop_gain

DT = 1.0 / 240.0
WHEEL = """<robot name="wheel_on_a_post">
  <link name="base"><inertial><mass value="100"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="wheel"><inertial><mass value="2"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="axle" type="continuous"><parent link="base"/><child link="wheel"/><origin xyz="0 0 1"/><axis xyz="0 1 0"/></joint>
</robot>"""


def spin(p, seconds=2.0, target=3.0, limit=10.0):
    """Drive the free wheel (lifted 1 m, no contact) with an explicit PID; returns its velocity history."""
    world = World(DT, gravity=0.0)
    try:
        robot = world.load_robot(WHEEL, parse_urdf(WHEEL))
        idx = robot.indices(["axle"])
        robot.free_joints(idx)
        pid, history = Pid(p), []
        for _ in range(int(seconds / DT)):
            _, (velocity,), _ = robot.joint_states(idx)
            history.append(velocity)
            robot.set_efforts(idx, [max(-limit, min(limit, pid.update(target - velocity, DT)))])
            world.step()
        return history, robot.smallest_inertia(idx[0])
    finally:
        world.close()


def test_stable_gain_reaches_the_target():
    history, inertia = spin(p=0.5)
    assert loop_gain(0.5, DT, inertia) < STABLE_LOOP_GAIN
    assert history[-1] == pytest.approx(3.0, abs=0.05)
    assert max(history) < 3.3  # no ringing


def test_gazebo_tuned_gain_is_unstable_at_our_step():
    """What _check_pid_stability guards against: p = 50 on this wheel oscillates instead of settling."""
    history, inertia = spin(p=50.0)
    assert loop_gain(50.0, DT, inertia) > STABLE_LOOP_GAIN
    tail = history[-100:]
    assert max(tail) - min(tail) > 1.0
