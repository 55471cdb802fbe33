"""Speed and acceleration limits for wheel commands (pure), like diff_drive_controller's SpeedLimiter.

Each is a small function of numbers so it can be tested alone; the controller composes them.
"""


def clamp(value, limit):
    """Clamp ``value`` to [-limit, limit]; ``limit`` <= 0 means no limit."""
    if limit <= 0:
        return value
    return max(-limit, min(limit, value))


def scale_to_limit(left, right, limit):
    """Scale a wheel pair by one common factor so neither exceeds ``limit``.

    Scaling both (rather than clamping each) keeps the commanded curvature: a saturated arc stays an arc.
    """
    peak = max(abs(left), abs(right))
    if limit <= 0 or peak <= limit:
        return left, right
    factor = limit / peak
    return left * factor, right * factor


def ramp(current, target, max_delta):
    """Move from ``current`` towards ``target`` by at most ``max_delta`` (<= 0: jump straight to target).

    Gazebo's diff drive ramps each wheel from its *measured* velocity by wheelAcceleration * dt per update.
    """
    if max_delta <= 0:
        return target
    return current + max(-max_delta, min(max_delta, target - current))


class SpeedLimiter:
    """Velocity, acceleration and jerk limits on one command axis, as diff_drive_controller applies them.

    diff_drive_controller keeps one limiter for ``linear/x`` and one for ``angular/z`` and feeds each the new
    command plus the two limited commands before it; reproducing its order (jerk, then acceleration, then
    velocity) matters because each stage works on the output of the previous one.

    Args:
        has_velocity_limits, has_acceleration_limits, has_jerk_limits: enable each stage (all off by default,
            as upstream).
        min_velocity, max_velocity: [m/s or rad/s]. min_acceleration, max_acceleration: [/s]. min_jerk,
            max_jerk: [/s^2]. A ``min_*`` left as None becomes ``-max_*``, the upstream parameter default.
    """

    def __init__(self, has_velocity_limits=False, has_acceleration_limits=False, has_jerk_limits=False,
                 min_velocity=None, max_velocity=0.0, min_acceleration=None, max_acceleration=0.0,
                 min_jerk=None, max_jerk=0.0):
        self.has_velocity_limits = has_velocity_limits
        self.has_acceleration_limits = has_acceleration_limits
        self.has_jerk_limits = has_jerk_limits
        self.max_velocity = max_velocity
        self.min_velocity = -max_velocity if min_velocity is None else min_velocity
        self.max_acceleration = max_acceleration
        self.min_acceleration = -max_acceleration if min_acceleration is None else min_acceleration
        self.max_jerk = max_jerk
        self.min_jerk = -max_jerk if min_jerk is None else min_jerk

    def limit(self, v, v0, v1, dt):
        """Limit the new command ``v`` given the last limited command ``v0`` and the one before, ``v1``.

        Args:
            v: the requested value. v0: the previous (already limited) value. v1: the value before v0.
            dt: the control period [s] (the controller's ``period``, not the command age).

        Returns:
            The limited value.
        """
        v = self.limit_jerk(v, v0, v1, dt)
        v = self.limit_acceleration(v, v0, dt)
        return self.limit_velocity(v)

    def limit_velocity(self, v):
        """Clamp ``v`` to [min_velocity, max_velocity] when velocity limits are on."""
        if not self.has_velocity_limits:
            return v
        return min(max(self.min_velocity, v), self.max_velocity)

    def limit_acceleration(self, v, v0, dt):
        """Clamp the step ``v - v0`` to [min_acceleration, max_acceleration] * dt when acceleration limits are on."""
        if not self.has_acceleration_limits:
            return v
        return v0 + min(max(self.min_acceleration * dt, v - v0), self.max_acceleration * dt)

    def limit_jerk(self, v, v0, v1, dt):
        """Clamp the change of the step, ``(v - v0) - (v0 - v1)``, when jerk limits are on.

        The bounds are ``min_jerk * 2 dt^2`` and ``max_jerk * 2 dt^2``: upstream scales by twice dt squared,
        and we keep that factor so the same YAML ramps up as fast as it does under ros_control.
        """
        if not self.has_jerk_limits:
            return v
        previous_step = v0 - v1
        twice_dt2 = 2.0 * dt * dt
        change = min(max(self.min_jerk * twice_dt2, (v - v0) - previous_step), self.max_jerk * twice_dt2)
        return v0 + previous_step + change
