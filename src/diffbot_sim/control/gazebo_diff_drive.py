"""gazebo_ros_diff_drive's per-step logic (pure): commands in, wheel joint velocity targets out, on the plugin's
update schedule. One engine for both front ends: the ROS plugin (:mod:`diffbot_sim.plugins.diff_drive`) wraps
it with its topics, the Gymnasium scene (:mod:`diffbot_sim.gym.scene`) with its actions.

What the plugin's UpdateChild does, plus what diff_drive_controller adds for safety: non-finite commands are
refused, stale commands brake when a timeout is set, wheel speeds are capped. Time is passed in (sim
seconds); the simulator alone owns it.
"""
import math

from diffbot_sim.control.command_inbox import CommandInbox
from diffbot_sim.control.kinematics import wheel_speeds
from diffbot_sim.control.limits import ramp, scale_to_limit
from diffbot_sim.control.schedule import next_due

TWIST_FIELDS = ("linear.x", "linear.y", "linear.z", "angular.x", "angular.y", "angular.z")


def non_finite_field(values):
    """Name of the first non-finite value among the six Twist fields (in TWIST_FIELDS order), or None."""
    for name, value in zip(TWIST_FIELDS, values):
        if not math.isfinite(value):
            return name
    return None


class GazeboDiffDriveCore:
    """Turns (v, w) commands into left/right wheel joint velocity targets [rad/s], on the plugin's schedule.

    Args:
        separation: wheel separation [m]. radius: wheel radius [m].
        max_wheel_velocity: cap on each wheel's joint velocity [rad/s] (> 0).
        max_wheel_acceleration: rim acceleration limit [m/s^2]; 0 = none.
        cmd_vel_timeout: seconds after which a command is stale and the wheels brake; 0 = hold forever.
        update_rate: the plugin's ``<updateRate>`` [Hz of sim time]; 0 = every physics step.
        time_step: the physics step [s]: the shortest control period an update is computed over.
        wake: called when a command is put in :attr:`inbox` (the simulator's ``wake.set``); None: nothing.
    """

    def __init__(self, separation, radius, max_wheel_velocity, max_wheel_acceleration=0.0, cmd_vel_timeout=0.0,
                 update_rate=0.0, time_step=0.0, wake=None):
        self.separation = separation
        self.radius = radius
        self.max_wheel_velocity = max_wheel_velocity
        self.max_wheel_acceleration = max_wheel_acceleration
        self.cmd_vel_timeout = cmd_vel_timeout
        self.update_period = 1.0 / update_rate if update_rate > 0 else 0.0
        self.time_step = time_step
        #: (linear.x [m/s], angular.z [rad/s]) commands on their way in; taken by :meth:`before_step`
        self.inbox = CommandInbox(wake)
        self.linear = self.angular = 0.0
        self.stamp = None  # sim time of the last accepted command
        self.targets = (0.0, 0.0)
        self.next_update = 0.0  # sim time of the next scheduled update
        self.last_update = 0.0  # sim time of the last update (its control period ends now)
        self._braking = False  # a stale command stopped the wheels; hold them until a new command

    @property
    def max_linear(self):
        return self.max_wheel_velocity * self.radius

    @property
    def max_angular(self):
        return 2.0 * self.max_linear / self.separation

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

    # -- the plugin's step ---------------------------------------------------------------------------------
    def start(self, now):
        """Updates are scheduled from sim time ``now`` (the loop's start, also after a reset)."""
        self.next_update = now

    def reset(self):
        """The plugin's Reset: command zero, a command not yet taken forgotten (the caller brakes the wheels)."""
        self.brake()
        self.inbox.clear()

    def before_step(self, now, wheels):
        """Everything the plugin does before the physics step at sim time ``now``: a new command from the inbox
        reaches the wheel motors at once; otherwise the wheels are updated when the plugin's update is due, or
        when the command went stale between two updates (the timeout brakes at its step, not at the next
        update); otherwise the motors keep their targets.

        Args:
            wheels: the drive's wheels (:class:`DriveWheels`): read only when there is an update.

        Returns:
            the (linear, angular) command taken from the inbox and applied now, or None.
        """
        command = self.inbox.take()
        applied = command is not None and self.set_command(command[0], command[1], now)
        if not applied and now + 1e-9 < self.next_update:
            expiry = self.expiry()
            if expiry is None or now < expiry:
                return None  # nothing new, nothing due: the motors keep their targets
        left_velocity, right_velocity = wheels.velocities()
        dt = max(now - self.last_update, self.time_step)
        wheels.set(*self.update(now, left_velocity, right_velocity, dt))
        self.last_update = now
        if now + 1e-9 >= self.next_update:
            self.next_update = next_due(self.next_update, self.update_period, now)
        return command if applied else None


class DriveWheels:
    """The drive's wheel joints on a robot body: the mean measured velocity of each side, one velocity target
    per side with the wheels' motor force limits.

    Args:
        robot: the body (``physics.Robot``, or anything with its ``joint_states(indices)`` and
            ``set_velocities(indices, velocities, forces)``).
        left, right: joint indices of the left and right wheels (as many on each side).
        forces: motor force limit [N·m] per wheel, left then right (``config.wheel_efforts``).
    """

    def __init__(self, robot, left, right, forces):
        self.robot, self.left, self.right = robot, list(left), list(right)
        self.indices = self.left + self.right
        self.forces = list(forces)

    def velocities(self):
        """(left, right) mean wheel joint velocity [rad/s]."""
        _, velocities, _ = self.robot.joint_states(self.indices)
        n = len(self.left)
        return sum(velocities[:n]) / n, sum(velocities[n:]) / n

    def set(self, left, right):
        """Velocity targets [rad/s] for every left and every right wheel."""
        n = len(self.left)
        self.robot.set_velocities(self.indices, [left] * n + [right] * n, self.forces)

    def brake(self):
        """Every wheel's target zero (held by its motor)."""
        self.set(0.0, 0.0)
