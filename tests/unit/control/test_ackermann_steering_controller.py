"""ackermann_steering_controller: parameters, odometry and per-update core, checked as upstream's rostests
check them (ackermann_steering_controller/test/*), on a harness like its ackermann_steering_bot: dt 0.01 s, a
rear wheel whose velocity is the last command (position += velocity · dt) and a steer that is where it was
told; plus the quirks upstream has (angular.z is the steering angle, the unmultiplied radius, no
publish_cmd)."""
import math

import pytest

from diffbot_sim.control.ackermann_steering_controller import (
    AckermannOdometry,
    AckermannSteeringCore,
    ackermann_config,
    turning_radius,
)
from diffbot_sim.errors import ConfigError

NS = "/ackermann_steering_bot_controller"
DT = 0.01
# test/common/config/ackermann_steering_bot_controllers.yaml (cmd_vel_timeout 20: tested separately)
BASE = {"type": "ackermann_steering_controller/AckermannSteeringController", "rear_wheel": "rear_wheel_joint",
        "front_steer": "front_steer_joint", "publish_rate": 50.0,
        "pose_covariance_diagonal": [0.001, 0.001, 1e6, 1e6, 1e6, 1000.0],
        "twist_covariance_diagonal": [0.001, 0.001, 1e6, 1e6, 1e6, 1000.0],
        "cmd_vel_timeout": 20.0, "wheel_separation_h_multiplier": 0.257}
SEPARATION_H, RADIUS = 0.4, 0.11  # the test bot's URDF
POSITION_TOLERANCE, VELOCITY_TOLERANCE, EPS, ORIENTATION_TOLERANCE = 0.01, 0.02, 0.01, 0.03


class Bot:
    """The controller on a perfect bicycle: wheel velocity and steer position are the commands."""

    def __init__(self, **overrides):
        self.core = AckermannSteeringCore(ackermann_config({**BASE, **overrides}, NS), SEPARATION_H, RADIUS)
        self.t = 0.0
        self.wheel = self.steer = self.wheel_velocity = 0.0
        self.core.starting(self.t)
        self.steps = []

    def run(self, seconds, command=None):
        if command is not None:
            assert self.core.set_command(*command, self.t) is None
        for _ in range(int(round(seconds / DT))):
            self.t += DT
            self.wheel += self.wheel_velocity * DT
            step = self.core.update(self.t, self.wheel, self.steer, DT)
            self.wheel_velocity, self.steer = step.wheel_velocity, step.steer_position
            self.steps.append(step)


def test_forward_travels_one_metre_straight():
    bot = Bot()
    bot.run(2.0, (0.0, 0.0))
    x0, y0, yaw0 = bot.core.pose
    bot.run(10.0, (0.1, 0.0))
    x, y, yaw = bot.core.pose
    assert math.hypot(x - x0, y - y0) == pytest.approx(1.0, abs=POSITION_TOLERANCE)
    assert abs(yaw - yaw0) < EPS
    assert bot.core.velocity[0] == pytest.approx(0.1, abs=EPS) and abs(bot.core.velocity[1]) < EPS


def test_turn_half_circle_with_upstreams_calibration():
    """upstream's testTurn: angular.z = pi/10 is the steering angle; with wheel_separation_h_multiplier
    0.257 the yaw rate tan(pi/10)·v/(0.4·0.257) is within its tolerance of pi/10 rad/s: a half circle in 10 s."""
    bot = Bot()
    bot.run(2.0, (0.0, 0.0))
    x0, y0, yaw0 = bot.core.pose
    bot.run(10.0, (0.1, math.pi / 10.0))
    x, y, yaw = bot.core.pose
    assert abs(x - x0) == pytest.approx(0.0, abs=POSITION_TOLERANCE)
    assert abs(y - y0) == pytest.approx(2.0 * 0.1 / (math.pi / 10.0), abs=0.02)
    assert abs(yaw - yaw0) == pytest.approx(math.pi, abs=ORIENTATION_TOLERANCE + 0.01)
    assert bot.core.velocity[0] == pytest.approx(0.1, abs=VELOCITY_TOLERANCE)
    assert abs(bot.core.velocity[1]) == pytest.approx(math.pi / 10.0, abs=EPS)


def test_angular_z_is_the_steering_angle_and_the_wheel_radius_is_unmultiplied():
    bot = Bot(wheel_radius_multiplier=2.0)
    bot.run(0.1, (0.5, 0.3))
    step = bot.steps[-1]
    assert step.steer_position == pytest.approx(0.3)
    assert step.wheel_velocity == pytest.approx(0.5 / RADIUS)  # not 0.5 / (2 * RADIUS)


def test_odometry_radius_follows_the_multiplier():
    bot = Bot(wheel_radius_multiplier=2.0)
    bot.run(1.0, (0.5, 0.0))
    assert bot.core.pose[0] == pytest.approx(2 * 0.5 * 0.99, abs=0.02)  # the first update commands, moves after


