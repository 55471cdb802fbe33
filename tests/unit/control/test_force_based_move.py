"""The force-based move plugin family's maths (diffbot_sim.control.force_based_move): tags and defaults per
published copy, the P wrench, the command timeout, the stable gain, and the odometry's arc integration."""
import math

import pytest

from diffbot_sim.control import force_based_move as fbm
from diffbot_sim.errors import ConfigError

RIDGEBACK = fbm.VARIANTS["libridgeback_ros_force_based_move.so"]
HECTOR = fbm.VARIANTS["libgazebo_ros_force_based_move.so"]
NEXUS = fbm.VARIANTS["libnexus_ros_force_based_move.so"]


def read(tags, variant=RIDGEBACK):
    notes = []
    cfg, unknown = fbm.read_config(tags, variant, "/robot/gazebo/plugin", notes)
    return cfg, unknown, notes


# -- tags ----------------------------------------------------------------------------------------------------
def test_defaults_are_upstreams():
    cfg, unknown, _ = read([])
    assert (cfg.command_topic, cfg.odometry_topic, cfg.odometry_frame, cfg.robot_base_frame) == (
        "cmd_vel", "odom", "odom", "base_footprint")
    assert (cfg.odometry_rate, cfg.cmd_vel_timeout, cfg.publish_odometry_tf) == (20.0, 0.25, True)
    assert (cfg.x_gain, cfg.y_gain, cfg.yaw_gain) == (10000.0, 10000.0, 100.0)
    assert cfg.robot_namespace is None and unknown == []


def test_the_vendors_tags_are_read():
    cfg, unknown, _ = read([("robotNamespace", "/"), ("commandTopic", "base/cmd_vel"), ("odometryTopic", "odom2"),
                            ("odometryFrame", "odom_x"), ("odometryRate", "25.0"), ("robotBaseFrame", "base_link"),
                            ("cmdVelTimeOut", "0.5"), ("publishOdometryTf", "0"), ("yaw_velocity_p_gain", "500.0"),
                            ("x_velocity_p_gain", "2000"), ("y_velocity_p_gain", "3000")])
    assert cfg == fbm.ForceBasedMoveConfig("/", "base/cmd_vel", "odom2", "odom_x", "base_link", 25.0, 0.5, False,
                                           2000.0, 3000.0, 500.0)
    assert unknown == []


def test_hectors_copy_has_no_timeout_and_ignores_the_tag():
    cfg, unknown, _ = read([("cmdVelTimeOut", "0.5")], HECTOR)
    assert cfg.cmd_vel_timeout is None
    assert unknown == ["cmdVelTimeOut"]
    assert read([], NEXUS)[0].cmd_vel_timeout == 0.25


def test_unknown_and_loader_tags():
    _, unknown, _ = read([("alwaysOn", "true"), ("updateRate", "50"), ("cmdVelLinearMin", "0.01")])
    assert unknown == ["cmdVelLinearMin"]


def test_bad_values_name_the_tag():
    with pytest.raises(ConfigError, match="x_velocity_p_gain"):
        read([("x_velocity_p_gain", "fast")])
    with pytest.raises(ConfigError, match="publishOdometryTf"):
        read([("publishOdometryTf", "maybe")])
    with pytest.raises(ConfigError, match="commandTopic"):
        read([("commandTopic", " ")])


def test_a_number_with_trailing_text_is_read_as_gazebo_reads_it():
    cfg, _, notes = read([("odometryRate", "25 Hz")])
    assert cfg.odometry_rate == 25.0 and len(notes) == 1


# -- control -------------------------------------------------------------------------------------------------
def test_wrench_is_the_p_gains_on_the_velocity_error():
    fx, fy, torque = fbm.wrench((0.2, -0.1, 0.5), (0.15, 0.0), 0.7, (10000.0, 2000.0, 500.0))
    assert fx == pytest.approx(500.0)
    assert fy == pytest.approx(-200.0)
    assert torque == pytest.approx(-100.0)


def test_command_timeout_is_strict_and_optional():
    assert not fbm.command_expired(10.25, 10.0, 0.25)
    assert fbm.command_expired(10.2501, 10.0, 0.25)
    assert fbm.command_expired(0.0, None, 0.25)  # no command yet: zero
    assert not fbm.command_expired(1e6, 0.0, None)  # Hector's: the last command holds


