"""Judging a car-like robot's arc by the body (pure): the turning radius its steering geometry gives and no
lateral slip of its unsteered axle.

A car cannot turn in place; it is judged driving an arc at a fixed steering angle instead. On a bicycle model
(ackermann_steering_controller: ``cmd_vel.angular.z`` is the steering angle δ) the middle of the rear axle
runs on a circle of radius ``L / tan δ`` (``L`` the wheelbase), and at low speed it moves along the body's
heading: its velocity has no sideways part. Both are measured on ground truth: the rear axle's positions
(body pose + the axle's offset in the body) fitted with a circle, and the angle between the axle's velocity
and the body's heading. Samples are plain tuples; the rostest suites and ``robot_check`` share these rules.
"""
import math
from typing import NamedTuple

from diffbot_sim.transforms import wrap_angle

#: fraction of the geometry's turning radius the measured one may differ by
RADIUS_TOLERANCE = 0.05
#: rad: the largest angle between the rear axle's velocity and the body's heading (lateral slip)
MAX_SLIP = 0.03
#: the steering angle [rad] and speed [m/s] the arc is driven at, and for how long [s]
ARC_STEER = 0.3
ARC_SPEED = 0.3
ARC_SECONDS = 8.0


class AxleSample(NamedTuple):
    """The unsteered axle's middle at time ``t``: position (x, y) [m], the body's heading [rad] and the axle's
    world velocity (vx, vy) [m/s]."""

    t: float
    x: float
    y: float
    heading: float
    vx: float
    vy: float


def axle_sample(t, base_xy, heading, base_velocity, yaw_rate, offset):
    """The axle at ``offset`` (x, y in the body frame) of a body at ``base_xy`` facing ``heading`` moving at
    ``base_velocity`` (vx, vy) and turning at ``yaw_rate``: position and velocity of that point (v + w x r)."""
    c, s = math.cos(heading), math.sin(heading)
    rx, ry = c * offset[0] - s * offset[1], s * offset[0] + c * offset[1]
    return AxleSample(t, base_xy[0] + rx, base_xy[1] + ry, heading,
                      base_velocity[0] - yaw_rate * ry, base_velocity[1] + yaw_rate * rx)


def axle_samples(poses, offset):
    """AxleSamples of the point at ``offset`` (body frame) from body poses [(t, x, y, yaw)] alone (ground truth
    without twists): positions, and velocities by differences of neighbouring samples."""
    points = []
    for t, x, y, yaw in poses:
        c, s = math.cos(yaw), math.sin(yaw)
        points.append((t, x + c * offset[0] - s * offset[1], y + s * offset[0] + c * offset[1], yaw))
    out = []
    for i, (t, x, y, yaw) in enumerate(points):
        a, b = points[max(i - 1, 0)], points[min(i + 1, len(points) - 1)]
        dt = b[0] - a[0]
        out.append(AxleSample(t, x, y, yaw, (b[1] - a[1]) / dt if dt > 0 else 0.0,
                              (b[2] - a[2]) / dt if dt > 0 else 0.0))
    return out


def geometry_radius(wheelbase, steer):
    """The rear axle's turning radius [m] of a bicycle model with ``wheelbase`` [m] steered by ``steer`` [rad]."""
    return math.inf if abs(math.tan(steer)) < 1e-12 else wheelbase / abs(math.tan(steer))


def front_wheel_radii(wheelbase, track, right, left):
    """The rear axle middle's turning radius [m] each steered front wheel alone implies, (by the right wheel, by
    the left wheel; signed: negative turning right), for wheels at ``right``/``left`` [rad] ``track`` [m] apart:
    where its axis meets the rear axle's line. A linkage that is not exactly Ackermann's makes them differ; the
    body turns between them."""
    def by(angle, side):
        return math.inf if abs(math.tan(angle)) < 1e-12 else wheelbase / math.tan(angle) + side * track / 2
    return by(right, -1) if right else math.inf, by(left, 1) if left else math.inf


def fit_circle(points):
    """Least-squares circle through (x, y) points (Kåsa's algebraic fit): (cx, cy, radius)."""
    n = len(points)
    if n < 3:
        raise ValueError("a circle needs at least 3 points")
    mx = sum(p[0] for p in points) / n
    my = sum(p[1] for p in points) / n
    u = [(p[0] - mx, p[1] - my) for p in points]
    suu = sum(a * a for a, _ in u)
    svv = sum(b * b for _, b in u)
    suv = sum(a * b for a, b in u)
    suuu = sum(a ** 3 for a, _ in u)
    svvv = sum(b ** 3 for _, b in u)
    suvv = sum(a * b * b for a, b in u)
    svuu = sum(b * a * a for a, b in u)
    det = suu * svv - suv * suv
    if abs(det) < 1e-15:
        raise ValueError("the points are on a line")
    rhs_u, rhs_v = (suuu + suvv) / 2, (svvv + svuu) / 2
    uc = (rhs_u * svv - rhs_v * suv) / det
    vc = (rhs_v * suu - rhs_u * suv) / det
    radius = math.sqrt(uc * uc + vc * vc + (suu + svv) / n)
    return mx + uc, my + vc, radius


def slip_angle(sample, min_speed=0.02):
    """Angle [rad] between the axle's velocity and the body's heading (0 at rest or when reversing straight)."""
    speed = math.hypot(sample.vx, sample.vy)
    if speed < min_speed:
        return 0.0
    angle = wrap_angle(math.atan2(sample.vy, sample.vx) - sample.heading)
    if abs(angle) > math.pi / 2:  # reversing: measure against the rear
        angle = wrap_angle(angle - math.pi)
    return angle


class Arc(NamedTuple):
    radius: float
    expected: float
    max_slip: float
    turned: float  # rad of heading over the samples
    passed: bool
    failures: list[str]


def arc(samples, wheelbase, steer, radius_tolerance=RADIUS_TOLERANCE, max_slip=MAX_SLIP, radius_range=None):
    """Judge an arc: the fitted radius within ``radius_tolerance`` of L / tan δ (or of the interval
    ``radius_range`` (low, high), e.g. :func:`front_wheel_radii` of a four-wheel car's real steering angles), no
    slip angle over ``max_slip``, and at least a quarter turn so that the fit means something."""
    expected = geometry_radius(wheelbase, steer)
    low, high = sorted(abs(r) for r in radius_range) if radius_range else (expected, expected)
    failures = []
    turned = sum(wrap_angle(b.heading - a.heading) for a, b in zip(samples, samples[1:]))
    radius = fit_circle([(s.x, s.y) for s in samples])[2] if len(samples) >= 3 else math.nan
    worst = max((abs(slip_angle(s)) for s in samples), default=math.nan)
    if not abs(turned) >= math.pi / 4:
        failures.append(f"turned {turned:.3f} rad, less than a quarter of pi: too short an arc to fit")
    if not low * (1 - radius_tolerance) <= radius <= high * (1 + radius_tolerance):
        gives = f"{expected:.3f} m (L {wheelbase:g} m / tan {steer:g})" if low == high else \
            f"{low:.3f}..{high:.3f} m (its front wheels' angles)"
        failures.append(f"turning radius {radius:.3f} m, the steering geometry gives {gives}")
    if not worst <= max_slip:
        failures.append(f"the rear axle slid sideways: slip angle up to {worst:.3f} rad (at most {max_slip:g})")
    return Arc(radius, expected, worst, turned, not failures, failures)
