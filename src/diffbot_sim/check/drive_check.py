"""Judging a drive test by the body: at rest first, then straight at 0.2 m/s for 4 s, sideways at 0.2 m/s for 4 s
(holonomic bases only) and in place at 0.5 rad/s for 4 s (pure).

The fixture-robot rostests (tests/integration/test_real_robot.py) and ``robot_check`` drive a robot the same
way and must agree on what "it drives" means, so the measuring and the tolerances live here once. The body is
judged on the physics ground truth: before driving it rests upright at the height its geometry rests at on
flat ground (:func:`rest`), while driving it stays there (:func:`ride`), and it moves and turns as commanded
(:func:`straight`, :func:`strafe`, :func:`turn`; the motions: :func:`runs`). The robot's own odometry is a
second, separate claim, checked against the command too: a ros_control robot's odometry integrates its wheel
encoders and reads a perfect drive while the body flies, sinks or slides. Motion poses are plain ``(x, y, yaw)``
tuples (m, m, rad) at the start and at the end of a motion; body samples are :class:`BodySample` tuples; nothing
here knows ROS messages.
"""
import math
import statistics
from dataclasses import dataclass, field
from typing import NamedTuple

from diffbot_sim.transforms import (
    roll_pitch_from_quaternion,
    wrap_angle as wrap,  # drive_check.wrap: callers' name for it
    yaw_from_quaternion,
)

SPEED = 0.2  # m/s, the straight run's command
TURN = 0.5  # rad/s, the turn in place's command
SECONDS = 4.0  # s (sim time) of each motion
COMMAND_RATE = 20.0  # Hz (sim time) at which the command is repeated
DISTANCE_TOLERANCE = 0.15  # fraction of SPEED * SECONDS
MAX_HEADING_CHANGE = 0.1  # rad, while driving straight
TURN_TOLERANCE = 0.20  # fraction of TURN * SECONDS, on the robot's own odometry
HEIGHT_TOLERANCE = 0.02  # m: the resting body vs. its geometry's rest height, and the body while driving
MAX_TILT = 0.1  # rad (5.7 degrees) between the body's z axis and the world's, at rest and while driving
REST_SPEED = 0.02  # m/s: the fastest the body's origin may move over a rest
TRUTH_TURN_FRACTION = 0.5  # of TURN * SECONDS: the least the body itself must turn in place
SKID_TURN_FRACTION = 0.25  # the same for a skid-steered body (more than one wheel a side: its wheels slide)
MAX_TURN_DRIFT = 0.1  # m the body's origin may move while turning in place
#: fraction of the command: how closely a base whose plugin imposes its velocity (planar_move, the force-based
#: move family) follows it, straight, sideways and turning, by ground truth (the fixtures planar_steered_casters and
#: force_based_mecanum reach it)
HOLONOMIC_TOLERANCE = 0.05
#: Plugins (bullet_sim's ``~plugins`` names them) that move a body sideways too, so its drive test strafes.
HOLONOMIC_PLUGINS = ("libgazebo_ros_planar_move.so", "libgazebo_ros_force_based_move.so",
                     "libridgeback_ros_force_based_move.so", "libnexus_ros_force_based_move.so")


class Run(NamedTuple):
    """One judged motion: a Twist (linear.x, linear.y [m/s], angular.z [rad/s]) repeated at COMMAND_RATE for
    ``seconds`` of sim time."""

    name: str
    linear_x: float
    linear_y: float
    angular_z: float
    seconds: float


STRAIGHT_RUN = Run("straight", SPEED, 0.0, 0.0, SECONDS)
STRAFE_RUN = Run("sideways", 0.0, SPEED, 0.0, SECONDS)  # to the robot's left (REP 103: +y)
TURN_RUN = Run("turn", 0.0, 0.0, TURN, SECONDS)
#: The motions of a drive test, in order: a holonomic base strafes between the straight run and the turn.
RUNS = (STRAIGHT_RUN, TURN_RUN)
HOLONOMIC_RUNS = (STRAIGHT_RUN, STRAFE_RUN, TURN_RUN)


