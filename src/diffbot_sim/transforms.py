"""Rotations and poses as plain numbers (pure; numpy only): URDF/SDF roll-pitch-yaw, (x, y, z, w)
quaternions, their rotation matrices, planar yaw, and poses composed and inverted.

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


def roll_pitch_from_quaternion(x, y, z, w):
    """(roll, pitch) [rad] of a unit quaternion, fixed-axis x-y-z (REP 103); pitch in [-pi/2, pi/2]."""
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    return roll, pitch


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
