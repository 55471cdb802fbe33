"""gazebo_ros_control's DefaultRobotHWSim (plugins/ros_control/hardware.RobotHWSim) and robot_check skip the
transmissions it does not simulate (franka_hw's multi-joint state and model interfaces, an unknown interface)
with one warning each, and give every other transmission joint its handle."""
import os
from types import SimpleNamespace

from diffbot_sim.check import robot_report
from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.plugins.registry import KNOWN, KNOWN_SENSORS
from diffbot_sim.plugins.ros_control import hardware

FIXTURE = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "data",
                       "robots", "arm_franka_transmissions.urdf")
SKIPPED = [
    "gazebo_ros_control: transmission 'arm_franka_state' (franka_hw/FrankaStateInterface) skipped by "
    "DefaultRobotHWSim: it names 3 joints; DefaultRobotHWSim simulates one per transmission",
    "gazebo_ros_control: transmission 'arm_franka_model' (franka_hw/FrankaModelInterface) skipped by "
    "DefaultRobotHWSim: it names 2 joints; DefaultRobotHWSim simulates one per transmission",
    "gazebo_ros_control: transmission 'wrist_trans' (transmission_interface/SimpleTransmission) skipped by "
    "DefaultRobotHWSim: its hardware interface 'hardware_interface/PosVelJointInterface' is not one it "
    "simulates (VelocityJointInterface, EffortJointInterface, PositionJointInterface)",
]


def test_default_hardware_skips_them_with_one_warning_each(monkeypatch):
    model = parse_urdf(open(FIXTURE).read(), FIXTURE)
    freed = []
    robot = SimpleNamespace(joint_index={"joint_1": 0, "joint_2": 1, "joint_3": 2, "wrist_joint": 3},
                            free_joints=freed.extend)
    ctx = SimpleNamespace(model=model, robot=robot, cfg=SimpleNamespace(time_step=0.001))
    monkeypatch.setattr(hardware, "get_param", lambda name, default: default)  # no parameter server
    warnings = []
    hw = hardware.RobotHWSim(ctx, "/", warnings)
    assert warnings == SKIPPED
    assert list(hw.joints) == ["joint_1", "joint_2", "joint_3"]  # wrist_joint has no handle: left free
    assert {j.method for j in hw.joints.values()} == {hardware.EFFORT} and freed == [0, 1, 2]


def test_robot_check_reports_the_same_lines(tmp_path):
    report = robot_report.build_report(FIXTURE, "", [], KNOWN, KNOWN_SENSORS, cache_dir=str(tmp_path))
    assert [w for w in report.warnings if "skipped by DefaultRobotHWSim" in w] == SKIPPED
