"""Rotations as plain numbers (pure; numpy only): URDF/SDF roll-pitch-yaw and (x, y, z, w) quaternions.

One place for the conventions every reader shares: fixed-axis roll, pitch, yaw (R = Rz(yaw) Ry(pitch)
Rx(roll), as URDF and SDF define them) and Hamilton quaternions in ROS's (x, y, z, w) order.
"""
import math

import numpy as np


def rpy_matrix(rpy):
    """Rotation matrix of fixed-axis roll, pitch, yaw (URDF and SDF): Rz(yaw) @ Ry(pitch) @ Rx(roll)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


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
