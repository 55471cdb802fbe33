"""joint_trajectory_controller's trajectories (ros_controllers 0.21.2, noetic-devel 678b92a), pure.

What a Gazebo user's arm does after a ``FollowJointTrajectory`` goal or a ``command`` message is decided by
how the JointTrajectoryController turns the message into per-joint spline segments and merges them with
what it is already executing. This module reproduces that, read from
``joint_trajectory_controller/include/``:

- ``trajectory_interface/quintic_spline_segment.h``: one segment, linear / cubic / quintic according to the
  fields present in *both* endpoints; sampled outside its span it gives the end point with zero velocity and
  acceleration (``sampleWithTimeBounds``).
- ``trajectory_interface/trajectory_interface.h``: ``findSegment`` (the last segment starting at or before
  a time) and ``sample`` (before the first segment: the first one's start, not "found").
- ``joint_trajectory_controller/init_joint_trajectory.h`` + ``joint_trajectory_msg_utils.h`` +
  ``joint_trajectory_segment.h``: ``initJointTrajectory``, here :func:`merge_trajectory`, with upstream's
  checks in upstream's order and its error texts, the bridge segment and ``wraparoundJointOffset``.
- ``hold_trajectory_builder.h`` / ``stop_trajectory_builder.h``: :func:`hold_trajectory`.
- ``tolerances.h``: :class:`StateTolerances` and :func:`resolve_goal_tolerances` (``updateSegmentTolerances``).

A trajectory is a tuple with one tuple of :class:`Segment` per controller joint (upstream's
``std::vector<std::vector<Segment>>``); times are in the controller's internal time base ("uptime", s).
Each segment carries its owner (the action goal id, or None for topic commands and holds) and the
tolerances checked while that goal is active.
"""
import bisect
import dataclasses
import math
from collections.abc import Hashable, Sequence
from dataclasses import dataclass
from typing import NamedTuple

from diffbot_sim.control.angles import shortest_angular_distance

# Upstream's error texts (the action result's error_string, or the ROS_ERROR of a refused command).
EMPTY_TRAJECTORY = "Trajectory message contains empty trajectory. Nothing to convert."
NOT_INCREASING = "Trajectory message contains waypoints that are not strictly increasing in time."
WRONG_JOINTS = "Cannot create trajectory from message. It does not contain the expected joints."
SIZE_MISMATCH = "Size mismatch in trajectory point position, velocity or acceleration data."
WRAP_SIZE_MISMATCH = "Size mismatch between trajectory point and vector specifying whether joints wrap around."
FROM_MESSAGE = "Can't construct segment from ROS message: "
START_END_MISMATCH = "Start/end points data size mismatch."
NO_CURRENT_SEGMENTS = ("Unexpected error: Could not find segments in current trajectory. "
                       "Please contact the package maintainer.")
_SPLINE = "Quintic spline segment can't be constructed: "
END_BEFORE_START = _SPLINE + "end_time < start_time."
EMPTY_POSITIONS = _SPLINE + "Endpoint positions can't be empty."


def to_ns(seconds):
    """Seconds as whole nanoseconds, the resolution of ros::Time / ros::Duration (and of Gazebo's clock)."""
    return round(float(seconds) * 1e9)


def to_sec(nanoseconds):
    """``ros::Time::toSec()`` / ``ros::Duration::toSec()``: sec + 1e-9 * nsec with nsec in [0, 1e9)."""
    sec, nsec = divmod(int(nanoseconds), 1_000_000_000)
    return float(sec) + 1e-9 * float(nsec)


class TrajectoryError(ValueError):
    """A trajectory message the controller refuses; ``str()`` is upstream's error text."""


class JointSample(NamedTuple):
    """One joint's desired state at a time: rad or m, per s, per s²."""

    position: float
    velocity: float
    acceleration: float


@dataclass(frozen=True)
class TrajectoryPoint:
    """A ``trajectory_msgs/JointTrajectoryPoint`` as plain data (``effort`` is ignored upstream, so absent).

    An empty sequence means "not given", as in the message; ``time_from_start`` is in s.
    """

    positions: Sequence[float] = ()
    velocities: Sequence[float] = ()
    accelerations: Sequence[float] = ()
    time_from_start: float = 0.0


