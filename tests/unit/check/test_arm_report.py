"""check.arm_report: each transmission joint's interface, method, limits, controller and role as robot_check
reports them; the small moves planned for the arm joints; a move judged by the joints and the body."""
import math

import pytest

from diffbot_sim.check import arm_report
from diffbot_sim.check.arm_check import PoseError
from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.errors import ConfigError


def trans(joint, interface):
    return (f"<transmission name='{joint}_t'><type>transmission_interface/SimpleTransmission</type>"
            f"<joint name='{joint}'><hardwareInterface>hardware_interface/{interface}</hardwareInterface></joint>"
            f"<actuator name='{joint}_m'/></transmission>")


def link(name):
    return (f"<link name='{name}'><inertial><mass value='0.1'/>"
            "<inertia ixx='1e-4' ixy='0' ixz='0' iyy='1e-4' iyz='0' izz='1e-4'/></inertial></link>")


ROBOT = f"""<robot name='r'>{link('base')}{link('wheel')}{link('upper')}{link('finger')}{link('finger2')}
  <joint name='wheel_joint' type='continuous'><parent link='base'/><child link='wheel'/><axis xyz='0 1 0'/>
    <limit effort='3' velocity='20'/></joint>
  <joint name='shoulder' type='revolute'><parent link='base'/><child link='upper'/><axis xyz='0 1 0'/>
    <limit lower='-1.5' upper='1.5' effort='6' velocity='1.5'/></joint>
  <joint name='finger_joint' type='prismatic'><parent link='upper'/><child link='finger'/><axis xyz='0 1 0'/>
    <limit lower='0' upper='0.03' effort='10' velocity='0.1'/></joint>
  <joint name='finger2_joint' type='prismatic'><parent link='upper'/><child link='finger2'/><axis xyz='0 -1 0'/>
    <limit lower='0' upper='0.03' effort='10' velocity='0.1'/><mimic joint='finger_joint'/></joint>
  {trans('wheel_joint', 'VelocityJointInterface')}{trans('shoulder', 'PositionJointInterface')}
  {trans('finger_joint', 'EffortJointInterface')}{trans('finger2_joint', 'EffortJointInterface')}
</robot>"""
TREE = {"arm_controller": {"type": "position_controllers/JointTrajectoryController", "joints": ["shoulder"]},
        "gripper": {"type": "effort_controllers/GripperActionController", "joint": "finger_joint", "max_effort": 4},
        "joint_limits": {"shoulder": {"has_velocity_limits": True, "max_velocity": 0.8}},
        "gazebo_ros_control": {"pid_gains": {"shoulder": {"p": 20.0, "d": 0.2}}}}
CONTROLLERS = {"/arm_controller": TREE["arm_controller"], "/gripper": TREE["gripper"]}


def infos(tree=TREE, controllers=CONTROLLERS):
    return {j.name: j for j in arm_report.joint_infos(parse_urdf(ROBOT), tree, "/", controllers, {"wheel_joint"})}


def test_each_transmission_joint_with_its_method_limits_controller_and_role():
    joints = infos()
    shoulder = joints["shoulder"]
    assert (shoulder.type, shoulder.interface, shoulder.method) == ("revolute", "PositionJointInterface",
                                                                   "position, pid_gains p 20")
    assert (shoulder.lower, shoulder.upper, shoulder.effort) == (-1.5, 1.5, 6.0)
    assert shoulder.velocity == 0.8  # joint_limits/shoulder overrides the URDF's 1.5
    assert (shoulder.controller, shoulder.controller_type) == ("arm_controller",
                                                              "position_controllers/JointTrajectoryController")
    assert shoulder.arm
    assert joints["wheel_joint"].role == "drive wheel" and not joints["wheel_joint"].arm
    assert joints["wheel_joint"].method == "velocity, no pid_gains"
    assert joints["finger2_joint"].role == "mimic of finger_joint (URDF)"
    assert joints["finger_joint"].controller == "gripper" and joints["finger_joint"].method == "effort"
    plugin = arm_report.joint_infos(parse_urdf(ROBOT), TREE, "/", CONTROLLERS, (), [("finger_joint", "finger2_joint")])
    assert plugin[-1].role == "mimic of finger_joint (plugin)"


