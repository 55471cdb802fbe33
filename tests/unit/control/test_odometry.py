"""odometry.py: wheel-encoder odometry with exact arc integration."""
import math

import pytest

from diffbot_sim.control.odometry import EncoderOdometry, integrate_exact
from diffbot_sim.errors import ConfigError

R, S = 0.032, 0.2  # the seed's wheel radius and separation


def drive(odom, wheel_left, wheel_right, duration, steps, start=0.0, t0=0.0):
    """Turn the wheels at constant joint rates [rad/s] for ``duration``, feeding ``steps`` updates."""
    for i in range(1, steps + 1):
        t = duration * i / steps
        odom.update(start + wheel_left * t, start + wheel_right * t, t0 + t)


def fresh(x=0.0, y=0.0, yaw=0.0):
    odom = EncoderOdometry(R, S)
    odom.reset(0.0, 0.0, 0.0, x, y, yaw)
    return odom


def test_first_update_only_initialises():
    odom = EncoderOdometry(R, S)
    assert odom.update(5.0, 7.0, 1.0) is False
    assert (odom.x, odom.y, odom.yaw) == (0.0, 0.0, 0.0)
    assert odom.update(5.0 + 1.0 / R, 7.0 + 1.0 / R, 2.0) is True  # 1 m each wheel: straight
    assert odom.x == pytest.approx(1.0) and odom.y == pytest.approx(0.0, abs=1e-12)


def test_straight_line():
    odom = fresh()
    drive(odom, 0.5 / R, 0.5 / R, duration=2.0, steps=20)  # 0.5 m/s for 2 s
    assert odom.x == pytest.approx(1.0)
    assert odom.y == pytest.approx(0.0, abs=1e-12)
    assert odom.yaw == pytest.approx(0.0, abs=1e-12)
    assert odom.linear == pytest.approx(0.5)
    assert odom.angular == pytest.approx(0.0, abs=1e-12)


def test_straight_line_along_heading():
    odom = fresh(x=1.0, y=2.0, yaw=math.pi / 3)
    drive(odom, 0.5 / R, 0.5 / R, duration=1.0, steps=7)
    assert odom.x == pytest.approx(1.0 + 0.5 * math.cos(math.pi / 3))
    assert odom.y == pytest.approx(2.0 + 0.5 * math.sin(math.pi / 3))


def test_full_circle_returns_to_start():
    radius, w = 0.5, 0.8  # arc of radius 0.5 m, turning left at 0.8 rad/s
    left = w * (radius - S / 2) / R
    right = w * (radius + S / 2) / R
    period = 2 * math.pi / w
    odom = fresh()
    drive(odom, left, right, duration=period / 4, steps=13)
    # a quarter of a left circle from the origin facing +x ends at (R, R) facing +y
    assert odom.x == pytest.approx(radius, abs=1e-9)
    assert odom.y == pytest.approx(radius, abs=1e-9)
    assert odom.yaw == pytest.approx(math.pi / 2)
    odom = fresh()
    drive(odom, left, right, duration=period, steps=37)
    assert odom.x == pytest.approx(0.0, abs=1e-9)
    assert odom.y == pytest.approx(0.0, abs=1e-9)
    assert odom.yaw == pytest.approx(2 * math.pi)
    assert odom.linear == pytest.approx(w * radius)
    assert odom.angular == pytest.approx(w)


def test_in_place_turn_two_pi():
    w = 1.0
    odom = fresh()
    drive(odom, -w * S / 2 / R, w * S / 2 / R, duration=2 * math.pi / w, steps=50)
    assert odom.yaw == pytest.approx(2 * math.pi)
    assert odom.x == pytest.approx(0.0, abs=1e-12) and odom.y == pytest.approx(0.0, abs=1e-12)
    assert odom.linear == pytest.approx(0.0, abs=1e-12)
    assert odom.angular == pytest.approx(w)


def test_in_place_turn_right_is_negative_yaw():
    odom = fresh()
    drive(odom, 2.0, -2.0, duration=1.0, steps=10)
    assert odom.yaw == pytest.approx(-2 * 2.0 * R / S)