def test_timeout_brakes_and_straightens():
    bot = Bot(cmd_vel_timeout=0.5)
    bot.run(0.3, (0.5, 0.2))
    assert bot.steps[-1].wheel_velocity > 0 and bot.steps[-1].steer_position == pytest.approx(0.2)
    bot.run(0.5)
    assert bot.steps[-1].wheel_velocity == 0.0 and bot.steps[-1].steer_position == 0.0
    late = [s for s in bot.steps if s.wheel_velocity == 0.0]
    assert late  # it braked within the run, after 0.5 s of silence


def test_angular_limits_limit_the_steering_angle():
    bot = Bot(angular={"z": {"has_velocity_limits": True, "max_velocity": 0.25,
                             "has_acceleration_limits": True, "max_acceleration": 1.0}})
    bot.run(0.05, (0.1, 0.6))
    assert bot.steps[0].steer_position == pytest.approx(1.0 * DT)  # rate-limited from 0
    bot.run(1.0)
    assert bot.steps[-1].steer_position == pytest.approx(0.25)


def test_linear_limits():
    bot = Bot(linear={"x": {"has_velocity_limits": True, "max_velocity": 0.3,
                            "has_acceleration_limits": True, "max_acceleration": 0.5}})
    bot.run(0.1, (2.0, 0.0))
    assert bot.steps[0].wheel_velocity == pytest.approx(0.5 * DT / RADIUS)
    bot.run(2.0)
    assert bot.steps[-1].wheel_velocity == pytest.approx(0.3 / RADIUS)


def test_open_loop_integrates_the_steering_angle_as_a_yaw_rate():
    """upstream's updateOpenLoop(last0_cmd_.lin, last0_cmd_.ang): the steer command is taken as w."""
    bot = Bot(open_loop=True)
    bot.run(1.0, (0.2, 0.1))
    assert bot.core.velocity == pytest.approx((0.2, 0.1))
    assert bot.core.pose[2] == pytest.approx(0.1 * (1.0 - DT), abs=1e-9)


def test_nan_joint_skips_the_update():
    bot = Bot()
    bot.run(0.1, (0.1, 0.0))
    before = bot.core.pose
    step = bot.core.update(bot.t + DT, float("nan"), 0.0, DT)
    assert step.skipped and not step.publish_odom and bot.core.pose == before


def test_publish_rate_is_kept_on_whole_periods():
    bot = Bot()
    bot.run(1.0, (0.0, 0.0))
    assert sum(s.publish_odom for s in bot.steps) == 49  # 50 Hz over 1 s, the first at 0.03 s


def test_refusals():
    core = AckermannSteeringCore(ackermann_config({**BASE, "allow_multiple_cmd_vel_publishers": False}, NS),
                                 SEPARATION_H, RADIUS)
    assert "not running" in core.set_command(0.1, 0.0, 0.0)
    core.starting(0.0)
    assert "Only 1 publisher" in core.set_command(0.1, 0.0, 0.0, num_publishers=2)
    assert "non-finite" in core.set_command(float("nan"), 0.0, 0.0)


def test_bicycle_odometry_closes_a_circle():
    """The wheel travelling 2·pi·R at steering angle atan(L/R) returns to the start, heading 2·pi."""
    odom = AckermannOdometry(0.5, 0.1, window=10)
    odom.init(0.0)
    radius = 2.0
    steer = math.atan(0.5 / radius)
    angle = 2 * math.pi * radius / 0.1
    for i in range(1, 1001):
        odom.update(angle * i / 1000, steer, i * 0.01)
    assert odom.x == pytest.approx(0.0, abs=1e-9) and odom.y == pytest.approx(0.0, abs=1e-9)
    assert odom.heading == pytest.approx(2 * math.pi)
    assert turning_radius(0.5, steer) == pytest.approx(radius)


def test_config_defaults_unknown_keys_and_errors():
    cfg = ackermann_config({"type": BASE["type"], "publish_cmd": True, "odom_frame_id": "/odom",
                            "estimate_velocity_from_position": True}, NS)
    assert (cfg.rear_wheel, cfg.front_steer, cfg.publish_rate, cfg.cmd_vel_timeout) == (
        "rear_wheel_joint", "front_steer_joint", 50.0, 0.5)
    assert cfg.velocity_rolling_window_size == 10 and cfg.enable_odom_tf and cfg.odom_frame_id == "odom"
    assert set(cfg.unknown_keys) == {f"{NS}/publish_cmd", f"{NS}/estimate_velocity_from_position"}
    assert any("covariance" in w for w in cfg.warnings) and any("leading slash" in w for w in cfg.warnings)
    with pytest.raises(ConfigError, match=f"{NS}/wheel_radius"):
        ackermann_config({**BASE, "wheel_radius": -1}, NS)
    with pytest.raises(ConfigError, match=f"{NS}/front_steer"):
        ackermann_config({**BASE, "front_steer": 3}, NS)
    with pytest.raises(ConfigError, match="wheel_separation_h"):
        AckermannSteeringCore(ackermann_config(BASE, NS), None, RADIUS)
