"""diff_drive_controller: DiffDriveController's per-update logic, checked the way its rostests check it
(its parameters' checking: test_diff_drive_config.py).

The harness mirrors ros_controllers' test robot (diffbot.h / diffbot.cpp): a fixed dt of 0.01 s, wheels
whose velocity is exactly the last command (position += velocity * dt in read(), then velocity = command),
and odom "messages" taken whenever the controller says to publish. Tolerances are the rostests' own.
"""
import math

import pytest

from diffbot_sim.control.diff_drive_config import diff_drive_controller_config
from diffbot_sim.control.diff_drive_controller import DiffDriveControllerCore, DiffDriveControllerStep
from diffbot_sim.errors import ConfigError

NS = "/diffbot_controller"
DT = 0.01
SEPARATION, RADIUS = 1.0, 0.11  # any positive geometry; the fake robot's wheels follow commands exactly

# test/test_common.h tolerances
EPS = 0.01
POSITION_TOLERANCE = 0.01
VELOCITY_TOLERANCE = 0.02
JERK_LINEAR_VELOCITY_TOLERANCE = 0.10
ORIENTATION_TOLERANCE = 0.03

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

# test/diffbot_limits.yaml
LIMITS = {
    "linear": {"x": {"has_velocity_limits": True, "min_velocity": -0.5, "max_velocity": 1.0,
                     "has_acceleration_limits": True, "min_acceleration": -0.5, "max_acceleration": 1.0,
                     "has_jerk_limits": True, "max_jerk": 5.0}},
    "angular": {"z": {"has_velocity_limits": True, "max_velocity": 2.0,
                      "has_acceleration_limits": True, "max_acceleration": 2.0,
                      "has_jerk_limits": True, "max_jerk": 10.0}},
}

SKID_STEER = {"left_wheel": ["wheel_0_joint", "wheel_1_joint", "wheel_2_joint"],
              "right_wheel": ["wheel_3_joint", "wheel_4_joint", "wheel_5_joint"]}

# one entry per diff_drive_test-based rostest: the YAML it loads on top of the base config
VARIANTS = {
    "diff_drive_controller": {},
    "multipliers": {"wheel_separation_multiplier": 2.3, "wheel_radius_multiplier": 1.4},
    "left_right_multipliers": {"wheel_separation_multiplier": 2.3, "left_wheel_radius_multiplier": 1.4,
                               "right_wheel_radius_multiplier": 1.4},
    "open_loop": {"open_loop": True},
    "radius_param": {"wheel_radius": 0.11},
    "separation_param": {"wheel_separation": 1.0},
    "skid_steer": SKID_STEER,
}


def params(**overrides):
    merged = dict(BASE)
    merged.update(overrides)
    return merged


class FakeDiffbot:
    """ros_controllers' test/diffbot.h plus the controller manager loop of test/diffbot.cpp, minus ROS."""

    def __init__(self, config_params, true_radius=RADIUS):
        self.config = diff_drive_controller_config(config_params, NS)
        self.core = DiffDriveControllerCore(self.config, wheel_separation=SEPARATION, wheel_radius=RADIUS)
        self.true_radius = true_radius
        n = len(self.config.left_wheels)
        self.pos = [0.0] * (2 * n)
        self.vel = [0.0] * (2 * n)
        self.cmd = [0.0] * (2 * n)
        self.running = True  # the std_srvs start/stop services
        self.time = 0.0
        self.odom = None  # the last published odom: dict of stamp, x, y, yaw, linear, angular
        self.cmd_vel_out = []
        self.core.starting(self.time)

    def publish(self, linear=0.0, angular=0.0, publishers=1):
        return self.core.set_command(linear, angular, self.time, publishers)

    def cycle(self):
        n = len(self.config.left_wheels)
        if self.running:
            for i in range(2 * n):
                self.pos[i] += self.vel[i] * DT
                self.vel[i] = self.cmd[i]
        else:
            self.pos = [math.nan] * (2 * n)
            self.vel = [math.nan] * (2 * n)
        step = self.core.update(self.time, self.pos[:n], self.pos[n:])
        assert isinstance(step, DiffDriveControllerStep)
        self.cmd = [step.left] * n + [step.right] * n
        if step.publish_odom:
            x, y, yaw = self.core.pose
            linear, angular = self.core.velocity
            self.odom = dict(stamp=self.time, x=x, y=y, yaw=yaw, linear=linear, angular=angular)
        if not step.skipped and self.config.publish_cmd:
            self.cmd_vel_out.append(self.core.last_command)
        self.time = round(self.time + DT, 9)
        return step

    def run(self, seconds):
        for _ in range(int(round(seconds / DT))):
            self.cycle()

    def true_distance(self):
        """How far the wheels really rolled (mean of all joints, true radius) [m]."""
        return sum(self.pos) / len(self.pos) * self.true_radius