def test_stable_gain_keeps_a_well_damped_gain():
    dt, mass = 1 / 240, 69.2
    assert fbm.stable_gain(10000.0, dt, mass) == (10000.0, True)  # a = 0.60
    assert fbm.stable_gain(500.0, dt, 6.5) == (500.0, True)


def test_stable_gain_replaces_a_stiff_one_by_the_exact_loop():
    dt, mass = 1 / 240, 2.0
    gain, kept = fbm.stable_gain(10000.0, dt, mass)  # a = 20.8: the explicit loop diverges
    assert not kept
    a = 10000.0 * dt / mass
    assert gain == pytest.approx(mass * (1.0 - math.exp(-a)) / dt)
    assert gain < mass / dt  # never past dead-beat: the error shrinks every step without changing sign
    velocity = 0.0
    for _ in range(3):
        velocity += gain * (0.2 - velocity) * dt / mass
        assert 0.0 < velocity <= 0.2


def test_stable_gain_leaves_what_it_cannot_judge():
    assert fbm.stable_gain(100.0, 1 / 240, 0.0) == (100.0, True)
    assert fbm.stable_gain(-100.0, 1 / 240, 1.0) == (-100.0, True)


# -- odometry ------------------------------------------------------------------------------------------------
def test_motion_straight_and_sideways():
    assert fbm.motion(0.2, 0.0, 0.0, 0.5) == pytest.approx((0.1, 0.0, 0.0))
    assert fbm.motion(0.0, 0.2, 5e-5, 0.5) == pytest.approx((0.0, 0.1, 0.0))  # |wz| < 1e-4: straight


def test_motion_in_place():
    assert fbm.motion(1e-5, -1e-5, 0.5, 0.04) == pytest.approx((0.0, 0.0, 0.02))


def test_motion_along_an_arc_turned_to_the_direction_of_travel():
    radius = 2.0 / math.pi  # a quarter circle of length 1
    assert fbm.motion(1.0, 0.0, math.pi / 2, 1.0) == pytest.approx((radius, radius, math.pi / 2))
    assert fbm.motion(0.0, 1.0, math.pi / 2, 1.0) == pytest.approx((-radius, radius, math.pi / 2))


def test_compose_moves_in_the_poses_own_frame_and_wraps():
    assert fbm.compose((1.0, 2.0, math.pi / 2), (0.5, 0.0, 0.0)) == pytest.approx((1.0, 2.5, math.pi / 2))
    assert fbm.compose((0.0, 0.0, 3.0), (0.0, 0.0, 0.5))[2] == pytest.approx(3.5 - 2 * math.pi)


def test_integrated_constant_twist_follows_the_circle():
    odometry = fbm.OdometryIntegrator(25.0)
    now = 0.0
    for _ in range(100):  # 4 s at 0.2 m/s and 0.5 rad/s
        now += 0.04
        odometry.advance(now, 0.2, 0.0, 0.5)
    radius, angle = 0.4, 2.0
    assert odometry.pose == pytest.approx((radius * math.sin(angle), radius * (1 - math.cos(angle)), angle))


def test_integrated_strafe_counts_the_lateral_velocity():
    odometry = fbm.OdometryIntegrator(25.0)
    odometry.advance(4.0, 0.0, 0.2, 0.0)
    assert odometry.pose == pytest.approx((0.0, 0.8, 0.0))


def test_odometry_is_due_strictly_after_a_period():
    odometry = fbm.OdometryIntegrator(20.0, now=1.0)
    assert not odometry.due(1.05)
    assert odometry.due(1.0501)
    assert odometry.next_due() == pytest.approx(1.05)
    odometry.advance(1.0501, 0.0, 0.0, 0.0)
    assert not odometry.due(1.1)
    odometry.restart(0.0)
    assert odometry.due(0.06) and odometry.pose == (0.0, 0.0, 0.0)


def test_no_odometry_at_a_rate_of_zero():
    odometry = fbm.OdometryIntegrator(0.0)
    assert not odometry.due(1e9)
    assert odometry.next_due() == math.inf


def test_covariance_switches_with_the_yaw_rate():
    still, turning = fbm.covariances(0.0), fbm.covariances(0.3)
    assert still[0] == (0.001, 0.001, 1e12, 1e12, 1e12, 0.01)
    assert still[1] == (0.001, 0.001, 0.001, 1e12, 1e12, 0.01)
    assert turning[0][5] == turning[1][5] == 100.0
