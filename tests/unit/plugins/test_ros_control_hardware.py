"""gazebo_ros_control's DefaultRobotHWSim (plugins/ros_control/hardware.RobotHWSim) without a ROS master: the
fixture arms in PyBullet, their YAML as the parameter server, and every verdict read from the physics (the joint
the body has), not from the hardware's own buffers."""
import math

import pytest
from conftest import DT, parameter_server

from diffbot_sim.plugins.ros_control import hardware


@pytest.fixture
def arm(arm_rig, monkeypatch):
    """``arm(name, params=None)`` -> (rig, hardware, warnings): the hardware built on the arm and started."""
    def make(name, params=None):
        rig = arm_rig(name, params)
        monkeypatch.setattr(hardware, "get_param", parameter_server(rig.params))
        warnings = []
        hw = hardware.RobotHWSim(rig.ctx, "/", warnings)
        hw.start()
        return rig, hw, warnings
    return make


def run(rig, hw, seconds):
    """writeSim, a physics step and readSim, for ``seconds`` of sim time."""
    for _ in range(max(1, round(seconds / DT))):
        hw.write(DT)
        rig.world.step()
        hw.read()


@pytest.mark.parametrize("name, method", [("arm_position_pid", hardware.POSITION_PID),
                                          ("arm_position_nogains", hardware.POSITION),
                                          ("arm_velocity_jtc", hardware.VELOCITY),
                                          ("arm_effort_jtc", hardware.EFFORT)])
def test_each_joint_is_driven_by_its_interface_and_gains(arm, name, method):
    _, hw, warnings = arm(name)
    assert hw.names() == ["joint_1", "joint_2", "joint_3"] and warnings == []
    assert {j.method for j in hw.joints.values()} == {method}
    assert [(j.effort_limit, j.velocity_limit) for j in hw.joints.values()] == [(10, 1.5), (10, 1.5), (5, 2.0)]


def test_a_position_joint_follows_at_the_urdf_velocity_and_holds_against_gravity(arm):
    rig, hw, _ = arm("arm_position_nogains")
    hw.set_command("joint_1", 0.3)
    hw.set_command("joint_2", 0.5)  # the arm leans out: gravity pulls on it
    run(rig, hw, 0.1)
    assert rig.joint("joint_1")[0] == pytest.approx(1.5 * 0.1, abs=1e-5)  # rate-limited by <limit velocity>
    run(rig, hw, 1.0)
    assert rig.joint("joint_1")[0] == pytest.approx(0.3, abs=1e-6)
    assert rig.joint("joint_2")[0] == pytest.approx(0.5, abs=1e-6)
    assert hw.busy is False  # motors hold unclipped targets: no write needed until a command changes
    hw.set_command("joint_1", 0.2)
    assert hw.busy is True


def test_a_position_command_beyond_the_joint_limit_stops_at_the_limit(arm):
    rig, hw, _ = arm("arm_position_nogains")
    hw.set_command("joint_1", 3.0)
    run(rig, hw, 2.5)
    assert rig.joint("joint_1")[0] == pytest.approx(2.5, abs=1e-6)  # <limit upper="2.5">
    assert hw.busy is True  # the limit still clips the command: written every step


def test_joint_limits_parameters_narrow_the_urdfs(arm):
    rig, hw, _ = arm("arm_position_nogains",
                     {"joint_limits": {"joint_1": {"has_velocity_limits": True, "max_velocity": 0.5}}})
    hw.set_command("joint_1", 0.3)
    run(rig, hw, 0.2)
    assert rig.joint("joint_1")[0] == pytest.approx(0.5 * 0.2, abs=1e-5)  # not the URDF's 1.5 rad/s


def test_a_velocity_joint_turns_at_its_command_clamped_to_its_limit(arm):
    rig, hw, _ = arm("arm_velocity_jtc")
    hw.set_command("joint_1", 0.5)
    hw.set_command("joint_3", 5.0)  # above <limit velocity="2.0">
    run(rig, hw, 0.2)
    assert rig.joint("joint_1")[1] == pytest.approx(0.5, abs=1e-3)
    assert rig.joint("joint_3")[1] == pytest.approx(2.0, abs=1e-3)