# -- the diff_drive_test rostests, for every YAML variant --------------------------------------------------

@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_forward(variant):
    bot = FakeDiffbot(params(**VARIANTS[variant]))
    bot.publish(0.0, 0.0)
    bot.run(2.0)
    old = bot.odom
    bot.publish(0.1, 0.0)
    bot.run(10.0)
    new = bot.odom
    distance = math.hypot(new["x"] - old["x"], new["y"] - old["y"])
    assert distance == pytest.approx(0.1 * (new["stamp"] - old["stamp"]), abs=POSITION_TOLERANCE)
    assert abs(new["yaw"] - old["yaw"]) < EPS
    assert new["linear"] == pytest.approx(0.1, abs=EPS)
    assert abs(new["angular"]) < EPS


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_turn(variant):
    bot = FakeDiffbot(params(**VARIANTS[variant]))
    bot.publish(0.0, 0.0)
    bot.run(2.0)
    old = bot.odom
    bot.publish(0.0, math.pi / 10.0)
    bot.run(10.0)
    new = bot.odom
    assert abs(new["x"] - old["x"]) < POSITION_TOLERANCE
    assert abs(new["y"] - old["y"]) < POSITION_TOLERANCE
    dyaw = new["yaw"] - old["yaw"]
    assert dyaw == pytest.approx(math.pi / 10.0 * (new["stamp"] - old["stamp"]), abs=ORIENTATION_TOLERANCE)
    assert abs(new["linear"]) < EPS
    assert new["angular"] == pytest.approx(math.pi / 10.0, abs=EPS)


def test_wheel_commands_use_multiplied_geometry():
    config = diff_drive_controller_config(params(wheel_separation_multiplier=2.3, left_wheel_radius_multiplier=1.4,
                               right_wheel_radius_multiplier=0.7), NS)
    core = DiffDriveControllerCore(config, wheel_separation=SEPARATION, wheel_radius=RADIUS)
    core.starting(0.0)
    core.set_command(0.2, 0.5, 0.0)
    step = core.update(0.01, [0.0], [0.0])
    ws = 2.3 * SEPARATION
    assert step.left == pytest.approx((0.2 - 0.5 * ws / 2.0) / (1.4 * RADIUS))
    assert step.right == pytest.approx((0.2 + 0.5 * ws / 2.0) / (0.7 * RADIUS))
    assert core.joint_commands() == {"wheel_0_joint": step.left, "wheel_1_joint": step.right}


@pytest.mark.parametrize("multipliers", [{"wheel_radius_multiplier": 1.4},
                                         {"wheel_separation_multiplier": 2.3, "wheel_radius_multiplier": 0.8}])
def test_multipliers_consistent_between_commands_and_odometry(multipliers):
    # the multiplier is "wrong" for the real wheels: they roll 1/1.4 of the way, yet odometry, made with the
    # same multiplier, reports exactly what was commanded (upstream's diff_drive_multipliers.test passes so)
    bot = FakeDiffbot(params(**multipliers))
    bot.publish(0.1, 0.0)
    bot.run(10.0)
    x = bot.core.pose[0]
    factor = multipliers["wheel_radius_multiplier"]
    assert x == pytest.approx(0.1 * 10.0, abs=POSITION_TOLERANCE)
    assert bot.true_distance() == pytest.approx(x / factor, rel=1e-9)


# -- diff_drive_limits_test (diffbot_limits.yaml) ------------------------------------------------------------

def limits_bot():
    bot = FakeDiffbot(params(**LIMITS))
    bot.publish(0.0, 0.0)
    bot.run(2.0)
    return bot, bot.odom


def test_linear_jerk_limits():
    bot, old = limits_bot()
    bot.publish(10.0, 0.0)
    bot.run(0.5)
    new = bot.odom
    assert new["linear"] == pytest.approx(0.37, abs=JERK_LINEAR_VELOCITY_TOLERANCE)
    assert abs(new["angular"] - old["angular"]) < EPS


def test_linear_acceleration_limits():
    bot, old = limits_bot()
    bot.publish(10.0, 0.0)
    bot.run(0.5)
    new = bot.odom
    assert abs(new["linear"] - old["linear"]) < 0.5 + VELOCITY_TOLERANCE
    assert abs(new["angular"] - old["angular"]) < EPS


def test_linear_velocity_limits():
    bot, old = limits_bot()
    bot.publish(10.0, 0.0)
    bot.run(5.0)
    new = bot.odom
    assert abs(new["linear"] - old["linear"]) < 1.0 + VELOCITY_TOLERANCE
    assert new["linear"] == pytest.approx(1.0, abs=EPS)  # and it does reach the limit
    assert abs(new["angular"] - old["angular"]) < EPS


