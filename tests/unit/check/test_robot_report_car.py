"""robot_report on car-like robots and contact sensors: the car fixtures of tests/data/car_way (an Ackermann bicycle
model, a SteerBotHardwareGazebo base) are reported as cars with their wheelbase, rear axle and the radii the arc may
have; contact sensors are listed with the collision they watch (as Gazebo names it) and what publishes them."""
import os
import subprocess

import pytest
import yaml

from diffbot_sim.check import arc_check, report_text, robot_report
from diffbot_sim.plugins.registry import KNOWN, KNOWN_SENSORS

DATA = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "data")
CAR = os.path.join(DATA, "car_way")


def _yaml(*names):
    out = []
    for name in names:
        path = os.path.join(CAR, "carlike_control", "config", name)
        with open(path) as handle:
            out.append((path, yaml.safe_load(handle)))
    return out


def _urdf(tmp_path, name):
    env = dict(os.environ, ROS_PACKAGE_PATH=os.environ.get("ROS_PACKAGE_PATH", "") + os.pathsep + CAR)
    text = subprocess.run(["xacro", os.path.join(CAR, "carlike_description", "urdf", name)], env=env,
                          capture_output=True, text=True, check=True).stdout
    path = tmp_path / name.replace(".xacro", "")
    path.write_text(text)
    return str(path)


def test_bicycle_is_a_car_with_its_wheelbase(tmp_path):
    report = robot_report.build_report(_urdf(tmp_path, "bicycle_bot.urdf.xacro"), "",
                                       _yaml("bicycle_ackermann_controller.yaml", "joint_state_publisher.yaml"),
                                       KNOWN, KNOWN_SENSORS, cache_dir=str(tmp_path / "cache"),
                                       known_controllers=["ackermann_steering_controller/AckermannSteeringController",
                                                          "joint_state_controller/JointStateController"])
    assert report.car and report.drive.wheelbase == pytest.approx(0.4)
    assert report.drive.rear_axle == pytest.approx((-0.2, 0.0)) and report.drive.radius_range is None
    assert not report.arm_joints  # the steering joint is the car's, not an arm's
    assert any("car-like" in line for line in report_text.format_report(report))


def test_steer_bot_base_gives_its_front_wheels_radii(tmp_path):
    report = robot_report.build_report(_urdf(tmp_path, "ackermann_base.urdf.xacro"), "",
                                       _yaml("base_ackermann_controller.yaml", "gains.yaml",
                                             "steer_bot_hardware_gazebo.yaml"), KNOWN, KNOWN_SENSORS,
                                       cache_dir=str(tmp_path / "cache"),
                                       known_controllers=["ackermann_steering_controller/AckermannSteeringController"])
    assert report.car and report.drive.wheelbase == pytest.approx(0.4)  # measured from the URDF
    low, high = sorted(abs(r) for r in report.drive.radius_range)
    assert low < arc_check.geometry_radius(0.4, arc_check.ARC_STEER) < high
    assert not any("robotSimType" in w for w in report.warnings)


def test_contact_sensors_are_listed(tmp_path):
    report = robot_report.build_report(os.path.join(DATA, "robots", "kobuki_bumper.urdf"), "", [], KNOWN,
                                       KNOWN_SENSORS, cache_dir=str(tmp_path / "cache"))
    assert len(report.contacts) == 3
    assert "base_footprint_fixed_joint_lump__base_link_collision" in report.contacts[0]
    assert "/bumper_states" in report.contacts[0] and "events/bumper" in report.contacts[0]
    assert "contact sensors:" in report_text.format_report(report)