def test_reverse_gives_negative_linear_velocity():
    odom = fresh()
    drive(odom, -0.2 / R, -0.2 / R, duration=1.0, steps=10)
    assert odom.linear == pytest.approx(-0.2)
    assert odom.x == pytest.approx(-0.2)


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -float("inf")])
def test_non_finite_input_freezes(bad):
    odom = fresh()
    odom.update(1.0, 1.0, 0.1)
    before = (odom.x, odom.y, odom.yaw, odom.linear, odom.angular)
    assert odom.update(bad, 2.0, 0.2) is False
    assert odom.update(2.0, bad, 0.3) is False
    assert (odom.x, odom.y, odom.yaw, odom.linear, odom.angular) == before
    assert all(math.isfinite(v) for v in before)
    # the next good reading integrates from the last good one: nothing lost, nothing poisoned
    assert odom.update(2.0, 2.0, 0.4) is True
    assert odom.x == pytest.approx(2.0 * R)
    assert odom.linear == pytest.approx(R / 0.3)


def test_tiny_dt_skipped_and_not_lost():
    odom = fresh()
    assert odom.update(1.0, 1.0, 0.00005) is False
    assert (odom.x, odom.linear) == (0.0, 0.0)
    assert odom.update(1.0, 1.0, 0.0) is False  # no time at all
    assert odom.update(2.0, 2.0, 0.01) is True  # measured from the reset at t=0
    assert odom.x == pytest.approx(2.0 * R)
    assert odom.linear == pytest.approx(2.0 * R / 0.01)


def test_reset_restarts_from_pose():
    odom = fresh()
    drive(odom, 3.0, 1.0, duration=1.0, steps=5)
    odom.reset(10.0, 20.0, 5.0, x=1.0, y=-1.0, yaw=0.5)
    assert (odom.x, odom.y, odom.yaw, odom.linear, odom.angular) == (1.0, -1.0, 0.5, 0.0, 0.0)
    odom.update(10.0 + 1.0 / R, 20.0 + 1.0 / R, 6.0)
    assert odom.x == pytest.approx(1.0 + math.cos(0.5))
    assert odom.y == pytest.approx(-1.0 + math.sin(0.5))


def _euler(x, y, yaw, distance, dyaw, substeps):
    for _ in range(substeps):
        x += distance / substeps * math.cos(yaw)
        y += distance / substeps * math.sin(yaw)
        yaw += dyaw / substeps
    return x, y, yaw


@pytest.mark.parametrize("distance, dyaw", [(1.0, 1.2), (0.7, -2.5), (-0.4, 0.9), (0.3, 1e-7), (0.0, 3.0)])
def test_exact_matches_small_step_integration(distance, dyaw):
    exact = integrate_exact(0.3, -0.2, 0.4, distance, dyaw)
    numeric = _euler(0.3, -0.2, 0.4, distance, dyaw, 20000)
    assert exact == pytest.approx(numeric, abs=1e-4)


def test_exact_is_step_size_independent():
    # one big step vs many small ones of the same arc land on the same pose
    one = integrate_exact(0.0, 0.0, 0.0, 1.5, 2.0)
    x, y, yaw = 0.0, 0.0, 0.0
    for _ in range(7):
        x, y, yaw = integrate_exact(x, y, yaw, 1.5 / 7, 2.0 / 7)
    assert (x, y, yaw) == pytest.approx(one, abs=1e-12)


def test_exact_straight_branch_continuous_with_arc_branch():
    near_straight = integrate_exact(0.0, 0.0, 0.2, 1.0, 1.0001e-6)  # arc formula
    straight = integrate_exact(0.0, 0.0, 0.2, 1.0, 0.9999e-6)  # midpoint formula
    assert near_straight == pytest.approx(straight, abs=1e-8)


# -- diff_drive_controller's additions: rolling window, per-side radius, open loop, restart ---------------

def test_default_window_is_one_and_radius_is_shared():
    odom = EncoderOdometry(R, S)
    assert odom.velocity_window == 1
    assert odom.radius == odom.left_radius == odom.right_radius == R
    odom.radius = 0.05  # the old single-radius attribute still sets both sides
    assert (odom.left_radius, odom.right_radius) == (0.05, 0.05)


