"""Explicit PID loops on PyBullet at our step, and the measure that decides when gazebo_ros_control's PID recipe
runs as an implicit motor instead (:func:`diffbot_sim.control.pid.explicit_loop_margin`): the loops it calls
well damped settle, the ones it refuses diverge or ring, and the implicit motor holds a target under gravity."""
import math

import pytest

from diffbot_sim.control.pid import STABILITY_MARGIN, Pid, PidGains, explicit_loop_margin, loop_verdict
from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.physics import World

DT = 1.0 / 240.0
WHEEL = """<robot name="wheel_on_a_post">
  <link name="base"><inertial><mass value="100"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    </link>
  <link name="wheel"><inertial><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="axle" type="continuous"><parent link="base"/><child link="wheel"/><origin xyz="0 0 1"/>
    <axis xyz="0 1 0"/></joint>
</robot>"""
#: an OpenMANIPULATOR-sized link (0.1 kg, 0.1 m): Gazebo-tuned p = 300 is far beyond its bound at 1/240 s
ARM = """<robot name="one_link_arm">
  <link name="base"><inertial><mass value="100"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    </link>
  <link name="link"><inertial><origin xyz="0.05 0 0"/><mass value="0.1"/>
    <inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="link"/><origin xyz="0 0 1"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="5" velocity="5"/></joint>
</robot>"""


def run(urdf, joint, control, seconds=2.0, gravity=0.0):
    """Step ``urdf`` (base fixed by its mass, lifted 1 m) calling ``control(robot, idx, position, velocity)``
    before each step; returns the joint's (position, velocity) history and the inertia it moves."""
    world = World(DT, gravity=gravity)
    try:
        robot = world.load_robot(urdf, parse_urdf(urdf))
        idx = robot.indices([joint])
        robot.free_joints(idx)
        history = []
        for _ in range(int(seconds / DT)):
            (position,), (velocity,), _ = robot.joint_states(idx)
            history.append((position, velocity))
            control(robot, idx, position, velocity)
            world.step()
        return history, robot.joint_inertias(idx)[0]
    finally:
        world.close()


def velocity_pid(p, target=3.0, limit=10.0):
    pid = Pid(PidGains(p))
    return lambda robot, idx, _pos, vel: robot.set_efforts(idx, [max(-limit, min(limit, pid.compute(target - vel,
                                                                                                      DT)))])


def test_stable_velocity_gain_reaches_the_target():
    history, inertia = run(WHEEL, "axle", velocity_pid(0.5))
    assert explicit_loop_margin(PidGains(0.5), DT, inertia, "velocity") < STABILITY_MARGIN
    assert history[-1][1] == pytest.approx(3.0, abs=0.05)
    assert max(v for _, v in history) < 3.3  # no ringing


def test_gazebo_tuned_velocity_gain_is_unstable_at_our_step():
    history, inertia = run(WHEEL, "axle", velocity_pid(50.0))
    assert explicit_loop_margin(PidGains(50.0), DT, inertia, "velocity") > 1.0
    tail = [v for _, v in history[-100:]]
    assert max(tail) - min(tail) > 1.0


def test_joint_inertias_are_what_the_motor_moves():
    """On an arm fixed to the world: the link's Iyy plus m r^2 about the shoulder (the mass matrix's diagonal).
    On a free base: less, by what the base turns back (the Schur complement): a wheel turning about an axle
    through both centres of mass moves Iw Ib / (Iw + Ib), not Iw."""
    fixed_arm = ARM.replace('<robot name="one_link_arm">', '<robot name="one_link_arm"><link name="world"/>'
                            '<joint name="bolt" type="fixed"><parent link="world"/><child link="base"/></joint>')
    _, arm = run(fixed_arm, "shoulder", lambda *a: None, seconds=DT)
    assert arm == pytest.approx(1e-4 + 0.1 * 0.05 ** 2, rel=1e-6)
    free_wheel = WHEEL.replace('<origin xyz="0 0 1"/>', '<origin xyz="0 0 0"/>')
    _, wheel = run(free_wheel, "axle", lambda *a: None, seconds=DT)
    assert wheel == pytest.approx(0.01 * 1.0 / (0.01 + 1.0), rel=1e-6)
    light_base = free_wheel.replace(
        '<mass value="100"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"',
        '<mass value="4"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"')
    _, wheel = run(light_base, "axle", lambda *a: None, seconds=DT)
    assert wheel == pytest.approx(0.005, rel=1e-6)  # half the diagonal: the base spins back as much


def position_pid(gains, target, limit=5.0):
    pid = Pid(gains)
    return lambda robot, idx, pos, _vel: robot.set_efforts(idx, [max(-limit, min(limit, pid.compute(target - pos,
                                                                                                      DT)))])


def test_position_loop_margin_separates_settling_from_diverging_gains():
    """Under gravity: p = 2, d = 0.05 settles at the target; TurtleBot3's p = 300, d = 1 does not."""
    good, bad = PidGains(2.0, d=0.05), PidGains(300.0, d=1.0)
    history, inertia = run(ARM, "shoulder", position_pid(good, 0.5), gravity=-9.81)
    assert explicit_loop_margin(good, DT, inertia, "position") < STABILITY_MARGIN
    assert history[-1][0] == pytest.approx(0.5, abs=0.05)
    history, inertia = run(ARM, "shoulder", position_pid(bad, 0.5), gravity=-9.81)
    assert explicit_loop_margin(bad, DT, inertia, "position") > 1.0
    tail = [p for p, _ in history[-100:]]
    assert max(tail) - min(tail) > 0.1 or not all(math.isfinite(p) for p in tail)


def test_implicit_position_motor_holds_the_target_under_gravity():
    """What an unstable PID joint runs as: PyBullet's position motor, capped at the URDF effort (5 N·m)."""
    def motor(robot, idx, _pos, _vel):
        robot.set_positions(idx, [0.5], [5.0])
    history, _ = run(ARM, "shoulder", motor, gravity=-9.81)
    assert history[-1][0] == pytest.approx(0.5, abs=0.01)
    assert abs(history[-1][1]) < 0.01


def test_a_loop_without_damping_is_never_rated_stable():
    """P-only (no d term, as published effort trajectory gains may be): however small p is against the joint's
    inertia, the explicit loop keeps ringing (nothing damps it but friction), so it is never rated well damped
    (the a + 2b < 4 bound alone would call p = 2 on this link 0.025 of its bound)."""
    undamped = PidGains(2.0)
    history, inertia = run(ARM, "shoulder", position_pid(undamped, 0.5), seconds=6.0)
    assert (undamped.p * DT * DT / inertia) / 4.0 < 0.05  # the bound alone: "well damped"
    assert explicit_loop_margin(undamped, DT, inertia, "position") >= 1.0
    tail = [p for p, _ in history[-240:]]
    assert max(tail) - min(tail) > 0.3  # still swinging about 0.5 rad, +-0.24 rad after 5 s
    assert loop_verdict(undamped, explicit_loop_margin(undamped, DT, inertia, "position"), "position") == \
        "an undamped"