def holonomic(plugins):
    """True when one of ``plugins`` (filenames: a list, or bullet_sim's comma-separated ``~plugins``) moves
    the body sideways (HOLONOMIC_PLUGINS)."""
    names = plugins.split(",") if isinstance(plugins, str) else plugins
    return any(name.strip() in HOLONOMIC_PLUGINS for name in names)


def runs(is_holonomic):
    """The motions to drive: HOLONOMIC_RUNS for a holonomic base, else RUNS."""
    return HOLONOMIC_RUNS if is_holonomic else RUNS


class BodySample(NamedTuple):
    """The ground-truth pose of the robot's root link at sim time ``t``: position [m] and roll, pitch, yaw
    [rad] (REP 103)."""

    t: float
    x: float
    y: float
    z: float
    roll: float
    pitch: float
    yaw: float

    @property
    def tilt(self):
        """Angle [rad] between the body's z axis and the world's (0 upright, pi upside down)."""
        return math.acos(max(-1.0, min(1.0, math.cos(self.roll) * math.cos(self.pitch))))


def body_sample(t, position, quaternion):
    """A :class:`BodySample` from a position (x, y, z) and a quaternion (x, y, z, w)."""
    roll, pitch = roll_pitch_from_quaternion(*quaternion)
    return BodySample(t, position[0], position[1], position[2], roll, pitch, yaw_from_quaternion(*quaternion))


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
    failures: list[str] = field(default_factory=list)

    @property
    def passed(self):
        return not self.failures


@dataclass
class Turn:
    """The turn in place; ``failures`` empty when it passed."""

    expected: float  # rad
    odom_yaw: float  # rad, signed
    truth_yaw: float  # rad, signed
    moved: float  # m the point the body turns about (the middle of its drive wheels) moved while turning
    failures: list[str] = field(default_factory=list)

    @property
    def passed(self):
        return not self.failures


def straight(odom_start, odom_end, truth_start, truth_end, expected=SPEED * SECONDS, tolerance=DISTANCE_TOLERANCE):
    """Judge the straight run: on odometry and ground truth alike, the distance within ``tolerance`` (a
    fraction) of ``expected`` and the heading changed by less than MAX_HEADING_CHANGE."""
    result = Straight(expected, _distance(odom_start, odom_end), _distance(truth_start, truth_end),
                      abs(wrap(odom_end[2] - odom_start[2])), abs(wrap(truth_end[2] - truth_start[2])))
    low, high = (1.0 - tolerance) * expected, (1.0 + tolerance) * expected
    for name, distance, heading in (("odometry", result.odom_distance, result.odom_heading),
                                    ("ground truth", result.truth_distance, result.truth_heading)):
        if not low < distance < high:
            result.failures.append(f"{name}: drove {distance:.3f} m, expected {low:.2f}..{high:.2f} m")
        if not heading < MAX_HEADING_CHANGE:
            result.failures.append(f"{name}: heading changed {heading:.3f} rad (limit {MAX_HEADING_CHANGE} rad)")
    return result


@dataclass
class Strafe:
    """The sideways run, measured on odometry and ground truth in the axes of the robot's heading at its
    start; ``failures`` empty when it passed."""

    expected: float  # m to the left
    odom_left: float  # m along the start heading's +y
    truth_left: float
    odom_forward: float  # m along the start heading's +x (drift)
    truth_forward: float
    odom_heading: float  # rad, absolute heading change
    truth_heading: float
    failures: list[str] = field(default_factory=list)

    @property
    def passed(self):
        return not self.failures


def sideways(start, end):
    """(left, forward) [m]: how far ``end`` is from ``start`` (x, y, yaw poses) along the start heading's +y
    and +x."""
    dx, dy = end[0] - start[0], end[1] - start[1]
    c, s = math.cos(start[2]), math.sin(start[2])
    return -s * dx + c * dy, c * dx + s * dy


