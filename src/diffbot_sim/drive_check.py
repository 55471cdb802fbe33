"""Judging a drive test: straight at 0.2 m/s for 4 s, then in place at 0.5 rad/s for 4 s (pure).

The fixture-robot rostests (tests/integration/test_real_robot.py) and ``robot_check`` drive a robot the same
way and must agree on what "it drives" means, so the measuring and the tolerances live here once. Poses are
plain ``(x, y, yaw)`` tuples (m, m, rad), taken from the robot's own odometry and from the physics ground
truth at the start and at the end of a motion; nothing here knows ROS messages.
"""
import math
from dataclasses import dataclass, field
from typing import List

SPEED = 0.2  # m/s, the straight run's command
TURN = 0.5  # rad/s, the turn in place's command
SECONDS = 4.0  # s (sim time) of each motion
COMMAND_RATE = 20.0  # Hz (sim time) at which the command is repeated
DISTANCE_TOLERANCE = 0.15  # fraction of SPEED * SECONDS
MAX_HEADING_CHANGE = 0.1  # rad, while driving straight
TURN_TOLERANCE = 0.20  # fraction of TURN * SECONDS, on the robot's own odometry


def yaw_from_quaternion(x, y, z, w):
    """Yaw [rad] of a unit quaternion (rotation about z, as REP 103 robots turn)."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def wrap(angle):
    """``angle`` in (-pi, pi]."""
    return math.atan2(math.sin(angle), math.cos(angle))


def _distance(a, b):
    return math.hypot(b[0] - a[0], b[1] - a[1])


@dataclass
class Straight:
    """The straight run, measured on odometry and ground truth; ``failures`` empty when it passed."""

    expected: float  # m
    odom_distance: float  # m
    truth_distance: float  # m
    odom_heading: float  # rad, absolute heading change
    truth_heading: float  # rad
    failures: List[str] = field(default_factory=list)

    @property
    def passed(self):
        return not self.failures


@dataclass
class Turn:
    """The turn in place; ``failures`` empty when it passed."""

    expected: float  # rad
    odom_yaw: float  # rad, signed
    truth_yaw: float  # rad, signed
    moved: float  # m the ground truth moved while turning
    failures: List[str] = field(default_factory=list)

    @property
    def passed(self):
        return not self.failures


def straight(odom_start, odom_end, truth_start, truth_end, expected=SPEED * SECONDS):
    """Judge the straight run: on odometry and ground truth alike, the distance within DISTANCE_TOLERANCE of
    ``expected`` and the heading changed by less than MAX_HEADING_CHANGE."""
    result = Straight(expected, _distance(odom_start, odom_end), _distance(truth_start, truth_end),
                      abs(wrap(odom_end[2] - odom_start[2])), abs(wrap(truth_end[2] - truth_start[2])))
    low, high = (1.0 - DISTANCE_TOLERANCE) * expected, (1.0 + DISTANCE_TOLERANCE) * expected
    for name, distance, heading in (("odometry", result.odom_distance, result.odom_heading),
                                    ("ground truth", result.truth_distance, result.truth_heading)):
        if not low < distance < high:
            result.failures.append(f"{name}: drove {distance:.3f} m, expected {low:.2f}..{high:.2f} m")
        if not heading < MAX_HEADING_CHANGE:
            result.failures.append(f"{name}: heading changed {heading:.3f} rad (limit {MAX_HEADING_CHANGE} rad)")
    return result


def turn(odom_start, odom_end, truth_start, truth_end, expected=TURN * SECONDS, truth_fraction=None,
         max_moved=None, odom_fraction=1.0 - TURN_TOLERANCE):
    """Judge the turn in place: the odometry's yaw change within TURN_TOLERANCE of ``expected``.

    The ground truth is always measured; it is judged only when asked: ``truth_fraction`` (the body must turn
    the commanded way by at least this fraction of ``expected``) and ``max_moved`` (m). A four-wheel robot
    driven as a diff drive turns its body slower than its wheels say (its wheels slide sideways), which its
    own odometry does not see, so callers choose how much of that they tolerate; an odometry that *is* the
    world pose (gazebo_ros_skid_steer_drive) sees the slide, hence ``odom_fraction`` (the lower bound).
    """
    result = Turn(expected, wrap(odom_end[2] - odom_start[2]), wrap(truth_end[2] - truth_start[2]),
                  _distance(truth_start, truth_end))
    low, high = odom_fraction * expected, (1.0 + TURN_TOLERANCE) * expected
    if not low < result.odom_yaw < high:
        result.failures.append(f"odometry: turned {result.odom_yaw:.3f} rad, expected {low:.2f}..{high:.2f} rad")
    if truth_fraction is not None and not result.truth_yaw > truth_fraction * expected:
        result.failures.append(f"ground truth: turned {result.truth_yaw:.3f} rad, expected more than "
                               f"{truth_fraction * expected:.2f} rad")
    if max_moved is not None and not result.moved < max_moved:
        result.failures.append(f"ground truth: turning in place moved the robot {result.moved:.3f} m "
                               f"(limit {max_moved} m)")
    return result
