"""Wheel-encoder odometry (pure), as diff_drive_controller integrates it.

Wheel *positions* (joint angles) give arc lengths; increments are integrated with the exact arc formula,
falling back to 2nd-order Runge-Kutta when the heading change is tiny. Velocities are signed (reversing
gives negative linear velocity, unlike gazebo_ros_diff_drive's encoder mode, gazebo_ros_pkgs#1432).
"""
import math


def integrate_exact(x, y, yaw, distance, dyaw):
    """Advance pose (x, y, yaw) by an arc of length ``distance`` [m] turning ``dyaw`` [rad]."""
    if abs(dyaw) < 1e-6:
        mid = yaw + dyaw / 2.0
        return x + distance * math.cos(mid), y + distance * math.sin(mid), yaw + dyaw
    radius = distance / dyaw
    new_yaw = yaw + dyaw
    return (x + radius * (math.sin(new_yaw) - math.sin(yaw)),
            y - radius * (math.cos(new_yaw) - math.cos(yaw)),
            new_yaw)


class EncoderOdometry:
    """Pose and velocity of the base from the two wheel joint angles.

    Args:
        wheel_radius: m. wheel_separation: m.
    """

    def __init__(self, wheel_radius, wheel_separation):
        self.radius = wheel_radius
        self.separation = wheel_separation
        self.x = self.y = self.yaw = 0.0
        self.linear = self.angular = 0.0
        self._left = self._right = self._time = None

    def reset(self, left_position, right_position, time, x=0.0, y=0.0, yaw=0.0):
        """Start integrating from pose (x, y, yaw) with the wheels at the given angles [rad] at ``time`` [s]."""
        self.x, self.y, self.yaw = x, y, yaw
        self.linear = self.angular = 0.0
        self._left, self._right, self._time = left_position, right_position, time

    def update(self, left_position, right_position, time):
        """Integrate the wheel angle increments since the last call; returns False if nothing was done.

        A non-finite angle leaves the odometry frozen (as diff_drive_controller does) instead of poisoning it.
        """
        if not (math.isfinite(left_position) and math.isfinite(right_position)):
            return False
        if self._time is None:
            self.reset(left_position, right_position, time)
            return False
        dt = time - self._time
        if dt < 1e-4:
            return False
        d_left = (left_position - self._left) * self.radius
        d_right = (right_position - self._right) * self.radius
        self._left, self._right, self._time = left_position, right_position, time
        distance = (d_left + d_right) / 2.0
        dyaw = (d_right - d_left) / self.separation
        self.x, self.y, self.yaw = integrate_exact(self.x, self.y, self.yaw, distance, dyaw)
        self.linear, self.angular = distance / dt, dyaw / dt
        return True
