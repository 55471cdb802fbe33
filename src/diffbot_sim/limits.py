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
