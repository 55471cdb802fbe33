"""Rotations and poses as plain numbers (pure; numpy only): URDF/SDF roll-pitch-yaw, (x, y, z, w)
quaternions, their rotation matrices, planar yaw, poses composed and inverted, and ignition-math's
quaternion interpolation (slerp, squad) as Gazebo's animations use it.

One place for the conventions every reader shares: fixed-axis roll, pitch, yaw (R = Rz(yaw) Ry(pitch)
Rx(roll), as URDF and SDF define them, and as ``tf.transformations.quaternion_from_euler`` with its
default static 'sxyz' axes computes them) and Hamilton quaternions in ROS's (x, y, z, w) order. Every
module that turns angles into quaternions or back imports them from here.
"""
import math

import numpy as np


def wrap_angle(angle):
    """``angle`` in (-pi, pi]: the difference of two headings as a turn."""
    return math.atan2(math.sin(angle), math.cos(angle))


def rpy_matrix(rpy):
    """Rotation matrix of fixed-axis roll, pitch, yaw (URDF and SDF): Rz(yaw) @ Ry(pitch) @ Rx(roll)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def quaternion_matrix(q):
    """Rotation matrix (3, 3) of a unit quaternion (x, y, z, w)."""
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def qmul(a, b):
    """Hamilton product a·b of two (x, y, z, w) quaternions."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def qconj(q):
    """The conjugate (the inverse of a unit quaternion)."""
    return (-q[0], -q[1], -q[2], q[3])


# ------------------------------------------------------------------------------------------------ poses
# A pose is ((x, y, z), (qx, qy, qz, qw)), plain tuples.

def qnormalize(q):
    """``q`` scaled to unit length (the identity for a zero quaternion)."""
    n = math.sqrt(sum(c * c for c in q))
    return tuple(c / n for c in q) if n > 0 else (0.0, 0.0, 0.0, 1.0)


def rotate(q, v):
    """Vector ``v`` turned by the unit quaternion ``q`` (x, y, z, w)."""
    x, y, z, w = q
    # v + 2 w (u x v) + 2 u x (u x v), with u the vector part: no matrix needed.
    cx, cy, cz = y * v[2] - z * v[1], z * v[0] - x * v[2], x * v[1] - y * v[0]
    return (v[0] + 2 * (w * cx + y * cz - z * cy),
            v[1] + 2 * (w * cy + z * cx - x * cz),
            v[2] + 2 * (w * cz + x * cy - y * cx))


def compose(a, b):
    """``a * b``: pose ``b`` (given in frame ``a``) expressed in ``a``'s parent frame."""
    (pa, qa), (pb, qb) = a, b
    p = rotate(qa, pb)
    return ((pa[0] + p[0], pa[1] + p[1], pa[2] + p[2]), qnormalize(qmul(qa, qb)))


def inverse(a):
    """The pose that undoes ``a``: ``compose(a, inverse(a)) == IDENTITY``."""
    p, (x, y, z, w) = a
    qi = (-x, -y, -z, w)
    r = rotate(qi, p)
    return ((-r[0], -r[1], -r[2]), qi)


def rpy_quaternion(roll, pitch, yaw):
    """Fixed-axis roll, pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll); URDF, SDF) -> quaternion (x, y, z, w).

    The same numbers as ``tf.transformations.quaternion_from_euler(roll, pitch, yaw)`` (axes 'sxyz'), which
    is what gazebo_ros's spawn_model sends for ``-R -P -Y``.
    """
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)


def _rpy_of(r00, r10, r20, r21, r22, r11, r12):
    """(roll, pitch, yaw) from the rotation matrix entries they need (see :func:`matrix_rpy`)."""
    cos_pitch = math.hypot(r00, r10)
    pitch = math.atan2(-r20, cos_pitch)
    if cos_pitch < 1e-12:  # gimbal lock: only roll - yaw (pitch +pi/2) or roll + yaw (-pi/2) is defined
        return math.atan2(-r12, r11), pitch, 0.0
    return math.atan2(r21, r22), pitch, math.atan2(r10, r00)


def matrix_rpy(m):
    """Fixed-axis (roll, pitch, yaw) [rad] of the rotation matrix ``m`` (3 x 3, ``m[i][j]``): the inverse of
    :func:`rpy_matrix`, as Python floats.

    Pitch is read with ``atan2`` from the matrix, so it stays exact near +-pi/2 where ``asin`` would lose half
    the digits. At gimbal lock (cos pitch < 1e-12, which also catches a matrix composed of two half pitches,
    where rounding leaves |sin pitch| a hair above 1) yaw is 0 and roll carries the rest, as ignition-math's
    ``Quaternion::Euler`` decides (Gazebo writes a spawned model's ``<pose>`` with it).
    """
    return _rpy_of(float(m[0][0]), float(m[1][0]), float(m[2][0]), float(m[2][1]), float(m[2][2]),
                   float(m[1][1]), float(m[1][2]))