@dataclass(frozen=True)
class StateTolerances:
    """Allowed |error| of position, velocity and acceleration; 0 (or less) means "not checked"."""

    position: float = 0.0
    velocity: float = 0.0
    acceleration: float = 0.0

    def violated(self, position_error, velocity_error, acceleration_error=0.0):
        """True when a checked component's |error| exceeds its tolerance (``checkStateTolerancePerJoint``)."""
        return (0.0 < self.position < abs(position_error) or 0.0 < self.velocity < abs(velocity_error)
                or 0.0 < self.acceleration < abs(acceleration_error))


@dataclass(frozen=True)
class SegmentTolerances:
    """One joint's tolerances for a goal's segments: along the path, at the goal, and the extra time (s)
    after the last segment's end allowed to get inside ``goal`` (``SegmentTolerancesPerJoint``)."""

    path: StateTolerances = StateTolerances()
    goal: StateTolerances = StateTolerances()
    goal_time: float = 0.0


NO_TOLERANCES = SegmentTolerances()


@dataclass(frozen=True)
class SplineState:
    """A segment end point; velocity/acceleration None when the point does not give them."""

    position: float
    velocity: float | None = None
    acceleration: float | None = None
    time_from_start: float = 0.0


def _coefficients(start, end, duration):
    """Polynomial coefficients c0..c5 for the richest spline both ends support (upstream's formulas)."""
    p0, p1, T = start.position, end.position, duration
    if start.velocity is None or end.velocity is None:  # linear
        return (p0, 0.0 if T == 0.0 else (p1 - p0) / T, 0.0, 0.0, 0.0, 0.0)
    v0, v1 = start.velocity, end.velocity
    if start.acceleration is None or end.acceleration is None:  # cubic
        if T == 0.0:
            return (p0, v0, 0.0, 0.0, 0.0, 0.0)
        return (p0, v0, (-3.0 * p0 + 3.0 * p1 - 2.0 * v0 * T - v1 * T) / T ** 2,
                (2.0 * p0 - 2.0 * p1 + v0 * T + v1 * T) / T ** 3, 0.0, 0.0)
    a0, a1 = start.acceleration, end.acceleration  # quintic
    if T == 0.0:
        return (p0, v0, 0.5 * a0, 0.0, 0.0, 0.0)
    T2 = T * T
    return (p0, v0, 0.5 * a0,
            (-20.0 * p0 + 20.0 * p1 - 3.0 * a0 * T2 + a1 * T2 - 12.0 * v0 * T - 8.0 * v1 * T) / (2.0 * T ** 3),
            (30.0 * p0 - 30.0 * p1 + 3.0 * a0 * T2 - 2.0 * a1 * T2 + 16.0 * v0 * T + 14.0 * v1 * T) / (2.0 * T ** 4),
            (-12.0 * p0 + 12.0 * p1 - a0 * T2 + a1 * T2 - 6.0 * v0 * T - 6.0 * v1 * T) / (2.0 * T ** 5))


def _polynomial_values(c, t):
    """(position, velocity, acceleration) of the polynomial ``c`` at ``t``: a plain tuple."""
    position = c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * (c[4] + t * c[5]))))
    velocity = c[1] + t * (2.0 * c[2] + t * (3.0 * c[3] + t * (4.0 * c[4] + t * 5.0 * c[5])))
    acceleration = 2.0 * c[2] + t * (6.0 * c[3] + t * (12.0 * c[4] + t * 20.0 * c[5]))
    return position, velocity, acceleration


def _polynomial(c, t):
    return JointSample(*_polynomial_values(c, t))


@dataclass(frozen=True)
class Segment:
    """One joint's spline between two times (s, controller time base), with its owner and tolerances.

    ``time_from_start`` is the start point's ``time_from_start`` (0 for bridges and holds, as upstream),
    reported in the ``state`` topic's ``desired.time_from_start``.
    """

    start_time: float
    duration: float
    coefficients: tuple[float, ...]
    time_from_start: float = 0.0
    owner: Hashable | None = None
    tolerances: SegmentTolerances = NO_TOLERANCES

    @classmethod
    def spline(cls, start_time, start, end_time, end, owner=None, tolerances=NO_TOLERANCES):
        """The segment from ``start`` (a :class:`SplineState`) at ``start_time`` to ``end`` at ``end_time``.

        Raises:
            TrajectoryError: ``end_time < start_time``, or an end point without a position.
        """
        if end_time < start_time:
            raise TrajectoryError(END_BEFORE_START)
        if start.position is None or end.position is None:
            raise TrajectoryError(EMPTY_POSITIONS)
        duration = end_time - start_time
        return cls(start_time, duration, _coefficients(start, end, duration), start.time_from_start, owner,
                   tolerances)

    @property
    def end_time(self):
        return self.start_time + self.duration

    def sample(self, time):
        """The state at ``time``; before the start or after the end: that end's position, at rest."""
        return JointSample(*self.values(time))

    def values(self, time):
        """:meth:`sample` as a plain (position, velocity, acceleration) tuple (the controller's every update)."""
        t = time - self.start_time
        if t < 0.0:
            return self.coefficients[0], 0.0, 0.0
        if t > self.duration:
            return _polynomial_values(self.coefficients, self.duration)[0], 0.0, 0.0
        return _polynomial_values(self.coefficients, t)

    def owned_by(self, owner):
        return dataclasses.replace(self, owner=owner)