def strafe(odom_start, odom_end, truth_start, truth_end, expected=SPEED * SECONDS, tolerance=DISTANCE_TOLERANCE):
    """Judge the sideways run (STRAFE_RUN): on odometry and ground truth alike, the distance to the robot's left
    within ``tolerance`` (a fraction) of ``expected``, the drift along its heading under ``tolerance`` times
    ``expected``, and the heading changed by less than MAX_HEADING_CHANGE."""
    odom_left, odom_forward = sideways(odom_start, odom_end)
    truth_left, truth_forward = sideways(truth_start, truth_end)
    result = Strafe(expected, odom_left, truth_left, odom_forward, truth_forward,
                    abs(wrap(odom_end[2] - odom_start[2])), abs(wrap(truth_end[2] - truth_start[2])))
    low, high, drift = (1.0 - tolerance) * expected, (1.0 + tolerance) * expected, tolerance * expected
    for name, left, forward, heading in (("odometry", odom_left, odom_forward, result.odom_heading),
                                         ("ground truth", truth_left, truth_forward, result.truth_heading)):
        if not low < left < high:
            result.failures.append(f"{name}: moved {left:.3f} m to the left, expected {low:.2f}..{high:.2f} m")
        if not abs(forward) < drift:
            result.failures.append(f"{name}: drifted {forward:.3f} m along its heading while moving sideways "
                                   f"(limit {drift:.2f} m)")
        if not heading < MAX_HEADING_CHANGE:
            result.failures.append(f"{name}: heading changed {heading:.3f} rad (limit {MAX_HEADING_CHANGE} rad)")
    return result


def skid_turn_drift(half_length, half_width, angle):
    """How far [m] the middle of a skid-steered wheel set may move turning ``angle`` [rad] in place: with more
    than one wheel a side, the wheels slide, and Coulomb friction puts the centre of rotation where the loads
    balance, anywhere inside the wheel footprint (2 ``half_length`` by 2 ``half_width``, m): a body whose mass
    sits off its centre turns about a point off its centre (measured: 8.5 cm to one side moved the middle
    0.36 m in a 1.6 rad turn). The bound is the chord of the farthest such centre, never less than
    MAX_TURN_DRIFT."""
    radius = math.hypot(half_length, half_width)
    return max(MAX_TURN_DRIFT, 2.0 * radius * math.sin(min(abs(angle), math.pi) / 2.0))


def centre_of(pose, centre):
    """Where the point ``centre`` (x, y) of the body frame is in the world when the body is at ``pose``."""
    x, y, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    return x + c * centre[0] - s * centre[1], y + s * centre[0] + c * centre[1]


def turn(odom_start, odom_end, truth_start, truth_end, expected=TURN * SECONDS, truth_fraction=TRUTH_TURN_FRACTION,
         max_moved=MAX_TURN_DRIFT, odom_fraction=1.0 - TURN_TOLERANCE, centre=(0.0, 0.0), tolerance=TURN_TOLERANCE):
    """Judge the turn in place: the ground truth turns the commanded way by at least ``truth_fraction`` of
    ``expected`` and at most ``tolerance`` (a fraction) over it, and the point it turns about, ``centre``
    (x, y) [m] in the root link's frame (the middle of the drive wheels: a base_link ahead of or behind the
    axle circles it), moves less than ``max_moved`` [m]; the odometry's yaw change is within
    ``odom_fraction``..1 + ``tolerance`` of ``expected``.

    A four-wheel robot driven as a diff drive turns its body slower than its wheels say (its wheels slide
    sideways), which its own odometry does not see, so callers may lower ``truth_fraction`` for it (skid
    steering turns at about 0.75 of the command); an odometry that *is* the world pose
    (gazebo_ros_skid_steer_drive) sees the slide, hence ``odom_fraction`` (the lower bound).
    """
    result = Turn(expected, wrap(odom_end[2] - odom_start[2]), wrap(truth_end[2] - truth_start[2]),
                  _distance(centre_of(truth_start, centre), centre_of(truth_end, centre)))
    high = (1.0 + tolerance) * expected
    low = odom_fraction * expected
    if not low < result.odom_yaw < high:
        result.failures.append(f"odometry: turned {result.odom_yaw:.3f} rad, expected {low:.2f}..{high:.2f} rad")
    if not truth_fraction * expected < result.truth_yaw < high:
        result.failures.append(f"ground truth: turned {result.truth_yaw:.3f} rad, expected "
                               f"{truth_fraction * expected:.2f}..{high:.2f} rad")
    if not result.moved < max_moved:
        result.failures.append(f"ground truth: turning in place moved the robot {result.moved:.3f} m "
                               f"(limit {max_moved} m)")
    return result


