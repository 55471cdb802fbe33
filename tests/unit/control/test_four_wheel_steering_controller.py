"""four_wheel_steering_controller: parameters, URDF geometry as urdf_geometry_parser measures it, the
commands and the odometry, on a perfect robot (wheel velocities and steering angles are the commands), as
upstream's four_wheel_steering rostests drive it (a Twist or a FourWheelSteering command, 10 s)."""
import math

import pytest

from diffbot_sim.control.four_wheel_steering_controller import (
    FourWheelSteeringCore,
    Geometry,
    axle_steering,
    four_wheel_steering_commands,
    four_wheel_steering_config,
    joint_distance,
    joint_offset,
    resolve_geometry,
    twist_commands,
)
from diffbot_sim.errors import ConfigError

NS = "/four_wheel_steering_controller"
DT = 0.01
BASE = {"type": "four_wheel_steering_controller/FourWheelSteeringController",
        "front_wheel": ["front_left_wheel", "front_right_wheel"],
        "rear_wheel": ["rear_left_wheel", "rear_right_wheel"],
        "front_steering": ["front_left_steering_joint", "front_right_steering_joint"],
        "rear_steering": ["rear_left_steering_joint", "rear_right_steering_joint"],
        "publish_rate": 50.0, "cmd_vel_timeout": 20.0,
        "pose_covariance_diagonal": [0.001] * 6, "twist_covariance_diagonal": [0.001] * 6}
GEOMETRY = Geometry(track=1.1, wheel_steering_y_offset=0.03, wheel_radius=0.28, wheel_base=1.1)


class Robot:
    def __init__(self, **overrides):
        self.core = FourWheelSteeringCore(four_wheel_steering_config({**BASE, **overrides}, NS), GEOMETRY)
        self.t = 0.0
        self.wheels = (0.0,) * 4
        self.steerings = (0.0,) * 4
        self.core.starting(0.0)

    def run(self, seconds):
        for _ in range(int(round(seconds / DT))):
            self.t += DT
            step = self.core.update(self.t, self.wheels, self.steerings, DT)
            self.wheels, self.steerings = step.wheels, step.steerings


def test_twist_forward_and_turn_are_read_back_by_the_odometry():
    robot = Robot()
    assert robot.core.set_twist(0.5, 0.0, 0.0, 0.0) is None
    robot.run(10.0)
    x, y, yaw = robot.core.pose
    assert x == pytest.approx(5.0, abs=0.02) and abs(y) < 1e-6 and abs(yaw) < 1e-9
    robot = Robot()
    robot.core.set_twist(0.3, 0.0, 0.2, 0.0)
    robot.run(10.0)
    # upstream reads its front axle speed from the raw wheel speeds: 1.4 % high with a steering offset
    assert robot.core.odometry.angular == pytest.approx(0.2, rel=0.02)
    assert robot.core.odometry.linear_x == pytest.approx(0.3, rel=0.02)
    assert robot.core.pose[2] == pytest.approx(0.2 * (10.0 - DT), rel=0.02)


def test_twist_steers_front_and_rear_opposite_about_one_centre():
    """Each wheel's steering points at the centre of rotation (0, R) of a symmetric turn: tan = (L/2)/(R ± t/2)."""
    (fl, fr, rl, rr), (sfl, sfr, srl, srr) = twist_commands(0.4, 0.2, GEOMETRY)
    radius, half = 0.4 / 0.2, GEOMETRY.steering_track / 2
    assert math.tan(sfl) == pytest.approx((GEOMETRY.wheel_base / 2) / (radius - half))
    assert math.tan(sfr) == pytest.approx((GEOMETRY.wheel_base / 2) / (radius + half))
    assert (srl, srr) == (-sfl, -sfr)
    assert fl == rl and fr == rr and fr > fl > 0