def test_linear_reverse_uses_min_velocity():
    bot, _ = limits_bot()
    bot.publish(-10.0, 0.0)
    bot.run(5.0)
    assert bot.odom["linear"] == pytest.approx(-0.5, abs=EPS)


def test_angular_acceleration_limits():
    bot, old = limits_bot()
    bot.publish(0.0, 10.0)
    bot.run(0.5)
    new = bot.odom
    assert abs(new["angular"] - old["angular"]) < 1.0 + VELOCITY_TOLERANCE
    assert abs(new["linear"] - old["linear"]) < EPS


def test_angular_velocity_limits():
    bot, old = limits_bot()
    bot.publish(0.0, 10.0)
    bot.run(5.0)
    new = bot.odom
    assert abs(new["angular"] - old["angular"]) < 2.0 + VELOCITY_TOLERANCE
    assert new["angular"] == pytest.approx(2.0, abs=EPS)
    assert abs(new["linear"] - old["linear"]) < EPS


# -- diff_drive_timeout_test ---------------------------------------------------------------------------

def test_timeout_brakes():
    bot = FakeDiffbot(params(cmd_vel_timeout=0.5))
    bot.publish(0.0, 0.0)
    bot.run(0.1)
    old = bot.odom
    bot.publish(1.0, 0.0)
    bot.run(3.0)
    assert abs(bot.odom["x"] - old["x"]) < 0.8
    assert bot.odom["x"] - old["x"] == pytest.approx(0.5, abs=0.05)  # it did drive for the 0.5 s
    assert bot.core.wheel_commands == (0.0, 0.0)
    assert bot.core.last_command == (0.0, 0.0)


def test_no_command_yet_means_standstill():
    bot = FakeDiffbot(params())
    bot.run(1.0)
    assert bot.core.pose == (0.0, 0.0, 0.0)


def test_infinite_timeout_holds_the_command():
    bot = FakeDiffbot(params(cmd_vel_timeout=float("inf")))
    bot.publish(0.2, 0.0)
    bot.run(100.0)
    assert bot.core.wheel_commands[0] == pytest.approx(0.2 / RADIUS)


# -- diff_drive_nan_test (publish_cmd true) ------------------------------------------------------------------

def finite_odom(odom):
    return all(math.isfinite(odom[key]) for key in ("x", "y", "yaw", "linear", "angular"))


def test_nan_wheel_positions_freeze_odometry():
    bot = FakeDiffbot(params(publish_cmd=True))
    bot.publish(0.0, 0.0)
    bot.run(2.0)
    bot.publish(0.1, 0.0)
    bot.run(2.0)
    frozen = bot.core.pose
    commands = bot.core.wheel_commands
    bot.running = False  # the stop service: positions become NaN
    published = len(bot.cmd_vel_out)
    step = bot.cycle()
    assert step.skipped and not step.publish_odom
    assert (step.left, step.right) == commands  # the wheels keep their commands, as upstream's early return
    bot.run(2.0)
    assert finite_odom(bot.odom)
    assert bot.core.pose == frozen
    assert len(bot.cmd_vel_out) == published  # cmd_vel_out is not published either
    bot.running = True  # start service; the fake robot's positions stay NaN, as in upstream's
    bot.run(2.0)
    assert finite_odom(bot.odom)
    assert all(math.isfinite(value) for value in bot.core.pose + bot.core.velocity)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_commands_ignored(bad):
    bot = FakeDiffbot(params(publish_cmd=True))
    bot.publish(0.0, 0.0)
    bot.run(0.1)
    for _ in range(10):
        assert bot.publish(bad, 0.0) == "Received NaN in velocity command. Ignoring."
        bot.run(0.1)
        assert all(math.isfinite(v) for v in bot.cmd_vel_out[-1])
    for _ in range(10):
        assert bot.publish(0.0, bad) is not None
        bot.run(0.1)
        assert all(math.isfinite(v) for v in bot.cmd_vel_out[-1])
    assert bot.odom["linear"] == 0.0
    assert (bot.odom["x"], bot.odom["y"]) == (0.0, 0.0)
    assert bot.cmd_vel_out[-1][0] == 0.0


def test_nan_command_keeps_previous_command():
    bot = FakeDiffbot(params())
    bot.publish(0.3, 0.0)
    bot.run(0.1)
    bot.publish(math.nan, 1.0)
    bot.run(0.1)
    assert bot.core.last_command == (0.3, 0.0)


def test_cmd_vel_out_is_the_limited_command():
    bot = FakeDiffbot(params(publish_cmd=True, **LIMITS))
    bot.publish(10.0, 0.0)
    bot.run(0.1)
    assert 0.0 < bot.cmd_vel_out[-1][0] < 0.1
    assert bot.cmd_vel_out[-1] == bot.core.last_command
    assert len(bot.cmd_vel_out) == 10  # every update, not at publish_rate