@dataclass
class Rest:
    """The body before driving, judged on ground-truth samples over a span of rest; ``failures`` empty when
    it rests upright where its geometry says it should."""

    expected: float | None  # m, the root link's height when the robot stands on flat ground (None: unknown)
    height: float  # m, the median height of the root link over the samples
    tilt: float  # rad, the largest tilt
    spread: float  # m, highest minus lowest height (a bouncing or sinking body)
    speed: float  # m/s, how fast the origin moved over the span, on average
    failures: list[str] = field(default_factory=list)

    @property
    def passed(self):
        return not self.failures


def rest(samples, expected=None):
    """Judge the body at rest (no command): upright (tilt below MAX_TILT), its height steady (within
    HEIGHT_TOLERANCE over the span) and within HEIGHT_TOLERANCE of ``expected`` when given, and still (its
    origin slower than REST_SPEED). A robot thrown into the air at spawn, sunk into the ground or lying on its
    side fails here, before any motion is judged."""
    if not samples:
        return Rest(expected, math.nan, math.nan, math.nan, math.nan, ["ground truth: no samples at rest"])
    heights = [s.z for s in samples]
    first, last = samples[0], samples[-1]
    span = last.t - first.t
    travel = math.dist((first.x, first.y, first.z), (last.x, last.y, last.z))
    result = Rest(expected, statistics.median(heights), max(s.tilt for s in samples), max(heights) - min(heights),
                  travel / span if span > 0 else 0.0)
    if not result.tilt < MAX_TILT:
        result.failures.append(f"ground truth: tilted {result.tilt:.3f} rad at rest (limit {MAX_TILT} rad)")
    if expected is not None and not abs(result.height - expected) < HEIGHT_TOLERANCE:
        result.failures.append(f"ground truth: rests at height {result.height:.3f} m, its geometry rests at "
                               f"{expected:.3f} m (tolerance {HEIGHT_TOLERANCE} m)")
    if not result.spread < HEIGHT_TOLERANCE:
        result.failures.append(f"ground truth: height varied {result.spread:.3f} m at rest "
                               f"({min(heights):.3f}..{max(heights):.3f} m)")
    if not result.speed < REST_SPEED:
        result.failures.append(f"ground truth: moved {travel:.3f} m in {span:.2f} s at rest")
    return result


@dataclass
class Ride:
    """The body while driving: how far its height left the rest height and how far it tilted."""

    height: float  # m, the rest height it is held to
    low: float  # m, lowest height while driving
    high: float  # m, highest
    tilt: float  # rad, the largest tilt
    failures: list[str] = field(default_factory=list)

    @property
    def passed(self):
        return not self.failures


def ride(samples, height, what="driving"):
    """Judge the body during a motion: it stays within HEIGHT_TOLERANCE of ``height`` (its rest height: no
    flying, no sinking) and upright (tilt below MAX_TILT)."""
    if not samples:
        return Ride(height, math.nan, math.nan, math.nan, [f"ground truth: no samples while {what}"])
    result = Ride(height, min(s.z for s in samples), max(s.z for s in samples), max(s.tilt for s in samples))
    if not (abs(result.low - height) < HEIGHT_TOLERANCE and abs(result.high - height) < HEIGHT_TOLERANCE):
        result.failures.append(f"ground truth: height {result.low:.3f}..{result.high:.3f} m while {what}, rest "
                               f"height {height:.3f} m (tolerance {HEIGHT_TOLERANCE} m)")
    if not result.tilt < MAX_TILT:
        result.failures.append(f"ground truth: tilted {result.tilt:.3f} rad while {what} (limit {MAX_TILT} rad)")
    return result
