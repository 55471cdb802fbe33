"""The diff-drive controller (pure): commands in, wheel joint velocity targets out.

What gazebo_ros_diff_drive's UpdateChild does, plus what diff_drive_controller adds for safety: non-finite
commands are refused, stale commands brake when a timeout is set, wheel speeds are capped. Time is passed
in (sim seconds); the simulator alone owns it.
"""
import math

from diffbot_sim.control.kinematics import wheel_speeds
from diffbot_sim.control.limits import ramp, scale_to_limit

TWIST_FIELDS = ("linear.x", "linear.y", "linear.z", "angular.x", "angular.y", "angular.z")


def non_finite_field(values):
    """Name of the first non-finite value among the six Twist fields (in TWIST_FIELDS order), or None."""
    for name, value in zip(TWIST_FIELDS, values):
        if not math.isfinite(value):
            return name
    return None


class DiffDriveController:
    """Turns (v, w) commands into left/right wheel joint velocity targets [rad/s].

    Args:
        separation: wheel separation [m]. radius: wheel radius [m].
        max_wheel_velocity: cap on each wheel's joint velocity [rad/s] (> 0).
        max_wheel_acceleration: rim acceleration limit [m/s^2]; 0 = none.
        cmd_vel_timeout: seconds after which a command is stale and the wheels brake; 0 = hold forever.
    """

    def __init__(self, separation, radius, max_wheel_velocity, max_wheel_acceleration=0.0, cmd_vel_timeout=0.0):
        self.separation = separation
        self.radius = radius
        self.max_wheel_velocity = max_wheel_velocity
        self.max_wheel_acceleration = max_wheel_acceleration
        self.cmd_vel_timeout = cmd_vel_timeout
        self.linear = self.angular = 0.0
        self.stamp = None  # sim time of the last accepted command
        self.targets = (0.0, 0.0)
        self._braking = False  # a stale command stopped the wheels; hold them until a new command

    @property
    def max_linear(self):
        return self.max_wheel_velocity * self.radius

    def set_command(self, linear, angular, now):
        """Accept a finite command at sim time ``now``, clamped to what the wheels can do.

        Returns False (and changes nothing) for a non-finite value: NaN must never reach the physics.
        """
        if not (math.isfinite(linear) and math.isfinite(angular)):
            return False
        # Scale both by one factor (keeps the curvature) so even 1e308 stays far from overflow in the
        # kinematics; the wheel-speed limit in update() then does the real limiting.
        factor = max(1.0, abs(linear) / self.max_linear, abs(angular) * self.separation / (2.0 * self.max_linear))
        self.linear, self.angular = linear / factor, angular / factor
        self.stamp = now
        self._braking = False
        return True

    def brake(self):
        """Command zero (e.g. on reset)."""
        self.linear = self.angular = 0.0
        self.stamp = None

    def expiry(self):
        """Sim time at which the current command goes stale, or None if it never does."""
        if self.cmd_vel_timeout <= 0 or self.stamp is None or (self.linear == 0.0 and self.angular == 0.0):
            return None
        return self.stamp + self.cmd_vel_timeout

    def update(self, now, left_velocity, right_velocity, dt):
        """Wheel joint velocity targets [rad/s] for this control period.

        Args:
            now: sim time [s]. left_velocity, right_velocity: measured wheel joint velocities [rad/s] (the
                acceleration ramp starts from them, as in Gazebo). dt: control period [s].
        """
        expiry = self.expiry()
        if expiry is not None and now >= expiry:
            # A stale command is a safety stop: brake at once (the motor torque limit still bounds the
            # deceleration physically) rather than ramping down over the acceleration limit, and keep
            # braking until a new command arrives.
            self.linear = self.angular = 0.0
            self._braking = True
        if self._braking:
            self.targets = (0.0, 0.0)
            return self.targets
        left, right = wheel_speeds(self.linear, self.angular, self.separation)
        left, right = scale_to_limit(left / self.radius, right / self.radius, self.max_wheel_velocity)
        max_delta = self.max_wheel_acceleration * dt / self.radius
        self.targets = (ramp(left_velocity, left, max_delta), ramp(right_velocity, right, max_delta))
        return self.targets