def find_segment(segments, time):
    """Index of the segment in charge at ``time`` (the last one starting at or before it), or None when
    ``time`` precedes them all (``findSegment``)."""
    if not segments or time < segments[0].start_time:
        return None
    return bisect.bisect_right(segments, time, key=lambda segment: segment.start_time) - 1


def sample(segments, time):
    """``(index or None, JointSample)``: the segment in charge at ``time`` and its state; before the first
    segment the index is None and the state is the first segment's start, at rest (upstream's ``sample``)."""
    index = find_segment(segments, time)
    if index is not None:
        return index, segments[index].sample(time)
    return None, segments[0].sample(time)


def wraparound_offset(previous, following, wraps):
    """The multiple of 2π to add to ``following`` so that a continuous joint moves the short way round from
    ``previous``; 0 for other joints (``wraparoundJointOffset``). A half-turn tie goes the way ``following``
    lies numerically."""
    if not wraps:
        return 0.0
    distance = shortest_angular_distance(previous, following)
    if abs(abs(distance) - math.pi) < 1e-9:
        distance = abs(distance) if following > previous else -abs(distance)
    return (previous + distance) - following


def hold_trajectory(start_time, positions, velocities, stop_duration, owner=None):
    """The trajectory that stops the joints (``setHoldPosition``'s builders), one segment per joint.

    ``stop_duration == 0`` (HoldTrajectoryBuilder): a zero-length segment at ``positions`` (upstream reads
    the measured positions), at rest. ``> 0`` (StopTrajectoryBuilder): from ``positions``/``velocities`` (the
    last desired state) to where a (p, v) → (p, −v) quintic of twice that length is at its midpoint, i.e. a
    stop after ``stop_duration`` s. Hold segments carry no tolerances.
    """
    trajectory = []
    for position, velocity in zip(positions, velocities):
        if stop_duration == 0.0:
            still = SplineState(position, 0.0, 0.0)
            trajectory.append((Segment.spline(start_time, still, start_time, still, owner),))
            continue
        start = SplineState(position, velocity, 0.0)
        there_and_back = Segment.spline(start_time, start, start_time + 2.0 * stop_duration,
                                        SplineState(position, -velocity, 0.0))
        stop = there_and_back.sample(start_time + stop_duration)
        trajectory.append((Segment.spline(start_time, start, start_time + stop_duration, SplineState(*stop),
                                          owner),))
    return tuple(trajectory)


def resolve_goal_tolerances(defaults, joint_names, path_tolerances=(), goal_tolerances=(), goal_time_tolerance=0.0):
    """Per-joint tolerances of a goal: ``defaults`` overridden by the goal's own (``updateSegmentTolerances``).

    ``path_tolerances``/``goal_tolerances`` hold ``(name, position, velocity, acceleration)`` entries (a
    mapping name → (p, v, a) also works), applied in order: > 0 replaces, < 0 disables (0), 0 keeps the
    default. ``goal_time_tolerance`` (s): > 0 replaces, < 0 sets 0, 0 keeps the default.
    """
    path_entries, goal_entries = _entries(path_tolerances), _entries(goal_tolerances)
    result = []
    for name, default in zip(joint_names, defaults):
        path, goal = default.path, default.goal
        for entry_name, *values in path_entries:
            if entry_name == name:
                path = _override(path, values)
        for entry_name, *values in goal_entries:
            if entry_name == name:
                goal = _override(goal, values)
        goal_time = default.goal_time
        if goal_time_tolerance < 0.0:
            goal_time = 0.0
        elif goal_time_tolerance > 0.0:
            goal_time = float(goal_time_tolerance)
        result.append(SegmentTolerances(path, goal, goal_time))
    return tuple(result)