def test_four_wheel_steering_command_and_axle_angles():
    (_, _, _, _), steer = four_wheel_steering_commands(0.5, 0.3, 0.0, GEOMETRY)
    assert steer[2] == steer[3] == 0.0
    assert axle_steering(steer[0], steer[1]) == pytest.approx(0.3)
    robot = Robot()
    robot.core.set_four_wheel_steering(0.5, 0.3, 0.0, 0.0)
    robot.run(5.0)
    assert robot.core.axle_steering[0] == pytest.approx(0.3)
    assert robot.core.odometry.angular == pytest.approx(0.5 * math.tan(0.3) / GEOMETRY.wheel_base, rel=0.01)


def test_the_newer_command_drives_and_the_timeout_brakes():
    robot = Robot(cmd_vel_timeout=0.5)
    robot.core.set_four_wheel_steering(0.5, 0.2, 0.0, 0.0)
    robot.t = 0.0
    robot.run(0.1)
    assert not robot.core.twist_mode
    robot.core.set_twist(0.5, 0.0, 0.0, robot.t)
    robot.run(0.1)
    assert robot.core.twist_mode and robot.steerings == (0.0,) * 4
    robot.run(1.0)
    assert robot.wheels == (0.0,) * 4


def test_nan_commands_are_refused():
    robot = Robot()
    assert "NaN" in robot.core.set_twist(float("nan"), 0.0, 0.0, 0.0)
    assert "NaN" in robot.core.set_four_wheel_steering(0.0, float("nan"), 0.0, 0.0)


def test_geometry_sums_origins_up_to_the_base_frame():
    joints = {"front_left_steering_joint": ("base_link", "fl_steer", (0.55, 0.55, 0.1)),
              "front_left_wheel": ("fl_steer", "fl_wheel", (0.0, 0.03, -0.1)),
              "front_right_steering_joint": ("base_link", "fr_steer", (0.55, -0.55, 0.1)),
              "front_right_wheel": ("fr_steer", "fr_wheel", (0.0, -0.03, -0.1)),
              "rear_left_steering_joint": ("base_link", "rl_steer", (-0.55, 0.55, 0.1)),
              "rear_left_wheel": ("rl_steer", "rl_wheel", (0.0, 0.03, -0.1))}
    assert joint_offset(joints, "front_left_wheel", "base_link") == pytest.approx((0.55, 0.58, 0.0))
    assert joint_distance(joints, "front_left_wheel", "front_right_wheel", "base_link") == pytest.approx(1.16)
    assert joint_distance(joints, "front_left_steering_joint", "front_left_wheel", "base_link") == \
        pytest.approx(0.03)
    assert joint_distance(joints, "front_left_wheel", "rear_left_wheel", "base_link") == pytest.approx(1.1)
    with pytest.raises(KeyError, match="parent joint"):
        joint_offset(joints, "front_left_wheel", "base_footprint")
    cfg = four_wheel_steering_config({**BASE, "wheel_radius": 0.3}, NS)
    geometry = resolve_geometry(cfg, 1.16, 0.03, 0.28, 1.1)
    assert geometry.wheel_radius == 0.3 and geometry.steering_track == pytest.approx(1.1)


def test_config_errors_and_unread_keys():
    with pytest.raises(ConfigError, match=f"{NS}/rear_steering"):
        four_wheel_steering_config({**BASE, "rear_steering": ["only_one"]}, NS)
    with pytest.raises(ConfigError, match=f"{NS}/front_wheel"):
        four_wheel_steering_config({k: v for k, v in BASE.items() if k != "front_wheel"}, NS)
    cfg = four_wheel_steering_config({**BASE, "odom_frame_id": "my_odom",
                                      "linear": {"x": {"has_jerk_limits": True, "max_jerk": 1.0}}}, NS)
    assert f"{NS}/odom_frame_id" in cfg.unknown_keys and f"{NS}/linear/x/has_jerk_limits" in cfg.unknown_keys
    assert not cfg.linear.has_jerk_limits
