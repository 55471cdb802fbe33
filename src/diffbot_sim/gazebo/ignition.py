"""ignition-math's pose conventions, as Gazebo classic applies them to what /gazebo services receive (pure):
``Quaternion::Normalize`` (a near-zero quaternion is the identity), ``RotateVectorReverse``. A pose is
``((x, y, z), (qx, qy, qz, qw))``. ``Quaternion::Euler``'s convention at gimbal lock is that of
:func:`diffbot_sim.transforms.quaternion_rpy`."""
import math

from diffbot_sim.transforms import rotate

IDENTITY = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def unrotate(q, v):
    """``v`` turned by the inverse of the unit quaternion ``q`` (ignition's RotateVectorReverse)."""
    return rotate((-q[0], -q[1], -q[2], q[3]), v)


def unit(q):
    """``q`` normalised as ignition's ``Quaternion::Normalize``: a norm within 1e-6 of zero is identity."""
    m = max(abs(c) for c in q)
    if m == 0.0:
        return (0.0, 0.0, 0.0, 1.0)
    s = tuple(c / m for c in q)  # scaled first, so 1e200 components do not overflow the square
    n = m * math.sqrt(sum(c * c for c in s))
    if n <= 1e-6:
        return (0.0, 0.0, 0.0, 1.0)
    return tuple(c / n for c in q)


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def floats(v):
    return tuple(float(c) for c in v)


def unit_pose(pose):
    """A pose's numbers as floats, its quaternion normalised as ignition does."""
    p, q = pose
    return floats(p), unit(floats(q))