def test_rolling_window_averages_the_last_estimates():
    odom = EncoderOdometry(R, S, velocity_window=3)
    odom.reset(0.0, 0.0, 0.0)
    angle, t = 0.0, 0.0
    for speed in (1.0, 1.0, 1.0, 4.0, 4.0, 4.0):  # wheel joint rate [rad/s], 0.1 s per update
        angle += speed * 0.1
        t += 0.1
        odom.update(angle, angle, t)
        if t == pytest.approx(0.4):
            assert odom.linear == pytest.approx((1.0 + 1.0 + 4.0) / 3 * R)
    assert odom.linear == pytest.approx(4.0 * R)  # the window now holds only the new speed
    assert odom.x == pytest.approx(15.0 * 0.1 * R)  # the pose is not averaged


def test_rolling_window_mean_over_fewer_samples_at_start():
    odom = EncoderOdometry(R, S, velocity_window=10)
    odom.reset(0.0, 0.0, 0.0)
    odom.update(1.0, 1.0, 0.1)
    assert odom.linear == pytest.approx(10.0 * R)  # one sample: its own value, not a tenth of it


@pytest.mark.parametrize("bad", [0, -1, 2.5, True, "10"])
def test_rolling_window_size_validated(bad):
    with pytest.raises(ConfigError, match="velocity_rolling_window_size"):
        EncoderOdometry(R, S, velocity_window=bad)


def test_per_side_radius_scales_each_wheel():
    odom = EncoderOdometry(R, S, right_wheel_radius=2 * R)
    odom.reset(0.0, 0.0, 0.0)
    odom.update(1.0, 1.0, 1.0)  # same angle, but the right wheel rolls twice as far: a left turn
    assert odom.yaw == pytest.approx((2 * R - R) / S)
    assert odom.linear == pytest.approx(1.5 * R)
    odom.set_wheel_params(2 * S, R)
    assert (odom.separation, odom.left_radius, odom.right_radius) == (2 * S, R, R)


def test_open_loop_integrates_commands():
    odom = EncoderOdometry(R, S)
    assert odom.update_open_loop(0.5, 0.0, 1.0) is False  # first call only sets the time
    assert odom.update_open_loop(0.5, 0.0, 3.0) is True
    assert (odom.x, odom.y) == pytest.approx((1.0, 0.0))
    assert (odom.linear, odom.angular) == (0.5, 0.0)
    odom.update_open_loop(0.5, math.pi / 2, 4.0)  # a quarter circle of radius 1/pi
    assert odom.yaw == pytest.approx(math.pi / 2)
    assert odom.x == pytest.approx(1.0 + 1.0 / math.pi)
    assert odom.y == pytest.approx(1.0 / math.pi)
    assert odom.update_open_loop(float("nan"), 0.0, 5.0) is False
    assert math.isfinite(odom.x) and odom.linear == 0.5


def test_restart_keeps_pose_and_angles_but_clears_window_and_time():
    odom = EncoderOdometry(R, S, velocity_window=5)
    odom.reset(0.0, 0.0, 0.0)
    odom.update(10.0, 10.0, 1.0)
    odom.restart(5.0)
    assert odom.x == pytest.approx(10.0 * R)
    assert (odom.linear, odom.angular) == (0.0, 0.0)
    odom.update(11.0, 11.0, 5.5)  # dt measured from the restart, increment from the old angles
    assert odom.x == pytest.approx(11.0 * R)
    assert odom.linear == pytest.approx(R / 0.5)


def test_restart_before_any_reading_sets_open_loop_time():
    odom = EncoderOdometry(R, S)
    odom.restart(2.0)
    assert odom.update_open_loop(1.0, 0.0, 2.5) is True
    assert odom.x == pytest.approx(0.5)
    closed = EncoderOdometry(R, S)
    closed.restart(2.0)
    assert closed.update(7.0, 7.0, 2.5) is False  # the first reading is still the starting point
    assert closed.x == 0.0
