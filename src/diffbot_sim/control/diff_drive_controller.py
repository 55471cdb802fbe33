"""ros_controllers' diff_drive_controller/DiffDriveController (noetic), as a pure per-update core.

Robots built for Gazebo + gazebo_ros_control load a DiffDriveController from their YAML; to run them
unchanged the simulator must move the wheels and integrate odometry the way the controller does. This module
holds that logic with time passed in as float seconds: ``DiffDriveControllerCore`` runs one control cycle per
``update`` on a ``DiffDriveControllerConfig`` that
:func:`diffbot_sim.control.diff_drive_config.diff_drive_controller_config` checked.
Publishing odom, TF and ``cmd_vel_out`` and reading the URDF for missing geometry belong to the caller.
"""
import math
from typing import NamedTuple

from diffbot_sim.control.kinematics import wheel_speeds
from diffbot_sim.control.odometry import EncoderOdometry
from diffbot_sim.errors import ConfigError


class DiffDriveControllerStep(NamedTuple):
    """What one ``DiffDriveControllerCore.update`` asks of the caller.

    Attributes:
        left: velocity command [rad/s] for every left wheel joint. right: the same for the right joints.
        publish_odom: publish odom (and TF when enabled) now, stamped with this update's time.
        skipped: a wheel position was not finite, so upstream's update returned early: odometry is frozen,
            nothing is published (``cmd_vel_out`` included) and the wheels keep their previous commands,
            which ``left``/``right`` repeat.
    """

    left: float
    right: float
    publish_odom: bool
    skipped: bool = False


