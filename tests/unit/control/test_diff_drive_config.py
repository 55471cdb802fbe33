"""diff_drive_config.diff_drive_controller_config: a DiffDriveController's parameters read as ros_controllers
(noetic) reads them: its defaults, its precedence, and one ConfigError naming the full parameter for a value it
cannot use.
"""
import math

import pytest

from diffbot_sim.control.diff_drive_config import (
    CONTROLLER_TYPE,
    DiffDriveControllerConfig,
    diff_drive_controller_config,
)
from diffbot_sim.errors import ConfigError

NS = "/diffbot_controller"

# test/diffbot_controllers.yaml, as rospy.get_param returns it
BASE = {
    "type": "diff_drive_controller/DiffDriveController",
    "left_wheel": "wheel_0_joint",
    "right_wheel": "wheel_1_joint",
    "publish_rate": 50.0,
    "pose_covariance_diagonal": [0.001, 0.001, 1000000.0, 1000000.0, 1000000.0, 1000.0],
    "twist_covariance_diagonal": [0.001, 0.001, 1000000.0, 1000000.0, 1000000.0, 1000.0],
    "cmd_vel_timeout": 20.0,
}

def params(**overrides):
    merged = dict(BASE)
    merged.update(overrides)
    return merged


def test_config_defaults_are_noetic():
    config = diff_drive_controller_config({"left_wheel": "l", "right_wheel": "r"}, "/mobile_base_controller")
    assert isinstance(config, DiffDriveControllerConfig)
    assert config.name == "/mobile_base_controller"
    assert (config.left_wheels, config.right_wheels) == (("l",), ("r",))
    assert config.wheel_separation is None and config.wheel_radius is None
    assert (config.wheel_separation_multiplier, config.left_wheel_radius_multiplier,
            config.right_wheel_radius_multiplier) == (1.0, 1.0, 1.0)
    assert config.publish_rate == 50.0 and config.publish_period == pytest.approx(0.02)
    assert config.open_loop is False
    assert config.velocity_rolling_window_size == 10
    assert config.cmd_vel_timeout == 0.5
    assert config.allow_multiple_cmd_vel_publishers is True
    assert (config.base_frame_id, config.odom_frame_id) == ("base_link", "odom")
    assert config.enable_odom_tf is True
    assert config.publish_cmd is False and config.publish_wheel_joint_controller_state is False
    for axis in (config.linear, config.angular):
        assert not (axis.has_velocity_limits or axis.has_acceleration_limits or axis.has_jerk_limits)
        assert (axis.max_velocity, axis.min_velocity) == (0.0, 0.0)
    assert config.unknown_keys == () and config.unsupported == ()


def test_config_from_a_real_robot_yaml():
    yaml = {
        "type": CONTROLLER_TYPE,
        "left_wheel": ["front_left_wheel", "rear_left_wheel"],
        "right_wheel": ["front_right_wheel", "rear_right_wheel"],
        "publish_rate": 50,  # an int where upstream reads a double
        "pose_covariance_diagonal": [0.001, 0.001, 1000000, 1000000, 1000000, 0.03],
        "twist_covariance_diagonal": [0.001, 0.001, 0.001, 1000000, 1000000, 0.03],
        "base_frame_id": "base_footprint",
        "wheel_separation_multiplier": 1.875,
        "wheel_radius_multiplier": 1,
        "cmd_vel_timeout": 0.25,
        "enable_odom_tf": False,
        "velocity_rolling_window_size": 2,
        "linear": {"x": {"has_velocity_limits": True, "max_velocity": 2, "has_acceleration_limits": True,
                         "max_acceleration": 20.0}},
        "angular": {"z": {"has_velocity_limits": True, "max_velocity": 2.0943951023931953,
                          "has_acceleration_limits": True, "max_acceleration": 6}},
        "k_l": 0.1, "k_r": 0.1,
    }
    config = diff_drive_controller_config(yaml, "/husky/mobile_base_controller/")
    assert config.name == "/husky/mobile_base_controller"
    assert config.joints == ("front_left_wheel", "rear_left_wheel", "front_right_wheel", "rear_right_wheel")
    assert config.publish_rate == 50.0 and isinstance(config.publish_rate, float)
    assert config.pose_covariance_diagonal == (0.001, 0.001, 1e6, 1e6, 1e6, 0.03)
    assert config.wheel_separation_multiplier == 1.875
    assert config.left_wheel_radius_multiplier == config.right_wheel_radius_multiplier == 1.0
    assert config.velocity_rolling_window_size == 2
    assert config.linear.max_velocity == 2.0 and config.linear.min_velocity == -2.0
    assert config.linear.min_acceleration == -20.0
    assert config.angular.max_acceleration == 6.0
    assert config.linear.has_jerk_limits is False
    assert config.unknown_keys == ("/husky/mobile_base_controller/k_l", "/husky/mobile_base_controller/k_r")
    assert config.warnings == ()


@pytest.mark.parametrize("value", [None, "", [], 3, ["a", 7], ["a", ""], {"a": 1}])
def test_bad_wheel_names_name_the_parameter(value):
    yaml = {"right_wheel": "r"}
    if value is not None:
        yaml["left_wheel"] = value
    with pytest.raises(ConfigError, match="/mobile_base_controller/left_wheel"):
        diff_drive_controller_config(yaml, "/mobile_base_controller")


def test_wheel_counts_must_match():
    with pytest.raises(ConfigError, match="/mobile_base_controller/right_wheel.*as many joints"):
        diff_drive_controller_config({"left_wheel": ["a", "b"], "right_wheel": "c"}, "/mobile_base_controller")


