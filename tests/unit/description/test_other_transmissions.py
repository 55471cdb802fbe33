"""urdf_model: transmissions gazebo_ros_control's DefaultRobotHWSim does not simulate (several joints, as
franka_hw's state and model interfaces; or another hardware interface) are kept apart in
``RobotModel.other_transmissions`` with the reason, instead of refusing the robot."""
import os

import pytest

from diffbot_sim.description.urdf_model import OtherTransmission, parse_urdf
from diffbot_sim.errors import ModelError

FIXTURE = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "data",
                       "robots", "arm_franka_transmissions.urdf")


def fixture_text():
    with open(FIXTURE) as handle:
        return handle.read()


def test_franka_transmissions_are_kept_apart_and_the_rest_loads():
    model = parse_urdf(fixture_text(), FIXTURE)
    assert [(t.joint, t.interface) for t in model.transmissions] == [
        ("joint_1", "EffortJointInterface"), ("joint_2", "EffortJointInterface"), ("joint_3", "EffortJointInterface")]
    state, kinematics, wrist = model.other_transmissions
    assert state == OtherTransmission("arm_franka_state", "franka_hw/FrankaStateInterface",
                                      ["joint_1", "joint_2", "joint_3"], ["franka_hw/FrankaStateInterface"] * 3,
                                      "it names 3 joints; DefaultRobotHWSim simulates one per transmission",
                                      ["", "", ""])
    assert (kinematics.joints, kinematics.interfaces, kinematics.roles) == (
        ["joint_1", "joint_3"], ["franka_hw/FrankaModelInterface"] * 2, ["root", "tip"])  # FrankaHWSim's chain
    assert wrist.joints == ["wrist_joint"] and wrist.interfaces == ["hardware_interface/PosVelJointInterface"]
    assert wrist.warning == ("transmission 'wrist_trans' (transmission_interface/SimpleTransmission) skipped by "
                             "DefaultRobotHWSim: its hardware interface 'hardware_interface/PosVelJointInterface' "
                             "is not one it simulates (VelocityJointInterface, EffortJointInterface, "
                             "PositionJointInterface)")
    assert model.warnings == []  # the hardware that skips them says so (gazebo_ros_control only warns there)


def test_a_skipped_transmission_never_looks_its_joints_up():
    """DefaultRobotHWSim skips a multi-joint transmission before asking the model for its joints."""
    text = fixture_text().replace('<joint name="joint_3"><role>tip</role>', '<joint name="ghost"><role>tip</role>')
    assert parse_urdf(text, FIXTURE).other_transmissions[1].joints == ["joint_1", "ghost"]
    text = fixture_text().replace('<joint name="wrist_joint"><hardwareInterface>hardware_interface/PosVel',
                                  '<joint name="ghost"><hardwareInterface>hardware_interface/PosVel')
    assert parse_urdf(text, FIXTURE).other_transmissions[2].joints == ["ghost"]


def test_a_transmission_without_a_joint_is_still_refused():
    text = fixture_text().replace(
        '<joint name="wrist_joint"><hardwareInterface>hardware_interface/PosVelJointInterface</hardwareInterface>'
        '</joint>',
        '')
    with pytest.raises(ModelError, match=r"transmission\[@name='wrist_trans'\]: names no <joint>"):
        parse_urdf(text, FIXTURE)
