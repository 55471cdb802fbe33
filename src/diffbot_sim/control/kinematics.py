"""Differential-drive kinematics (pure). REP 103: x forward, positive yaw rate turns left.

Rim speeds are in m/s; a wheel joint's angular velocity is rim speed / wheel radius.
"""


def wheel_speeds(linear, angular, separation):
    """Inverse kinematics: body (v [m/s], w [rad/s]) -> (left, right) rim speeds [m/s]."""
    half = angular * separation / 2.0
    return linear - half, linear + half


def body_velocity(left, right, separation):
    """Forward kinematics: (left, right) rim speeds [m/s] -> body (v [m/s], w [rad/s])."""
    return (left + right) / 2.0, (right - left) / separation

