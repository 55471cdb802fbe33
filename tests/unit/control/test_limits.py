"""limits.py: clamp, scale_to_limit (keeps the wheel ratio), ramp, SpeedLimiter (diff_drive_controller's)."""
import pytest

from diffbot_sim.control.limits import SpeedLimiter, clamp, ramp, scale_to_limit


@pytest.mark.parametrize("value, limit, expected", [
    (5.0, 2.0, 2.0), (-5.0, 2.0, -2.0), (1.5, 2.0, 1.5), (-1.5, 2.0, -1.5), (2.0, 2.0, 2.0),
    (7.0, 0.0, 7.0), (-7.0, -1.0, -7.0), (1e308, 3.0, 3.0),
])
def test_clamp(value, limit, expected):
    assert clamp(value, limit) == expected


def test_scale_to_limit_keeps_ratio():
    left, right = scale_to_limit(10.0, 30.0, 20.0)
    assert right == pytest.approx(20.0)
    assert left == pytest.approx(20.0 / 3.0)
    assert right / left == pytest.approx(3.0)


def test_scale_to_limit_negative_peak_and_signs():
    left, right = scale_to_limit(-40.0, 10.0, 20.0)
    assert left == pytest.approx(-20.0) and right == pytest.approx(5.0)
    assert left / right == pytest.approx(-4.0)


def test_scale_to_limit_differs_from_clamping_each():
    # clamping each wheel would give (20, 20): a straight line instead of the commanded arc
    assert scale_to_limit(25.0, 50.0, 20.0) != (clamp(25.0, 20.0), clamp(50.0, 20.0))


@pytest.mark.parametrize("left, right, limit", [(3.0, -4.0, 5.0), (5.0, 5.0, 5.0), (9.0, 9.0, 0.0),
                                                (9.0, 1.0, -1.0)])
def test_scale_to_limit_within_or_unlimited_unchanged(left, right, limit):
    assert scale_to_limit(left, right, limit) == (left, right)


def test_ramp_up_and_down():
    assert ramp(0.0, 10.0, 2.0) == 2.0
    assert ramp(10.0, 0.0, 2.0) == 8.0
    assert ramp(-1.0, -10.0, 0.5) == -1.5


def test_ramp_does_not_overshoot():
    assert ramp(1.0, 1.3, 2.0) == pytest.approx(1.3)
    assert ramp(1.0, 0.8, 2.0) == pytest.approx(0.8)


@pytest.mark.parametrize("max_delta", [0.0, -1.0])
def test_ramp_without_limit_jumps(max_delta):
    assert ramp(3.0, -7.0, max_delta) == -7.0


def test_ramp_converges_in_expected_steps():
    value, steps = 0.0, 0
    while value != 5.0:
        value = ramp(value, 5.0, 0.5)
        steps += 1
        assert steps <= 10
    assert steps == 10


# -- SpeedLimiter ---------------------------------------------------------------------------------------

DT = 0.01


def test_speed_limiter_off_by_default_passes_through():
    limiter = SpeedLimiter(max_velocity=1.0, max_acceleration=1.0, max_jerk=1.0)
    assert limiter.limit(10.0, 0.0, 0.0, DT) == 10.0
    assert limiter.limit(-3.5, 2.0, 7.0, DT) == -3.5


def test_speed_limiter_min_defaults_to_minus_max():
    limiter = SpeedLimiter(max_velocity=1.5, max_acceleration=2.0, max_jerk=3.0)
    assert (limiter.min_velocity, limiter.min_acceleration, limiter.min_jerk) == (-1.5, -2.0, -3.0)
    limiter = SpeedLimiter(min_velocity=-0.2, max_velocity=1.0)
    assert limiter.min_velocity == -0.2


def test_speed_limiter_velocity_is_asymmetric_clamp():
    limiter = SpeedLimiter(has_velocity_limits=True, min_velocity=-0.5, max_velocity=1.0)
    assert limiter.limit(10.0, 0.0, 0.0, DT) == 1.0
    assert limiter.limit(-10.0, 0.0, 0.0, DT) == -0.5
    assert limiter.limit(0.3, 0.0, 0.0, DT) == 0.3


def test_speed_limiter_acceleration_limits_the_step_from_v0():
    limiter = SpeedLimiter(has_acceleration_limits=True, min_acceleration=-0.5, max_acceleration=1.0)
    assert limiter.limit(10.0, 0.2, 0.0, DT) == pytest.approx(0.2 + 1.0 * DT)
    assert limiter.limit(-10.0, 0.2, 0.0, DT) == pytest.approx(0.2 - 0.5 * DT)
    assert limiter.limit(0.205, 0.2, 0.0, DT) == 0.205  # within the bound: untouched
    assert limiter.limit(0.2, 0.2, 0.7, DT) == 0.2  # v1 plays no part


def test_speed_limiter_jerk_uses_previous_step_and_twice_dt_squared():
    limiter = SpeedLimiter(has_jerk_limits=True, max_jerk=5.0)
    bound = 5.0 * 2.0 * DT * DT  # upstream's bound on the change of the step
    # from rest the step may grow by the bound alone
    assert limiter.limit(10.0, 0.0, 0.0, DT) == pytest.approx(bound)
    # after a step of 0.01 (v1 -> v0), the next step may be 0.01 + bound
    assert limiter.limit(10.0, 0.01, 0.0, DT) == pytest.approx(0.01 + 0.01 + bound)
    # stopping abruptly after that step: the step may only shrink by the bound
    assert limiter.limit(0.0, 0.01, 0.0, DT) == pytest.approx(0.01 + 0.01 - bound)
    # a request inside the bound is left alone
    assert limiter.limit(0.0205, 0.01, 0.0, DT) == pytest.approx(0.0205)


def test_speed_limiter_order_jerk_then_acceleration_then_velocity():
    limiter = SpeedLimiter(True, True, True, max_velocity=0.015, max_acceleration=1.0, max_jerk=5.0)
    # jerk allows 0.01 + 0.01 + 0.001; acceleration cuts the step to 0.01; velocity cuts to 0.015
    assert limiter.limit_jerk(10.0, 0.01, 0.0, DT) == pytest.approx(0.021)
    assert limiter.limit_acceleration(0.021, 0.01, DT) == pytest.approx(0.02)
    assert limiter.limit(10.0, 0.01, 0.0, DT) == pytest.approx(0.015)


def test_speed_limiter_ramp_from_rest_matches_hand_computation():
    # diffbot_limits.yaml's linear/x: jerk 5 builds the step by 0.001 per cycle until acceleration (1.0)
    # caps it at 0.01: after 10 cycles 0.001 + ... + 0.010 = 0.055, then +0.01 per cycle up to 1.0
    limiter = SpeedLimiter(True, True, True, min_velocity=-0.5, max_velocity=1.0, min_acceleration=-0.5,
                           max_acceleration=1.0, max_jerk=5.0)
    v0 = v1 = 0.0
    history = []
    for _ in range(200):
        v = limiter.limit(10.0, v0, v1, DT)
        v1, v0 = v0, v
        history.append(v)
    assert history[9] == pytest.approx(0.055)
    assert history[49] == pytest.approx(0.455)
    assert history[-1] == 1.0
    steps = [b - a for a, b in zip([0.0] + history, history)]
    assert max(steps) <= 0.01 + 1e-12
