"""Differential-drive kinematics (pure). REP 103: x forward, positive yaw rate turns left.

Rim speeds are in m/s; a wheel joint's angular velocity is rim speed / wheel radius.
"""
import math


def wheel_speeds(linear, angular, separation):
    """Inverse kinematics: body (v [m/s], w [rad/s]) -> (left, right) rim speeds [m/s]."""
    half = angular * separation / 2.0
    return linear - half, linear + half


def body_velocity(left, right, separation):
    """Forward kinematics: (left, right) rim speeds [m/s] -> body (v [m/s], w [rad/s])."""
    return (left + right) / 2.0, (right - left) / separation


def yaw_from_quaternion(x, y, z, w):
    """Yaw (rad, about +z, in (-pi, pi]) of a unit quaternion; roll and pitch are ignored."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def quaternion_from_yaw(yaw):
    """(x, y, z, w) of a rotation by ``yaw`` rad about +z."""
    return 0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0)
