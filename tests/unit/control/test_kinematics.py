"""kinematics.py: diff-drive forward/inverse kinematics, REP 103 signs."""
import math

import pytest

from diffbot_sim.control.kinematics import body_velocity, wheel_speeds


@pytest.mark.parametrize("linear, angular, separation", [
    (0.3, 0.0, 0.2), (0.0, 1.5, 0.2), (-0.2, 0.7, 0.35), (1.1, -2.3, 0.5), (0.0, 0.0, 0.2), (-0.05, -0.4, 0.1),
])
def test_round_trip(linear, angular, separation):
    left, right = wheel_speeds(linear, angular, separation)
    v, w = body_velocity(left, right, separation)
    assert v == pytest.approx(linear, abs=1e-12)
    assert w == pytest.approx(angular, abs=1e-12)


def test_round_trip_from_wheels():
    v, w = body_velocity(0.13, -0.41, 0.27)
    assert wheel_speeds(v, w, 0.27) == pytest.approx((0.13, -0.41))


def test_straight_line_wheels_equal():
    assert wheel_speeds(0.4, 0.0, 0.2) == (0.4, 0.4)
    assert body_velocity(-0.25, -0.25, 0.2) == (-0.25, 0.0)


def test_in_place_turn_wheels_opposite():
    left, right = wheel_speeds(0.0, 2.0, 0.2)
    assert left == pytest.approx(-0.2) and right == pytest.approx(0.2)
    v, w = body_velocity(-0.1, 0.1, 0.2)
    assert v == 0.0 and w == pytest.approx(1.0)


def test_rep103_positive_angular_makes_right_wheel_faster():
    left, right = wheel_speeds(0.5, 1.0, 0.3)
    assert right > left
    assert right - left == pytest.approx(0.3)
    # and a faster right wheel means a left (positive, counter-clockwise) turn
    assert body_velocity(0.4, 0.6, 0.3)[1] > 0
    assert body_velocity(0.6, 0.4, 0.3)[1] < 0


def test_arc_radius():
    # an arc of radius R: v = w * R
    radius, angular, separation = 0.8, 0.5, 0.2
    left, right = wheel_speeds(angular * radius, angular, separation)
    assert left == pytest.approx(angular * (radius - separation / 2))
    assert right == pytest.approx(angular * (radius + separation / 2))
    assert math.isclose(right / left, (radius + 0.1) / (radius - 0.1))