def test_a_bad_rosparam_limit_names_the_parameter():
    tree = dict(TREE, joint_limits={"shoulder": {"has_velocity_limits": True, "max_velocity": "fast"}})
    with pytest.raises(ConfigError, match="/joint_limits/shoulder"):
        infos(tree)


def test_format_joints_one_line_each():
    lines = arm_report.format_joints(list(infos().values()))
    assert lines[0] == "joints with a transmission: 4"
    assert ("  shoulder: revolute, PositionJointInterface (position, pid_gains p 20), [-1.5, 1.5] rad, 0.8 rad/s, "
            "6 N·m; arm_controller (position_controllers/JointTrajectoryController)") in lines
    assert any(line.startswith("  wheel_joint: continuous") and "no position limits" in line for line in lines)
    assert arm_report.format_joints([]) == []


def test_step_target_moves_away_from_the_nearer_limit_within_the_range():
    joints = infos()
    shoulder, finger = joints["shoulder"], joints["finger_joint"]
    assert arm_report.step_target(shoulder, 0.0) == pytest.approx(0.2)
    assert arm_report.step_target(shoulder, 1.45) == pytest.approx(1.25)
    assert arm_report.step_target(shoulder, -1.45) == pytest.approx(-1.25)
    assert arm_report.step_target(finger, 0.0) == pytest.approx(0.01)  # a third of its 3 cm range
    assert arm_report.step_target(joints["wheel_joint"], 5.0) == pytest.approx(5.2)  # no limits


def test_plan_moves_per_controller_and_says_what_is_not_moved():
    joints = list(infos().values())
    moves, skipped = arm_report.plan_moves(joints, {"shoulder": 0.1, "finger_joint": 0.0},
                                           arm_report.controller_joints(CONTROLLERS, "/"))
    by_name = {m.controller: m for m in moves}
    assert by_name["arm_controller"].how == arm_report.TRAJECTORY
    assert by_name["arm_controller"].targets == pytest.approx([-0.1])  # away from the nearer (upper) limit
    assert by_name["gripper"].how == arm_report.GRIPPER and by_name["gripper"].moved == ["finger_joint"]
    assert skipped == []  # the wheel and the mimic finger are not arm joints
    lone = [j for j in joints if j.name == "shoulder"]
    lone[0].controller, lone[0].controller_type = "", ""
    assert arm_report.plan_moves(lone, {"shoulder": 0.0}, {}) == ([], [("shoulder", "no controller")])


def test_judge_move_wants_the_joints_there_and_the_body_agreeing():
    move = arm_report.Move("arm_controller", "t", arm_report.TRAJECTORY, ["shoulder"], [0.3], ["shoulder"])
    good = {"base": PoseError(0.0, 0.0), "upper": PoseError(0.001, 0.002)}
    result = arm_report.judge_move(move, "out", {"shoulder": 0.3}, {"shoulder": 0.29}, {}, good, "SUCCEEDED")
    assert result.passed and result.worst_link == "upper"
    stuck = arm_report.judge_move(move, "out", {"shoulder": 0.3}, {"shoulder": 0.0}, {}, good)
    assert not stuck.passed and "shoulder at 0.0, sent to 0.3000" in stuck.failures[0]
    off = arm_report.judge_move(move, "out", {"shoulder": 0.3}, {"shoulder": 0.3}, {},
                                {"base": PoseError(0.0, 0.0), "upper": PoseError(0.02, 0.0)})
    assert not off.passed and "link upper is 20.0 mm" in off.failures[0]
    assert not arm_report.judge_move(move, "out", {"shoulder": 0.3}, {"shoulder": 0.3}, {}, {}).passed
    lines = arm_report.format_moves([result, stuck], [("elbow", "no controller")])
    assert lines[0].startswith("  arm_controller out: shoulder +0.300 (at +0.290), SUCCEEDED; worst link upper")
    assert lines[0].endswith(": PASS") and lines[1].endswith(": FAIL")
    assert lines[-1] == "  elbow: not moved (no controller)"


def test_gripper_max_effort_from_the_controller_else_the_joint():
    finger = infos()["finger_joint"]
    assert arm_report.max_effort_for(finger, {"max_effort": 4}) == 4.0
    assert arm_report.max_effort_for(finger, {}) == 10.0
    assert arm_report.max_effort_for(None, {}) == 10.0
    assert math.isinf(infos()["wheel_joint"].lower)