def test_an_effort_is_clamped_to_the_effort_limit_and_stops_pushing_past_the_velocity_limit(arm):
    first = {}
    for command in (100.0, 10.0, 5.0):
        rig, hw, _ = arm("arm_effort_jtc")
        hw.set_command("joint_1", command)  # the turntable: no gravity about its axis
        run(rig, hw, DT)
        first[command] = rig.joint("joint_1")[1]
        assert hw.joints["joint_1"].effort == min(command, 10.0)
        run(rig, hw, 0.1)
        # One step took it past 1.5 rad/s: Gazebo's CheckAndTruncateForce gives no more push from then on (the
        # limp arm folding on the turntable only slows it); 0.1 s more of 10 N·m would add ~300 rad/s.
        assert rig.joint("joint_1")[1] <= first[command] + 1e-6
    assert first[100.0] == pytest.approx(first[10.0], rel=1e-9) and first[10.0] > 1.5
    assert first[5.0] == pytest.approx(first[10.0] / 2, rel=1e-3)


def test_an_uncommanded_effort_joint_is_limp(arm):
    rig, hw, _ = arm("arm_effort_jtc")
    rig.robot.set_joint_positions([rig.robot.joint_index["joint_2"]], [0.3])  # leaning out
    run(rig, hw, 0.5)
    assert rig.joint("joint_2")[0] > 0.5  # gravity folds the arm: nothing holds it
    assert [j.effort for j in hw.joints.values()] == [0.0, 0.0, 0.0]


def test_a_stable_pid_brings_the_joint_to_its_target_under_gravity(arm):
    rig, hw, warnings = arm("arm_position_pid")
    hw.set_command("joint_2", 0.5)
    run(rig, hw, 3.0)
    assert rig.joint("joint_2")[0] == pytest.approx(0.5, abs=0.01) and warnings == []
    assert abs(hw.joints["joint_2"].effort) > 0.1  # the PID's torque, reported as Gazebo's GetForce


def test_a_pid_unstable_at_our_step_runs_as_a_motor_with_one_warning(arm):
    gains = {"joint_1": {"p": 20.0, "d": 0.4}, "joint_2": {"p": 1e5, "d": 0.0}, "joint_3": {"p": 20.0, "d": 0.15}}
    rig, hw, warnings = arm("arm_position_pid", {"gazebo_ros_control": {"pid_gains": gains}})
    assert len(warnings) == 1 and warnings[0].startswith("/gazebo_ros_control/pid_gains/joint_2: p=100000 d=0")
    assert "runs as PyBullet's position motor" in warnings[0]
    assert [j.implicit for j in hw.joints.values()] == [False, True, False]
    hw.set_command("joint_2", 0.5)
    run(rig, hw, 2.0)
    assert rig.joint("joint_2")[0] == pytest.approx(0.5, abs=1e-3)  # an explicit p of 1e5 would blow up


def test_the_estop_freezes_positions_and_its_release_lets_them_go(arm):
    rig, hw, _ = arm("arm_position_nogains")
    hw.set_command("joint_1", 0.3)
    run(rig, hw, 0.5)
    hw.set_estop(True)
    hw.set_command("joint_1", -0.3)
    run(rig, hw, 0.5)
    assert rig.joint("joint_1")[0] == pytest.approx(0.3, abs=1e-6)
    hw.set_estop(False)
    run(rig, hw, 0.5)
    assert rig.joint("joint_1")[0] == pytest.approx(-0.3, abs=1e-6)


def test_the_estop_zeroes_efforts(arm):
    rig, hw, _ = arm("arm_effort_jtc")
    hw.set_estop(True)
    hw.set_command("joint_1", 5.0)
    run(rig, hw, 0.1)
    assert abs(rig.joint("joint_1")[1]) < 1e-3 and hw.joints["joint_1"].effort == 0.0


def test_start_zeroes_the_commands_and_reads_the_joints(arm):
    rig, hw, _ = arm("arm_position_nogains")
    hw.set_command("joint_1", 0.3)
    run(rig, hw, 0.5)
    hw.start()
    assert [j.command for j in hw.joints.values()] == [0.0, 0.0, 0.0]
    assert hw.positions(["joint_1"]) == [pytest.approx(0.3, abs=1e-6)]  # read from the body
    run(rig, hw, 0.5)
    assert rig.joint("joint_1")[0] == pytest.approx(0.0, abs=1e-6)  # command 0: back to 0, as initSim leaves it


def test_truncate_is_gazebos_check_and_truncate_force():
    joint = hardware.SimJoint("j", 0, "EffortJointInterface", hardware.EFFORT, "revolute", -1.0, 1.0,
                              effort_limit=2.0, velocity_limit=1.0)
    assert hardware._truncate(5.0, 0.5, joint) == 2.0
    assert hardware._truncate(-5.0, 0.5, joint) == -2.0
    assert hardware._truncate(1.0, 1.5, joint) == 0.0  # too fast: no push further
    assert hardware._truncate(-1.0, 1.5, joint) == -1.0  # braking is allowed
    joint.effort_limit = math.inf
    assert hardware._truncate(50.0, 0.0, joint) == 50.0
