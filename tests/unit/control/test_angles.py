"""angles.py: the ros/angles C++ header's functions. Cases marked "upstream" are ros/angles master
(Noetic) ``angles/test/utest.cpp``; the others are hand-computed edge cases of the C++ recipe."""
import math

import pytest

from diffbot_sim.control.angles import (
    find_min_max_delta,
    normalize_angle,
    normalize_angle_positive,
    shortest_angular_distance,
    shortest_angular_distance_with_large_limits,
    shortest_angular_distance_with_limits,
    two_pi_complement,
)

PI = math.pi
EPS = 1e-9


# upstream TEST(Angles, normalize_angle_positive)
@pytest.mark.parametrize("angle, expected", [
    (0, 0), (PI, PI), (2 * PI, 0), (3 * PI, PI), (4 * PI, 0), (-PI, PI), (-2 * PI, 0), (-3 * PI, PI),
    (-4 * PI, 0), (-PI / 2, 3 * PI / 2), (-3 * PI / 2, PI / 2), (PI / 2, PI / 2), (5 * PI / 2, PI / 2),
    (9 * PI / 2, PI / 2),
])
def test_normalize_angle_positive_upstream(angle, expected):
    assert normalize_angle_positive(angle) == pytest.approx(expected, abs=EPS)


def test_normalize_angle_positive_range():
    assert normalize_angle_positive(-0.25) == pytest.approx(2 * PI - 0.25, abs=1e-15)
    assert normalize_angle_positive(7.0) == pytest.approx(7.0 - 2 * PI, abs=1e-15)


# upstream TEST(Angles, normalize_angle)
@pytest.mark.parametrize("angle, expected", [
    (0, 0), (PI, PI), (2 * PI, 0), (3 * PI, PI), (4 * PI, 0), (-PI, PI), (-2 * PI, 0), (-3 * PI, PI),
    (-4 * PI, 0), (-PI / 2, -PI / 2), (-3 * PI / 2, PI / 2), (PI / 2, PI / 2), (5 * PI / 2, PI / 2),
    (9 * PI / 2, PI / 2),
])
def test_normalize_angle_upstream(angle, expected):
    assert normalize_angle(angle) == pytest.approx(expected, abs=EPS)


def test_normalize_angle_interval_is_half_open_at_minus_pi():
    # (-pi, pi]: exactly -pi comes out as +pi (fmod(0, 2pi) = 0 <= 0 -> 0 + pi), 3.5 wraps negative
    assert normalize_angle(-PI) == PI
    assert normalize_angle(3.5) == pytest.approx(3.5 - 2 * PI, abs=1e-15)
    assert normalize_angle(-3.5) == pytest.approx(2 * PI - 3.5, abs=1e-15)


# upstream TEST(Angles, shortest_angular_distance)
@pytest.mark.parametrize("from_angle, to_angle, expected", [
    (0, PI / 2, PI / 2), (0, -PI / 2, -PI / 2), (PI / 2, 0, -PI / 2), (-PI / 2, 0, PI / 2),
    (PI, PI / 2, -PI / 2), (PI, -PI / 2, PI / 2), (PI / 2, PI, PI / 2), (-PI / 2, PI, -PI / 2),
    (5 * PI, PI / 2, -PI / 2), (7 * PI, -PI / 2, PI / 2), (9 * PI / 2, PI, PI / 2), (-3 * PI / 2, PI, PI / 2),
    (-3 * PI / 4, 3 * PI / 4, -PI / 2), (3 * PI / 4, -3 * PI / 4, PI / 2),
])
def test_shortest_angular_distance_upstream(from_angle, to_angle, expected):
    assert shortest_angular_distance(from_angle, to_angle) == pytest.approx(expected, abs=EPS)


def test_shortest_angular_distance_argument_order():
    # to - from, not from - to
    assert shortest_angular_distance(0.1, 0.4) == pytest.approx(0.3, abs=1e-15)


# upstream TEST(Angles, two_pi_complement)
@pytest.mark.parametrize("angle, expected", [
    (0, 2 * PI), (2 * PI, 0), (-2 * PI, 0), (2 * PI - EPS, -EPS), (-2 * PI + EPS, EPS), (PI / 2, -3 * PI / 2),
    (PI, -PI), (-PI, PI), (-PI / 2, 3 * PI / 2), (3 * PI, -PI), (-3.0 * PI, PI), (-5.0 * PI / 2.0, 3 * PI / 2),
])
def test_two_pi_complement_upstream(angle, expected):
    assert two_pi_complement(angle) == pytest.approx(expected, abs=EPS)


