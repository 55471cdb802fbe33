"""SteerBotHardwareGazebo's YAML and its linkage, as steer_bot_hardware_gazebo.cpp reads and computes them."""
import math

import pytest

from diffbot_sim.control.steer_bot_hardware import linkage_angles, steer_bot_config
from diffbot_sim.errors import ConfigError

NS = "/steer_bot"
# steer_bot_control/config/ctrl_steer_bot_hardware_gazebo.yaml and ctrl_gains.yaml of a published steer bot
PARAMS = {"rear_wheel": "rear_wheel_joint", "front_steer": "front_steer_joint",
          "virtual_rear_wheels": ["rear_right_wheel_joint", "rear_left_wheel_joint"],
          "virtual_front_wheels": ["front_right_wheel_joint", "front_left_wheel_joint"],
          "virtual_front_steers": ["front_right_steer_joint", "front_left_steer_joint"],
          "enable_ackermann_link": True, "wheel_separation_h": 0.4, "wheel_separation_w": 0.4}
GAINS = {"rear_right_wheel_joint": {"p": 100000.0, "d": 10.0, "i": 0.5, "i_clamp": 3.0},
         "rear_left_wheel_joint": {"p": 100000.0, "d": 10.0, "i": 0.5, "i_clamp": 3.0}}


def test_config_reads_the_published_yaml():
    cfg = steer_bot_config(PARAMS, GAINS, NS)
    assert cfg.virtual_front_steers == ("front_right_steer_joint", "front_left_steer_joint")
    assert cfg.virtual_wheels[:2] == ("rear_right_wheel_joint", "rear_left_wheel_joint")
    assert (cfg.wheel_separation_h, cfg.wheel_separation_w, cfg.enable_ackermann_link) == (0.4, 0.4, True)


def test_ackermann_link_is_upstreams_formula():
    """atan2(2h tan d, 2h + w/2 tan d) on the right, 2h - w/2 tan d on the left: the inner (left, for a left
    turn) wheel steers more, and the two wheels' mean cotangent is the bicycle model's."""
    cfg = steer_bot_config(PARAMS, GAINS, NS)
    right, left = linkage_angles(0.3, cfg)
    t, h, w = math.tan(0.3), 0.4, 0.4
    assert math.tan(right) == pytest.approx(2 * h * t / (2 * h + w / 2 * t))
    assert math.tan(left) == pytest.approx(2 * h * t / (2 * h - w / 2 * t))
    assert left > 0.3 > right > 0
    assert (1 / math.tan(right) + 1 / math.tan(left)) / 2 == pytest.approx(1 / t)
    assert linkage_angles(-0.3, cfg) == pytest.approx((-left, -right))


def test_parallel_link_doubles_the_left_angle_as_upstream_writes_it():
    cfg = steer_bot_config({**PARAMS, "enable_ackermann_link": False}, GAINS, NS)
    assert linkage_angles(0.2, cfg) == (0.2, 0.4)


def test_missing_pieces_name_their_parameter():
    with pytest.raises(ConfigError, match="/steer_bot/gains/rear_left_wheel_joint/p"):
        steer_bot_config(PARAMS, {"rear_right_wheel_joint": {"p": 1.0}}, NS)
    with pytest.raises(ConfigError, match="/steer_bot/steer_bot_hardware_gazebo/virtual_front_steers"):
        steer_bot_config({**PARAMS, "virtual_front_steers": ["one"]}, GAINS, NS)
    with pytest.raises(ConfigError, match="wheel_separation_w"):
        steer_bot_config({k: v for k, v in PARAMS.items() if k != "wheel_separation_w"}, GAINS, NS)
    with pytest.raises(ConfigError, match="/steer_bot/steer_bot_hardware_gazebo"):
        steer_bot_config(None, GAINS, NS)