class DiffDriveControllerCore:
    """One DiffDriveController, minus ROS: commands and wheel positions in, wheel commands and odometry out.

    Call ``starting(now)`` once (the controller manager does upstream), then ``update`` every control
    cycle and ``set_command`` whenever a ``cmd_vel`` message arrives.

    Args:
        config: a ``DiffDriveControllerConfig``.
        wheel_separation, wheel_radius: m, measured from the URDF by the caller; used only where the config
            leaves the parameter unset (an explicit parameter wins, as upstream).

    Raises:
        ConfigError: separation or radius is neither in the config nor given (or is not > 0).
    """

    def __init__(self, config, wheel_separation=None, wheel_radius=None):
        self.config = config
        separation = config.wheel_separation if config.wheel_separation is not None else wheel_separation
        radius = config.wheel_radius if config.wheel_radius is not None else wheel_radius
        for key, value in (("wheel_separation", separation), ("wheel_radius", radius)):
            if value is None or isinstance(value, bool) or not isinstance(value, (int, float)) \
                    or not math.isfinite(value) or value <= 0:
                raise ConfigError(f"{config.name}/{key}", value,
                                  "a number > 0, in the parameter or measurable from the URDF")
        # Effective geometry, multipliers applied once: both odometry and inverse kinematics use it, so a
        # multiplier that is wrong for the real robot still gives self-consistent commands and odometry.
        self.separation = config.wheel_separation_multiplier * separation
        self.left_radius = config.left_wheel_radius_multiplier * radius
        self.right_radius = config.right_wheel_radius_multiplier * radius
        self.odometry = EncoderOdometry(self.left_radius, self.separation,
                                        velocity_window=config.velocity_rolling_window_size,
                                        right_wheel_radius=self.right_radius)
        self.linear_limiter = config.linear.limiter()
        self.angular_limiter = config.angular.limiter()
        self.running = False
        self._command = (0.0, 0.0, None)  # linear, angular, receipt time (None: never received)
        self._last0 = (0.0, 0.0)  # the last limited command
        self._last1 = (0.0, 0.0)  # the one before it (the jerk limiter needs both)
        self._wheels = (0.0, 0.0)
        self._last_publish_ns = None
        period = config.publish_period
        self._publish_period_ns = None if math.isinf(period) else _ns(period)
        self._previous_time = None

    # -- lifecycle ------------------------------------------------------------------------------------

    def starting(self, now):
        """Start at sim time ``now`` [s]: brake, restart the publish schedule and the odometry's dt."""
        self.running = True
        self.brake()
        self._last_publish_ns = _ns(now)
        self._previous_time = now
        self.odometry.restart(now)

    def stopping(self, now=None):
        """Stop: brake and refuse commands until ``starting`` again. ``now`` is unused, as upstream."""
        self.running = False
        self.brake()

    def brake(self):
        """Zero both wheel commands (until the next ``update`` computes new ones)."""
        self._wheels = (0.0, 0.0)

    # -- input ----------------------------------------------------------------------------------------

    def set_command(self, linear, angular, now, num_publishers=1):
        """Take a ``cmd_vel`` (``linear.x`` [m/s], ``angular.z`` [rad/s]) received at sim time ``now``.

        Args:
            linear, angular: the Twist fields DDC reads. now: receipt time [s], what the timeout is measured
                from. num_publishers: publishers on the subscriber's topic when the message arrived.

        Returns:
            None when accepted, otherwise the reason it was refused, for a throttled log. Refusals match
            upstream: not running; more than one publisher while ``allow_multiple_cmd_vel_publishers`` is
            false (brakes, but keeps the stored command, so an earlier one still runs until its timeout);
            a NaN or infinite value.
        """
        if not self.running:
            return "Can't accept new commands. Controller is not running."
        if not self.config.allow_multiple_cmd_vel_publishers and num_publishers > 1:
            self.brake()
            return f"Detected {num_publishers} publishers. Only 1 publisher is allowed. Going to brake."
        if not (math.isfinite(linear) and math.isfinite(angular)):
            return "Received NaN in velocity command. Ignoring."
        self._command = (float(linear), float(angular), now)
        return None

    # -- control cycle --------------------------------------------------------------------------------

    def update(self, now, left_positions=None, right_positions=None, period=None):
        """Run one control cycle at sim time ``now`` [s].

        Order as upstream: odometry (closed loop from the mean of each side's joint angles, or open loop
        from the last limited command); the publish decision; the command, zeroed when older than
        ``cmd_vel_timeout``; the speed limiters (``period`` as dt); inverse kinematics.

        Args:
            now: sim time [s].
            left_positions, right_positions: joint angles [rad], one per configured joint (a bare float is
                taken as a one-element list); ignored with ``open_loop``.
            period: the control period [s]; default: time since the previous ``update`` (or ``starting``).

        Returns:
            DiffDriveControllerStep.

        Raises:
            RuntimeError: called before ``starting``. ValueError: not one position per configured joint
                (closed loop only).
        """
        if not self.running:
            raise RuntimeError("DiffDriveControllerCore.update() before starting()")
        if period is None:
            period = now - self._previous_time
        self._previous_time = now

        # COMPUTE ODOMETRY
        if self.config.open_loop:
            self.odometry.update_open_loop(self._last0[0], self._last0[1], now)
        else:
            left = _mean(left_positions, len(self.config.left_wheels), "left_positions")
            right = _mean(right_positions, len(self.config.right_wheels), "right_positions")
            if not (math.isfinite(left) and math.isfinite(right)):
                return DiffDriveControllerStep(self._wheels[0], self._wheels[1], False, True)
            self.odometry.update(left, right, now)

        # Fixed rate on upstream's integer-nanosecond clock (float sums of 0.02 would jitter by a cycle);
        # the schedule advances by whole periods, so a late cycle does not shift later publications.
        period_ns = self._publish_period_ns
        publish = period_ns is not None and self._last_publish_ns + period_ns < _ns(now)
        if publish:
            self._last_publish_ns += period_ns

        # MOVE ROBOT
        linear, angular, stamp = self._command
        if stamp is None or now - stamp > self.config.cmd_vel_timeout:
            linear = angular = 0.0
        linear = self.linear_limiter.limit(linear, self._last0[0], self._last1[0], period)
        angular = self.angular_limiter.limit(angular, self._last0[1], self._last1[1], period)
        self._last1, self._last0 = self._last0, (linear, angular)

        rim_left, rim_right = wheel_speeds(linear, angular, self.separation)
        self._wheels = (rim_left / self.left_radius, rim_right / self.right_radius)
        return DiffDriveControllerStep(self._wheels[0], self._wheels[1], publish, False)

    # -- state ----------------------------------------------------------------------------------------

    @property
    def pose(self):
        """Odometry pose (x [m], y [m], yaw [rad]) in the odom frame; yaw is not wrapped, as upstream."""
        return self.odometry.x, self.odometry.y, self.odometry.yaw

    @property
    def velocity(self):
        """Odometry body velocity (linear [m/s], angular [rad/s]): rolling mean, or the command if open loop."""
        return self.odometry.linear, self.odometry.angular

    @property
    def last_command(self):
        """The last limited command (linear [m/s], angular [rad/s]): what ``cmd_vel_out`` carries."""
        return self._last0

    @property
    def wheel_commands(self):
        """The current (left, right) wheel command [rad/s]."""
        return self._wheels

    def joint_commands(self):
        """Every wheel joint name mapped to its current velocity command [rad/s]."""
        commands = {name: self._wheels[0] for name in self.config.left_wheels}
        commands.update({name: self._wheels[1] for name in self.config.right_wheels})
        return commands


# -- helpers --------------------------------------------------------------------------------------------

def _ns(seconds):
    """Seconds as integer nanoseconds, rounded as ros::Time/ros::Duration do."""
    return int(round(seconds * 1e9))


def _mean(positions, count, label):
    """Mean joint angle of one side; NaN/inf pass through so the caller can freeze odometry."""
    if isinstance(positions, (int, float)) and not isinstance(positions, bool):
        positions = (positions,)
    if positions is None or len(positions) != count:
        raise ValueError(f"{label}: expected {count} joint position(s), got {positions!r}")
    return sum(positions) / count