def _entries(tolerances):
    if hasattr(tolerances, "items"):
        return [(name, *values) for name, values in tolerances.items()]
    return [tuple(entry) for entry in tolerances]


def _override(tolerances, values):
    fields = []
    for current, wanted in zip((tolerances.position, tolerances.velocity, tolerances.acceleration), values):
        fields.append(float(wanted) if wanted > 0.0 else 0.0 if wanted < 0.0 else current)
    return StateTolerances(*fields)


def joint_mapping(message_joints, controller_joints):
    """Controller index of each message joint, or None when the message names more joints than the
    controller has, none at all, or one it does not have (``internal::mapping``)."""
    if not message_joints or len(message_joints) > len(controller_joints):
        return None
    try:
        return [list(controller_joints).index(name) for name in message_joints]
    except ValueError:
        return None


class _Point(NamedTuple):
    """A message point with its time_from_start in ns."""

    point: object
    offset_ns: int

    @property
    def positions(self):
        return self.point.positions

    @property
    def velocities(self):
        return self.point.velocities

    @property
    def accelerations(self):
        return self.point.accelerations


class MergeResult(NamedTuple):
    """The trajectory to execute, and upstream's ROS_WARN about dropped points (None if silent)."""

    trajectory: tuple
    warning: str | None


def merge_trajectory(current, joint_names, wraparound, message_joints, points, stamp_ns, now_ns, now_uptime_ns,
                     owner=None, tolerances=None, allow_partial_joints_goal=False):
    """The trajectory that replaces ``current`` after a message (``initJointTrajectory``).

    Args:
        current: the trajectory being executed (one tuple of segments per controller joint), or () for none.
        joint_names, wraparound: the controller's joints and whether each is continuous.
        message_joints, points: the message's ``joint_names`` and points (objects with ``positions``,
            ``velocities``, ``accelerations``, ``time_from_start``).
        stamp_ns: the message's ``header.stamp`` (ns); 0 means "start at the next update".
        now_ns, now_uptime_ns: the next control update, in message time and in the controller's time base
            (ns: upstream does this arithmetic on ros::Time; segment times are then its ``toSec()``).
        owner: the goal id the new segments belong to (None for a topic command).
        tolerances: per controller joint, the :class:`SegmentTolerances` of the new segments (goals only).

    The result keeps, for each joint in the message, the current segments from the one in charge at ``now``
    until the new start, then a bridge from the current trajectory's state at ``max(start, now)`` to the
    first point after ``now``, then the segments between the message's points. Joints not in the message
    (partial goals) keep their trajectory, its segments from ``now`` on handed to ``owner``.

    Raises:
        TrajectoryError: upstream's reason for refusing the message.
    """
    if not points:
        raise TrajectoryError(EMPTY_TRAJECTORY)
    offsets_ns = [to_ns(point.time_from_start) for point in points]
    if any(a >= b for a, b in zip(offsets_ns, offsets_ns[1:])):
        raise TrajectoryError(NOT_INCREASING)
    if not allow_partial_joints_goal and len(message_joints) != len(joint_names):
        raise TrajectoryError(WRONG_JOINTS)
    mapping = joint_mapping(message_joints, joint_names)
    if mapping is None:
        raise TrajectoryError(WRONG_JOINTS)
    start_ns = now_ns if stamp_ns == 0 else stamp_ns
    start_uptime_ns = now_uptime_ns + (start_ns - now_ns)
    first, warning = _first_future_point(offsets_ns, stamp_ns, start_ns, now_ns)
    kept = [_Point(point, offset) for point, offset in zip(points[first:], offsets_ns[first:])]
    now_uptime = to_sec(now_uptime_ns)
    result = [list(segments) for segments in current]
    for segments in result:  # every joint's remaining segments now belong to the new owner
        active = find_segment(segments, now_uptime)
        if active is not None:
            segments[active:] = [segment.owned_by(owner) for segment in segments[active:]]
    if not result:
        result = [[] for _ in joint_names]
    joint_tolerances = tolerances if tolerances is not None else (NO_TOLERANCES,) * len(joint_names)
    for column, joint in enumerate(mapping):
        _check_sizes(kept[0], len(message_joints))
        segments, offset = [], 0.0
        if current:
            segments, offset = _keep_and_bridge(current[joint], wraparound[joint], kept[0], column,
                                                start_uptime_ns, now_uptime, owner, joint_tolerances[joint])
        for a, b in zip(kept, kept[1:]):
            _check_sizes(a, len(message_joints))
            _check_sizes(b, len(message_joints))
            segments.append(_message_segment(start_uptime_ns, a, b, column, offset, owner, joint_tolerances[joint]))
        if segments:
            result[joint] = segments
    if not any(result):
        return MergeResult((), warning)
    return MergeResult(tuple(tuple(segments) for segments in result), warning)


