"""The ROS ``angles`` package (ros/angles, Noetic release 1.9.13, ``angles/include/angles/angles.h``) in
Python: angle normalisation and the shortest angular distance with and without joint limits (rad).

Why a copy of our own: the simulator reproduces C++ consumers of these functions (gazebo_ros_control's
DefaultRobotHWSim, the effort_controllers, joint_trajectory_controller), so the C++ header's floating-point
recipe is what must be matched (``fmod(a + pi, 2 pi)`` in ``normalize_angle``). The Python module that ros/angles
also ships (``angles/__init__.py``) uses Python's ``%`` instead; it is the ROS 2 1.16 port that Debian bookworm
packages as ``python3-angles`` (not installed here, and the PyPI project named ``angles`` is an unrelated
astronomy library). No other maintained Python package provides these functions.

The ``*_with_limits`` functions return ``(ok, value)`` tuples where the C++ returns a bool and writes an output
reference. ``ok`` False still comes with upstream's "coherent" fallback value, as there.
"""
import math

_PI = math.pi
_TWO_PI = 2.0 * math.pi
_fmod = math.fmod


def normalize_angle_positive(angle):
    """``angle`` (rad) wrapped into [0, 2 pi)."""
    result = math.fmod(angle, _TWO_PI)
    if result < 0:
        return result + _TWO_PI
    return result


def normalize_angle(angle):
    """``angle`` (rad) wrapped into (-pi, pi]; -pi maps to +pi, as upstream."""
    result = _fmod(angle + _PI, _TWO_PI)
    if result <= 0.0:
        return result + _PI
    return result - _PI


def shortest_angular_distance(from_angle, to_angle):
    """The rotation (rad, in (-pi, pi]) that takes ``from_angle`` to an angle equivalent to ``to_angle``:
    ``normalize_angle(to_angle - from_angle)``, written out (controllers call it for every joint every step)."""
    result = _fmod(to_angle - from_angle + _PI, _TWO_PI)
    if result <= 0.0:
        return result + _PI
    return result - _PI


def two_pi_complement(angle):
    """The same direction reached the other way round the circle: pi/4 -> -7 pi/4, -pi/4 -> 7 pi/4.

    Upstream quirks kept: inputs outside [-2 pi, 2 pi] are first reduced with ``fmod``; 0 gives +2 pi.
    """
    if angle > _TWO_PI or angle < -_TWO_PI:
        angle = math.fmod(angle, _TWO_PI)
    if angle < 0:
        return _TWO_PI + angle
    if angle > 0:
        return -_TWO_PI + angle
    return _TWO_PI


def find_min_max_delta(from_angle, left_limit, right_limit):
    """``(ok, min_delta, max_delta)``: how far (rad) one can turn from ``from_angle`` before reaching
    ``left_limit`` (negative way) and ``right_limit`` (positive way), limits in [-pi, pi] on the unit circle.

    ``ok`` is False when ``from_angle`` is outside [left_limit, right_limit] (the interval may wrap through pi
    when left > right). Upstream marks this function "internal use"; it is reproduced because
    :func:`shortest_angular_distance_with_limits` depends on its exact results.
    """
    to_left = shortest_angular_distance(from_angle, left_limit)
    to_right = shortest_angular_distance(from_angle, right_limit)
    to_left_other_way = two_pi_complement(to_left)
    to_right_other_way = two_pi_complement(to_right)

    if to_left == 0:
        return True, to_left, max(to_right, to_right_other_way)
    if to_right == 0:
        return True, min(to_left, to_left_other_way), to_right

    delta_min, delta_min_2pi = to_left, to_left_other_way
    if to_left_other_way < delta_min:
        delta_min, delta_min_2pi = to_left_other_way, to_left

    delta_max, delta_max_2pi = to_right, to_right_other_way
    if to_right_other_way > delta_max:
        delta_max, delta_max_2pi = to_right_other_way, to_right

    if delta_min <= delta_max_2pi or delta_max >= delta_min_2pi:
        full_circle = left_limit == -math.pi and right_limit == math.pi
        return full_circle, delta_max_2pi, delta_min_2pi
    return True, delta_min, delta_max


def shortest_angular_distance_with_limits(from_angle, to_angle, left_limit, right_limit):
    """``(ok, shortest)``: the rotation (rad) from ``from_angle`` to ``to_angle`` (modulo 2 pi) that stays within
    [left_limit, right_limit] (limits in [-pi, pi]; left > right means the interval through pi).

    ``ok`` is False when ``from_angle`` or ``to_angle`` is outside the limits; ``shortest`` is then upstream's
    best guess (the direction away from the nearer limit). DefaultRobotHWSim uses this for the POSITION_PID
    error of revolute joints whatever its limits, so for ranges wider than 2 pi it can be off by 2 pi.
    """
    from_ok, min_delta, max_delta = find_min_max_delta(from_angle, left_limit, right_limit)
    delta = shortest_angular_distance(from_angle, to_angle)
    delta_mod_2pi = two_pi_complement(delta)

    if from_ok:
        if min_delta <= delta <= max_delta:
            return True, delta
        if min_delta <= delta_mod_2pi <= max_delta:
            return True, delta_mod_2pi
        # The target is outside the limits: turn towards the limit the target is nearer to.
        _, min_delta_to, max_delta_to = find_min_max_delta(to_angle, left_limit, right_limit)
        if abs(min_delta_to) < abs(max_delta_to):
            return False, max(delta, delta_mod_2pi)
        if abs(min_delta_to) > abs(max_delta_to):
            return False, min(delta, delta_mod_2pi)
        return False, _shorter(delta, delta_mod_2pi)

    # The start is outside the limits (upstream also evaluates the target's deltas here and ignores them).
    if abs(min_delta) < abs(max_delta):
        return False, min(delta, delta_mod_2pi)
    if abs(min_delta) > abs(max_delta):
        return False, max(delta, delta_mod_2pi)
    return False, _shorter(delta, delta_mod_2pi)


def shortest_angular_distance_with_large_limits(from_angle, to_angle, left_limit, right_limit):
    """``(ok, shortest)``: like :func:`shortest_angular_distance_with_limits` for limits that may lie outside
    [-pi, pi] (e.g. [-2 pi, 2 pi]); requires left_limit <= right_limit.

    ``shortest`` is the shorter of the two ways round that keeps ``from_angle + shortest`` within the limits.
    ``ok`` is False when the limits are reversed, ``from_angle`` is outside them, or neither way fits (then
    ``shortest`` is the shorter way regardless). effort_controllers use this for revolute joints.
    """
    delta = shortest_angular_distance(from_angle, to_angle)
    delta_2pi = two_pi_complement(delta)
    if abs(delta) > abs(delta_2pi):
        delta, delta_2pi = delta_2pi, delta

    if left_limit > right_limit:
        return False, delta

    from_inside = left_limit <= from_angle <= right_limit
    if left_limit <= from_angle + delta <= right_limit:
        return from_inside, delta
    if left_limit <= from_angle + delta_2pi <= right_limit:
        return from_inside, delta_2pi
    return False, delta


def _shorter(delta, delta_other_way):
    """Upstream's tie-break: ``delta`` unless the other way is strictly shorter."""
    return delta if abs(delta) < abs(delta_other_way) else delta_other_way