def quaternion_rpy(q):
    """Fixed-axis (roll, pitch, yaw) [rad] of the quaternion ``q`` (x, y, z, w; normalised first): the inverse
    of :func:`rpy_quaternion`, read as :func:`matrix_rpy` reads the rotation matrix (the one conversion of a
    full rotation to angles; ignition-math's convention at gimbal lock)."""
    x, y, z, w = qnormalize(tuple(float(c) for c in q))
    return _rpy_of(1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y), 2 * (y * z + w * x),
                   1 - 2 * (x * x + y * y), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x))


def roll_pitch_from_quaternion(x, y, z, w):
    """(roll, pitch) [rad] of a unit quaternion, fixed-axis x-y-z (REP 103); pitch in [-pi/2, pi/2]."""
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    return roll, pitch


# ------------------------------------------------------------------------------------------------ interpolation
# ignition-math6's Quaternion operations that Gazebo's animations use (an actor's script), with its exact
# formulas and thresholds, so that an interpolation lands where Gazebo's does, quirks included.

#: ``ignition::math::equal``'s default tolerance: values this close count as equal.
IGN_EQUAL = 1e-6


def qinverse(q):
    """``Quaternion::Inverse``: the conjugate over the squared norm (the identity for a zero quaternion)."""
    norm2 = sum(c * c for c in q)
    if abs(norm2) <= IGN_EQUAL:
        return (0.0, 0.0, 0.0, 1.0)
    return (-q[0] / norm2, -q[1] / norm2, -q[2] / norm2, q[3] / norm2)


def qlog(q):
    """``Quaternion::Log``: angle * axis when sin(angle) >= 1e-3, else the vector part as it is (w = 0)."""
    x, y, z, w = q
    if abs(w) < 1.0:
        angle = math.acos(w)
        sin = math.sin(angle)
        if abs(sin) >= 1e-3:
            c = angle / sin
            return (c * x, c * y, c * z, 0.0)
    return (x, y, z, 0.0)


def qexp(q):
    """``Quaternion::Exp``: (sin a * axis, cos a) for the vector part of length a."""
    x, y, z, _ = q
    angle = math.sqrt(x * x + y * y + z * z)
    sin = math.sin(angle)
    c = sin / angle if abs(sin) >= 1e-3 else 1.0
    return (c * x, c * y, c * z, math.cos(angle))


def _qscale(q, s):
    return tuple(c * s for c in q)


def _qadd(a, b):
    return tuple(x + y for x, y in zip(a, b))


def slerp(t, p, q, shortest_path=False):
    """``Quaternion::Slerp``: spherical interpolation ``p`` -> ``q`` at ``t`` in 0..1; ``shortest_path`` flips
    ``q`` when the two are more than half a turn apart; near-equal (|cos| >= 0.999) ends are lerped."""
    cos = sum(a * b for a, b in zip(p, q))
    if cos < 0.0 and shortest_path:
        cos, q = -cos, _qscale(q, -1.0)
    if abs(cos) < 1.0 - 1e-3:
        sin = math.sqrt(1.0 - cos * cos)
        angle = math.atan2(sin, cos)
        return _qadd(_qscale(p, math.sin((1.0 - t) * angle) / sin), _qscale(q, math.sin(t * angle) / sin))
    mix = _qadd(_qscale(p, 1.0 - t), _qscale(q, t))
    norm = math.sqrt(sum(c * c for c in mix))
    return (0.0, 0.0, 0.0, 1.0) if abs(norm) <= IGN_EQUAL else _qscale(mix, 1.0 / norm)


def squad(t, p, a, b, q, shortest_path=False):
    """``Quaternion::Squad``: Shoemake's spherical quadrangle through ``p``, ``q`` with inner points ``a``,
    ``b``."""
    return slerp(2.0 * t * (1.0 - t), slerp(t, p, q, shortest_path), slerp(t, a, b))


def shoemake_tangent(p, later, earlier):
    """``RotationSpline``'s inner point at ``p`` between its neighbours ``earlier`` and ``later``:
    ``p exp(-(log(p^-1 later) + log(p^-1 earlier)) / 4)``."""
    inv = qinverse(p)
    return qmul(p, qexp(_qscale(_qadd(qlog(qmul(inv, later)), qlog(qmul(inv, earlier))), -0.25)))


# ------------------------------------------------------------------------------------------------ planar
# A ground robot's heading: rotation about +z only (REP 103: counter-clockwise positive).

def yaw_from_quaternion(x, y, z, w):
    """Yaw [rad] about +z, in (-pi, pi], of a unit quaternion; roll and pitch are ignored."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def quaternion_from_yaw(yaw):
    """(x, y, z, w) of a rotation by ``yaw`` [rad] about +z."""
    return 0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0)


def rays_along(position, rotation, directions, near, far):
    """Start and end points (each (rays, 3), C-contiguous float64) of rays from ``near`` to ``far`` [m] along
    ``directions`` ((rays, 3), unit, in the frame of ``rotation``) from ``position``: a ray sensor's rays in the
    world (one formula, so rays cast in the ray process are the very numbers cast in place)."""
    world = directions @ rotation.T
    return np.ascontiguousarray(position + world * near), np.ascontiguousarray(position + world * far)