# -- diff_drive_multiple_cmd_vel_publishers_test --------------------------------------------------------

def test_multiple_publishers_brake_when_disallowed():
    bot = FakeDiffbot(params(allow_multiple_cmd_vel_publishers=False))
    bot.run(0.1)
    old = bot.odom
    for _ in range(2):  # two `rostopic pub -r 2` publishers for 1 s
        reason = bot.publish(0.1, 0.1, publishers=2)
        assert "Going to brake" in reason
        assert bot.core.wheel_commands == (0.0, 0.0)
        bot.run(0.5)
    new = bot.odom
    assert math.hypot(new["x"] - old["x"], new["y"] - old["y"]) == pytest.approx(0.0, abs=POSITION_TOLERANCE)
    assert abs(new["yaw"] - old["yaw"]) < EPS


def test_multiple_publishers_allowed_by_default():
    bot = FakeDiffbot(params())
    assert bot.publish(0.1, 0.0, publishers=2) is None
    bot.run(1.0)
    assert bot.core.pose[0] > 0.05


# -- lifecycle and publish schedule -----------------------------------------------------------------------

def test_commands_refused_unless_running():
    core = DiffDriveControllerCore(diff_drive_controller_config(params(), NS), SEPARATION, RADIUS)
    assert "not running" in core.set_command(0.1, 0.0, 0.0)
    with pytest.raises(RuntimeError):
        core.update(0.0, [0.0], [0.0])
    core.starting(0.0)
    assert core.set_command(0.1, 0.0, 0.0) is None
    core.update(0.01, [0.0], [0.0])
    assert core.wheel_commands != (0.0, 0.0)
    core.stopping()
    assert core.wheel_commands == (0.0, 0.0)
    assert "not running" in core.set_command(0.1, 0.0, 0.02)


def test_restart_keeps_odometry_pose():
    bot = FakeDiffbot(params())
    bot.publish(0.5, 0.0)
    bot.run(1.0)
    bot.core.stopping(bot.time)
    pose = bot.core.pose
    bot.core.starting(bot.time)
    assert bot.core.wheel_commands == (0.0, 0.0)
    assert bot.core.pose == pose


def test_publish_schedule_follows_publish_rate():
    bot = FakeDiffbot(params(publish_rate=50))
    stamps = []
    for _ in range(100):
        now = bot.time
        if bot.cycle().publish_odom:
            stamps.append(now)
    # last + period < now: the first publication is strictly after one period, then every 0.02 s
    assert stamps[0] == pytest.approx(0.03)
    assert len(stamps) == 49
    assert all(b - a == pytest.approx(0.02) for a, b in zip(stamps, stamps[1:]))


def test_publish_rate_zero_never_publishes():
    bot = FakeDiffbot(params(publish_rate=0))
    assert not any(bot.cycle().publish_odom for _ in range(100))


def test_update_checks_joint_counts():
    bot = FakeDiffbot(params(**SKID_STEER))
    with pytest.raises(ValueError, match="left_positions"):
        bot.core.update(0.01, [0.0], [0.0, 0.0, 0.0])
    step = bot.core.update(0.01, [0.0] * 3, [0.0] * 3)
    assert not step.skipped
    assert len(bot.core.joint_commands()) == 6


def test_open_loop_ignores_wheel_positions():
    bot = FakeDiffbot(params(open_loop=True))
    bot.publish(0.2, 0.0)
    bot.run(1.0)
    step = bot.core.update(bot.time, None, None)  # no positions needed, NaN would not stop it either
    assert not step.skipped
    assert bot.core.pose[0] == pytest.approx(0.2, abs=0.01)
    assert bot.core.velocity == (0.2, 0.0)


# -- geometry: the parameters or the URDF ---------------------------------------------------------------

def test_geometry_parameter_wins_over_urdf():
    config = diff_drive_controller_config(params(wheel_separation=0.5), NS)
    core = DiffDriveControllerCore(config, wheel_separation=0.9, wheel_radius=0.1)
    assert (core.separation, core.left_radius, core.right_radius) == (0.5, 0.1, 0.1)


@pytest.mark.parametrize("separation, radius, culprit", [(None, 0.1, "wheel_separation"),
                                                         (0.5, None, "wheel_radius"),
                                                         (0.5, 0.0, "wheel_radius")])
def test_geometry_required_from_parameter_or_urdf(separation, radius, culprit):
    with pytest.raises(ConfigError) as info:
        DiffDriveControllerCore(diff_drive_controller_config(params(), NS), wheel_separation=separation,
                                wheel_radius=radius)
    assert info.value.name == f"{NS}/{culprit}"