def test_two_pi_complement_of_zero_is_plus_two_pi():
    assert two_pi_complement(0.0) == 2 * PI
    assert two_pi_complement(0.25) == pytest.approx(0.25 - 2 * PI, abs=1e-15)


# upstream TEST(Angles, find_min_max_delta)
@pytest.mark.parametrize("from_angle, left, right, ok, min_delta, max_delta", [
    (0, -PI, PI, True, -PI, PI),
    (PI / 2, -PI, PI, True, -3 * PI / 2, PI / 2),
    (-PI / 2, -PI, PI, True, -PI / 2, 3 * PI / 2),
    (0, -PI / 2, PI / 2, True, -PI / 2, PI / 2),
    (PI / 4, -PI / 2, PI / 2, True, -3 * PI / 4, PI / 4),
    (-PI / 4, -PI / 2, PI / 2, True, -PI / 4, 3 * PI / 4),
    (-PI, -PI, PI, True, 0.0, 2 * PI),
    (-0.25, 0.25, -0.25, True, -2 * PI + 0.5, 0.0),
    (PI - EPS, -PI, PI, True, -2 * PI + EPS, EPS),
    (-PI / 2, -PI / 2, PI / 2, True, 0.0, PI),
    (3 * PI / 4, PI / 2, -PI / 2, True, -PI / 4, 3 * PI / 4),
])
def test_find_min_max_delta_upstream(from_angle, left, right, ok, min_delta, max_delta):
    result = find_min_max_delta(from_angle, left, right)
    assert result[0] is ok
    assert result[1] == pytest.approx(min_delta, abs=EPS)
    assert result[2] == pytest.approx(max_delta, abs=EPS)


@pytest.mark.parametrize("from_angle", [-PI, PI])
def test_find_min_max_delta_outside_upstream(from_angle):
    assert find_min_max_delta(from_angle, -PI / 2, PI / 2)[0] is False


def test_find_min_max_delta_outside_gives_swapped_deltas():
    # from 1.0 with limits [-0.5, 0.5]: to_left = -1.5 (other way 2pi-1.5), to_right = -0.5 (2pi-0.5);
    # delta_min = -1.5 (its 2pi partner 2pi-1.5), delta_max = 2pi-0.5 (partner -0.5) -> (False, -0.5, 2pi-1.5)
    ok, low, high = find_min_max_delta(1.0, -0.5, 0.5)
    assert ok is False
    assert low == pytest.approx(-0.5, abs=1e-12)
    assert high == pytest.approx(2 * PI - 1.5, abs=1e-12)


# upstream TEST(Angles, shortestDistanceWithLimits): (from, to, left, right, ok, expected or None)
@pytest.mark.parametrize("from_angle, to_angle, left, right, ok, expected", [
    (-0.5, 0.5, -0.25, 0.25, False, None),
    (-0.5, 0.5, 0.25, 0.25, False, None),
    (-0.5, 0.5, 0.25, -0.25, True, -2 * PI + 1.0),
    (0.5, 0.5, 0.25, -0.25, True, 0.0),
    (0.5, 0, 0.25, -0.25, False, -0.5),
    (-0.5, 0, 0.25, -0.25, False, 0.5),
    (-0.2, 0.2, 0.25, -0.25, False, -2 * PI + 0.4),
    (0.2, -0.2, 0.25, -0.25, False, 2 * PI - 0.4),
    (0.2, 0, 0.25, -0.25, False, 2 * PI - 0.2),
    (-0.2, 0, 0.25, -0.25, False, -2 * PI + 0.2),
    (-0.25, -0.5, 0.25, -0.25, True, -0.25),
    (-0.25, 0.5, 0.25, -0.25, True, -2 * PI + 0.75),
    (-0.2500001, 0.5, 0.25, -0.25, True, -2 * PI + 0.5 + 0.2500001),
    (-0.6, 0.5, -0.25, 0.25, False, None),
    (-0.5, 0.6, -0.25, 0.25, False, None),
    (-0.6, 0.75, -0.25, 0.3, False, None),
    (-0.6, PI * 3.0 / 4.0, -0.25, 0.3, False, None),
    (-PI, PI, -PI, PI, True, 0.0),
])
def test_shortest_angular_distance_with_limits_upstream(from_angle, to_angle, left, right, ok, expected):
    result_ok, shortest = shortest_angular_distance_with_limits(from_angle, to_angle, left, right)
    assert result_ok is ok
    if expected is not None:
        assert shortest == pytest.approx(expected, abs=1e-6)


