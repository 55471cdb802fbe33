"""arc_check: the circle fit, the slip angle and the arc's verdict on synthetic drives."""
import math

import pytest

from diffbot_sim.check import arc_check


def drive(radius, slip=0.0, n=200, turn=math.pi, offset=(0.0, 0.0)):
    """A body whose rear axle runs on a circle of ``radius`` about (1, 2), its heading ``slip`` off the path."""
    out = []
    for i in range(n):
        a = turn * i / (n - 1)
        x, y = 1 + radius * math.sin(a), 2 - radius * math.cos(a)
        tangent = a
        out.append(arc_check.AxleSample(i * 0.1, x, y, tangent - slip, 0.3 * math.cos(tangent),
                                        0.3 * math.sin(tangent)))
    return out


def test_fit_circle_recovers_centre_and_radius():
    pts = [(3 + 2 * math.cos(a), -1 + 2 * math.sin(a)) for a in (0.1, 0.5, 1.0, 1.7, 2.2)]
    assert arc_check.fit_circle(pts) == pytest.approx((3, -1, 2))
    with pytest.raises(ValueError):
        arc_check.fit_circle([(0, 0), (1, 1), (2, 2)])


def test_arc_passes_on_the_geometry_and_fails_off_it():
    wheelbase, steer = 0.4, 0.3
    radius = arc_check.geometry_radius(wheelbase, steer)
    good = arc_check.arc(drive(radius), wheelbase, steer)
    assert good.passed and good.radius == pytest.approx(radius) and good.max_slip < 1e-9
    wide = arc_check.arc(drive(radius * 1.2), wheelbase, steer)
    assert not wide.passed and "turning radius" in wide.failures[0]
    slipping = arc_check.arc(drive(radius, slip=0.1), wheelbase, steer)
    assert not slipping.passed and "slid sideways" in slipping.failures[0]
    short = arc_check.arc(drive(radius, turn=0.3), wheelbase, steer)
    assert not short.passed


def test_axle_sample_adds_the_rotation():
    s = arc_check.axle_sample(0.0, (0.0, 0.0), math.pi / 2, (0.0, 0.3), 0.5, (-0.2, 0.0))
    assert (s.x, s.y) == pytest.approx((0.0, -0.2))
    assert (s.vx, s.vy) == pytest.approx((0.1, 0.3))  # v + w x r, r = (0, -0.2): (0.5 * 0.2, 0)


def test_front_wheel_radii_meet_for_an_exact_ackermann_linkage():
    wheelbase, track, radius = 0.4, 0.4, 1.3
    right = math.atan(wheelbase / (radius + track / 2))
    left = math.atan(wheelbase / (radius - track / 2))
    assert arc_check.front_wheel_radii(wheelbase, track, right, left) == pytest.approx((radius, radius))
    low, high = arc_check.front_wheel_radii(wheelbase, track, 0.9 * right, left)
    assert low > radius and high == pytest.approx(radius)
    inside = arc_check.arc(drive(1.05 * radius), wheelbase, 0.3, radius_tolerance=0.0,
                           radius_range=(radius, 1.1 * radius))
    assert inside.passed, inside.failures
