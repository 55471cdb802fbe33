"""Wheel-encoder odometry (pure), as diff_drive_controller integrates it.

Wheel *positions* (joint angles) give arc lengths; increments are integrated with the exact arc formula,
falling back to 2nd-order Runge-Kutta when the heading change is tiny. Velocities are signed (reversing
gives negative linear velocity, unlike gazebo_ros_diff_drive's encoder mode, gazebo_ros_pkgs#1432).
"""
import math
from collections import deque

from diffbot_sim.errors import ConfigError


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

    The defaults give the plain estimate gazebo_ros_diff_drive needs (one radius, velocity from the last
    increment alone); diff_drive_controller's Odometry is the same with a rolling mean over the last
    ``velocity_window`` velocity estimates and a radius per side (its radius multipliers), plus
    ``update_open_loop`` for ``open_loop: true``.

    Args:
        wheel_radius: m; the left wheel's, and the right's too unless ``right_wheel_radius`` is given.
        wheel_separation: m.
        velocity_window: how many increment/dt estimates ``linear``/``angular`` average (>= 1).
        right_wheel_radius: m, or None for ``wheel_radius``.
    """

    def __init__(self, wheel_radius, wheel_separation, velocity_window=1, right_wheel_radius=None):
        if (isinstance(velocity_window, bool) or not isinstance(velocity_window, (int, float))
                or velocity_window != int(velocity_window) or velocity_window < 1):
            raise ConfigError("velocity_rolling_window_size", velocity_window, "an integer >= 1")
        self.set_wheel_params(wheel_separation, wheel_radius, right_wheel_radius)
        self.x = self.y = self.yaw = 0.0
        self.linear = self.angular = 0.0
        self._left = self._right = self._time = None
        self._linear_samples = deque(maxlen=int(velocity_window))
        self._angular_samples = deque(maxlen=int(velocity_window))

    @property
    def radius(self):
        """The left wheel radius [m] (both, for the single-radius users); setting it sets both."""
        return self.left_radius

    @radius.setter
    def radius(self, value):
        self.left_radius = self.right_radius = value

    @property
    def velocity_window(self):
        """How many velocity estimates the rolling mean spans."""
        return self._linear_samples.maxlen

    def set_wheel_params(self, wheel_separation, left_radius, right_radius=None):
        """Set the geometry the increments are scaled with, multipliers already applied, as DDC's setWheelParams.

        Args:
            wheel_separation: m. left_radius: m. right_radius: m, or None for ``left_radius``.
        """
        self.separation = wheel_separation
        self.left_radius = left_radius
        self.right_radius = left_radius if right_radius is None else right_radius

    def reset(self, left_position, right_position, time, x=0.0, y=0.0, yaw=0.0):
        """Start integrating from pose (x, y, yaw) with the wheels at the given angles [rad] at ``time`` [s]."""
        self.x, self.y, self.yaw = x, y, yaw
        self.linear = self.angular = 0.0
        self._left, self._right, self._time = left_position, right_position, time
        self._linear_samples.clear()
        self._angular_samples.clear()

    def restart(self, time):
        """Clear the velocity window and measure the next dt from ``time``; keep the pose and wheel angles.

        What diff_drive_controller's ``starting()`` does to its odometry (``init(time)``): a restarted
        controller neither jumps nor averages in the velocity from before it was stopped. Before the first
        wheel reading this only sets the time ``update_open_loop`` measures from; the first ``update`` still
        takes its angles as the starting point.
        """
        self._linear_samples.clear()
        self._angular_samples.clear()
        self.linear = self.angular = 0.0
        self._time = time

    def update(self, left_position, right_position, time):
        """Integrate the wheel angle increments since the last call; returns False if nothing was done.

        A non-finite angle leaves the odometry frozen (as diff_drive_controller does) instead of poisoning it.
        """
        if not (math.isfinite(left_position) and math.isfinite(right_position)):
            return False
        if self._left is None:
            self.reset(left_position, right_position, time)
            return False
        dt = time - self._time
        if dt < 1e-4:
            return False
        d_left = (left_position - self._left) * self.left_radius
        d_right = (right_position - self._right) * self.right_radius
        self._left, self._right, self._time = left_position, right_position, time
        distance = (d_left + d_right) / 2.0
        dyaw = (d_right - d_left) / self.separation
        self.x, self.y, self.yaw = integrate_exact(self.x, self.y, self.yaw, distance, dyaw)
        self._linear_samples.append(distance / dt)
        self._angular_samples.append(dyaw / dt)
        if self._linear_samples.maxlen == 1:
            self.linear, self.angular = self._linear_samples[0], self._angular_samples[0]
        else:
            self.linear = sum(self._linear_samples) / len(self._linear_samples)
            self.angular = sum(self._angular_samples) / len(self._angular_samples)
        return True

    def update_open_loop(self, linear, angular, time):
        """Integrate a commanded body velocity (v [m/s], w [rad/s]) held since the last update.

        diff_drive_controller's ``open_loop: true``: the wheels are not read at all, so the pose is what the
        commands say; the reported velocity is the command itself (no rolling mean, as upstream). Returns
        False when nothing was integrated (first call, or a non-finite input).
        """
        if not (math.isfinite(linear) and math.isfinite(angular) and math.isfinite(time)):
            return False
        self.linear, self.angular = linear, angular
        if self._time is None:
            self._time = time
            return False
        dt = time - self._time
        self._time = time
        self.x, self.y, self.yaw = integrate_exact(self.x, self.y, self.yaw, linear * dt, angular * dt)
        return True