def test_with_limits_inside_goes_the_long_way_round_the_stop():
    # revolute [-2, 2]: from 1.5 to -1.5 is 3 rad the short way through pi (beyond the stop at 2),
    # so the answer is -3 (through 0), and both ends are inside -> ok
    ok, shortest = shortest_angular_distance_with_limits(1.5, -1.5, -2.0, 2.0)
    assert ok is True
    assert shortest == pytest.approx(-3.0, abs=1e-12)
    ok, shortest = shortest_angular_distance_with_limits(-1.5, 1.5, -2.0, 2.0)
    assert ok is True and shortest == pytest.approx(3.0, abs=1e-12)


def test_with_limits_target_outside_turns_towards_nearer_stop():
    # limits [-1, 1], from 0 (min -1, max 1) to 1.2: delta 1.2 > 1 and 1.2-2pi < -1 -> target outside.
    # find_min_max_delta(1.2) is (False, -0.2, 2pi-2.2): |-0.2| < |4.08| -> max(1.2, 1.2-2pi)
    ok, shortest = shortest_angular_distance_with_limits(0.0, 1.2, -1.0, 1.0)
    assert ok is False
    # the target is nearer the right (upper) stop -> the positive way, 1.2, not 1.2 - 2pi
    assert shortest == pytest.approx(1.2, abs=1e-12)
    ok, shortest = shortest_angular_distance_with_limits(0.0, -1.2, -1.0, 1.0)
    assert ok is False and shortest == pytest.approx(-1.2, abs=1e-12)


def test_with_limits_start_outside_moves_back_inside():
    # from 1.5 outside [-1, 1] (nearer the upper stop) to 0: delta -1.5 (back through the range)
    ok, shortest = shortest_angular_distance_with_limits(1.5, 0.0, -1.0, 1.0)
    assert ok is False
    assert shortest == pytest.approx(-1.5, abs=1e-12)
    ok, shortest = shortest_angular_distance_with_limits(-1.5, 0.0, -1.0, 1.0)
    assert ok is False and shortest == pytest.approx(1.5, abs=1e-12)


# upstream TEST(Angles, shortestDistanceWithLargeLimits)
@pytest.mark.parametrize("from_angle, to_angle, left, right, ok, expected", [
    (0, 10.5 * PI, -2 * PI, 2 * PI, True, 0.5 * PI),
    (0, 10.5 * PI, -2 * PI, 0.1 * PI, True, -1.5 * PI),
    (2 * PI, PI, 2 * PI - 0.1, 2 * PI + 0.1, False, None),
    (10.5 * PI, 0, -2 * PI, 2 * PI, False, None),
    (0, 0.1, 2 * PI, -2 * PI, False, None),
    (0.999507, 1.0, -20 * PI, 20 * PI, True, 0.000493),
])
def test_shortest_angular_distance_with_large_limits_upstream(from_angle, to_angle, left, right, ok, expected):
    result_ok, shortest = shortest_angular_distance_with_large_limits(from_angle, to_angle, left, right)
    assert result_ok is ok
    if expected is not None:
        assert shortest == pytest.approx(expected, abs=1e-6)


def test_large_limits_fallbacks_return_the_shorter_way():
    # reversed limits: (False, delta) with delta the shorter way; 0 -> 0.1 is +0.1
    assert shortest_angular_distance_with_large_limits(0, 0.1, 2 * PI, -2 * PI) == (False, pytest.approx(0.1))
    # no way fits [2pi-0.1, 2pi+0.1] from 2pi to pi: the shorter of (pi, -pi) by |.| -> delta = normalize(-pi)
    ok, shortest = shortest_angular_distance_with_large_limits(2 * PI, PI, 2 * PI - 0.1, 2 * PI + 0.1)
    assert ok is False and abs(shortest) == pytest.approx(PI)


def test_large_limits_start_outside_still_gives_the_fitting_way():
    # from 3.5 outside [-3, 3] to 0: delta = normalize(-3.5) = 2pi-3.5 ~ 2.78 -> 6.28 outside; the other way
    # -3.5 lands on 0, inside -> (False, -3.5)
    ok, shortest = shortest_angular_distance_with_large_limits(3.5, 0.0, -3.0, 3.0)
    assert ok is False
    assert shortest == pytest.approx(-3.5, abs=1e-12)


def test_large_limits_swaps_to_the_shorter_way_first():
    # from 0 to 4 rad within [-5, 5]: normalize(4) = 4 - 2pi ~ -2.28 is shorter than 4 -> -2.28 (fits)
    ok, shortest = shortest_angular_distance_with_large_limits(0.0, 4.0, -5.0, 5.0)
    assert ok is True
    assert shortest == pytest.approx(4.0 - 2 * PI, abs=1e-12)