def test_wheel_radius_multiplier_overrides_per_side():
    config = diff_drive_controller_config(params(wheel_radius_multiplier=1.2, left_wheel_radius_multiplier=0.9), NS)
    assert config.left_wheel_radius_multiplier == config.right_wheel_radius_multiplier == 1.2
    assert any("left_wheel_radius_multiplier" in w and "ignored" in w for w in config.warnings)
    config = diff_drive_controller_config(params(left_wheel_radius_multiplier=0.9,
                                                 right_wheel_radius_multiplier=1.1), NS)
    assert (config.left_wheel_radius_multiplier, config.right_wheel_radius_multiplier) == (0.9, 1.1)
    assert config.warnings == ()


def test_missing_covariances_are_zeros_with_a_warning():
    yaml = params()
    del yaml["pose_covariance_diagonal"], yaml["twist_covariance_diagonal"]
    config = diff_drive_controller_config(yaml, NS)
    assert config.pose_covariance_diagonal == config.twist_covariance_diagonal == (0.0,) * 6
    assert len(config.warnings) == 2
    assert f"{NS}/pose_covariance_diagonal" in config.warnings[0]


@pytest.mark.parametrize("value, culprit", [([0.1] * 5, ""), ("0.1", ""), ([0.1] * 5 + ["x"], "[5]"),
                                            ([0.1] * 5 + [math.nan], "[5]")])
def test_bad_covariance_names_the_parameter(value, culprit):
    with pytest.raises(ConfigError) as info:
        diff_drive_controller_config(params(twist_covariance_diagonal=value), NS)
    assert info.value.name == f"{NS}/twist_covariance_diagonal{culprit}"


def test_unknown_keys_collected_at_every_level():
    yaml = params(k_l=0.1, preserve_turning_radius=True,
                  linear={"x": {"max_velocity": 1.0, "max_vel": 2.0}, "y": {"max_velocity": 1.0}},
                  angular={"z": {}})
    config = diff_drive_controller_config(yaml, NS)
    assert set(config.unknown_keys) == {f"{NS}/k_l", f"{NS}/preserve_turning_radius", f"{NS}/linear/y",
                                        f"{NS}/linear/x/max_vel"}


def test_leading_slash_frames_stripped_with_warning():
    config = diff_drive_controller_config(params(base_frame_id="/base_footprint", odom_frame_id="/odom"), NS)
    assert (config.base_frame_id, config.odom_frame_id) == ("base_footprint", "odom")
    assert len(config.warnings) == 2 and "leading slash" in config.warnings[0]


@pytest.mark.parametrize("key, value", [("base_frame_id", ""), ("odom_frame_id", "/"), ("base_frame_id", 3)])
def test_bad_frames(key, value):
    with pytest.raises(ConfigError, match=f"{NS}/{key}"):
        diff_drive_controller_config(params(**{key: value}), NS)


@pytest.mark.parametrize("key, value", [
    ("publish_rate", "50"), ("publish_rate", -1.0), ("cmd_vel_timeout", -0.5), ("cmd_vel_timeout", math.nan),
    ("wheel_separation", 0), ("wheel_radius", -0.1), ("wheel_separation_multiplier", 0.0),
    ("wheel_radius_multiplier", True), ("left_wheel_radius_multiplier", math.inf),
    ("open_loop", "true"), ("enable_odom_tf", 1), ("publish_cmd", None),
    ("allow_multiple_cmd_vel_publishers", 0), ("velocity_rolling_window_size", 0),
    ("velocity_rolling_window_size", 2.5), ("velocity_rolling_window_size", False),
    ("type", "diff_drive_controller/SkidSteer"), ("linear", 1.0),
])
def test_bad_values_name_the_parameter(key, value):
    with pytest.raises(ConfigError) as info:
        diff_drive_controller_config(params(**{key: value}), NS)
    assert info.value.name == f"{NS}/{key}"


@pytest.mark.parametrize("limits, culprit", [
    ({"x": {"has_velocity_limits": 1}}, "linear/x/has_velocity_limits"),
    ({"x": {"max_velocity": "fast"}}, "linear/x/max_velocity"),
    ({"x": {"has_acceleration_limits": True, "max_acceleration": 1.0, "min_acceleration": 2.0}},
     "linear/x/min_acceleration"),
    ({"x": 5}, "linear/x"),
])
def test_bad_limits_name_the_parameter(limits, culprit):
    with pytest.raises(ConfigError) as info:
        diff_drive_controller_config(params(linear=limits), NS)
    assert info.value.name == f"{NS}/{culprit}"


def test_disabled_limits_are_not_cross_checked():
    config = diff_drive_controller_config(params(linear={"x": {"max_acceleration": 1.0, "min_acceleration": 2.0}}), NS)
    assert config.linear.min_acceleration == 2.0


def test_ints_and_integral_window_accepted():
    config = diff_drive_controller_config(params(cmd_vel_timeout=1, wheel_separation=1, wheel_radius=1,
                               velocity_rolling_window_size=4.0, publish_rate=100,
                               angular={"z": {"has_jerk_limits": True, "max_jerk": 10}}), NS)
    assert config.cmd_vel_timeout == 1.0 and config.publish_rate == 100.0
    assert config.velocity_rolling_window_size == 4 and isinstance(config.velocity_rolling_window_size, int)
    assert config.angular.max_jerk == 10.0 and config.angular.min_jerk == -10.0
    assert (config.wheel_separation, config.wheel_radius) == (1.0, 1.0)


def test_wheel_joint_controller_state_is_unsupported():
    config = diff_drive_controller_config(params(publish_wheel_joint_controller_state=True), NS)
    assert config.unsupported == (f"{NS}/publish_wheel_joint_controller_state",)
    assert len(config.warnings) == 1
