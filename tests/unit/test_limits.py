"""limits.py: clamp, scale_to_limit (keeps the wheel ratio), ramp."""
import pytest

from diffbot_sim.limits import clamp, ramp, scale_to_limit


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