def _first_future_point(offsets_ns, stamp_ns, start_ns, now_ns):
    """Index of the first point due after ``now_ns`` and upstream's warning about the dropped ones.

    Raises:
        TrajectoryError: every point is due at or before ``now_ns``.
    """
    count = len(offsets_ns)
    past = sum(1 for offset in offsets_ns if not now_ns < start_ns + offset)
    if past == 0:
        return 0, None
    if past == count:
        late = to_sec(now_ns - (start_ns + offsets_ns[-1]))
        raise TrajectoryError(f"Dropping all {count} trajectory point(s), as they occur before the "
                              f"current time.\nLast point is {late:f}s in the past.")
    if past == 1 and offsets_ns[0] == 0 and stamp_ns == 0:
        return 1, None  # a leading "current state" point at t=0: dropped silently
    due_in = to_sec(start_ns + offsets_ns[past] - now_ns)
    return past, (f"Dropping first {past} trajectory point(s) out of {count}, as they occur before the "
                  f"current time.\nFirst valid point will be reached in {due_in:.3f}s.")


def _check_sizes(point, joint_count):
    """Upstream's ``isValid``: velocities/accelerations, when given, as many as positions. Also refused here:
    given fields shorter than the message's joints (upstream reads past their end)."""
    size = len(point.positions)
    for values in (point.positions, point.velocities, point.accelerations):
        if values and (len(values) != size or len(values) < joint_count):
            raise TrajectoryError(SIZE_MISMATCH)


def _joint_state(point, column, offset):
    """The column's values of ``point`` as a SplineState, ``offset`` added to the position.

    Raises:
        TrajectoryError: the point has no positions (upstream: its offset vector has the wrong size).
    """
    if not point.positions:
        raise TrajectoryError(WRAP_SIZE_MISMATCH)
    velocity = float(point.velocities[column]) if point.velocities else None
    acceleration = float(point.accelerations[column]) if point.accelerations else None
    return SplineState(float(point.positions[column]) + offset, velocity, acceleration, to_sec(point.offset_ns))


def _keep_and_bridge(segments, wraps, first_point, column, start_uptime_ns, now_uptime, owner, tolerances):
    """The current segments still to run before the new start, plus the bridge to ``first_point``; and
    the wraparound offset for all the new points of this joint."""
    bridge_time = max(to_sec(start_uptime_ns), now_uptime)
    _, bridge_from = sample(segments, bridge_time)
    if not first_point.positions:
        raise TrajectoryError(WRAP_SIZE_MISMATCH)
    offset = wraparound_offset(bridge_from.position, float(first_point.positions[column]), wraps)
    target = _joint_state(first_point, column, offset)
    active, last = find_segment(segments, now_uptime), find_segment(segments, bridge_time)
    if active is None or last is None:
        raise TrajectoryError(NO_CURRENT_SEGMENTS)
    bridge_end = to_sec(start_uptime_ns) + to_sec(first_point.offset_ns)  # a sum of doubles, as upstream
    bridge = Segment.spline(bridge_time, SplineState(*bridge_from), bridge_end, target, owner, tolerances)
    return list(segments[active:last + 1]) + [bridge], offset


def _message_segment(start_uptime_ns, a, b, column, offset, owner, tolerances):
    """The segment between two consecutive message points (``JointTrajectorySegment``'s message form)."""
    if bool(a.positions) != bool(b.positions):
        raise TrajectoryError(FROM_MESSAGE + START_END_MISMATCH)
    try:
        segment = Segment.spline(to_sec(start_uptime_ns + a.offset_ns), _joint_state(a, column, offset),
                                 to_sec(start_uptime_ns + b.offset_ns), _joint_state(b, column, offset), owner,
                                 tolerances)
    except TrajectoryError as err:
        raise TrajectoryError(FROM_MESSAGE + str(err)) from None
    return segment
