"""ros_controllers' joint_trajectory_controller (0.21.2, noetic-devel 678b92a) as a pure per-update core.

Arm setups made for Gazebo + gazebo_ros_control load ``{position,velocity,effort}_controllers/
JointTrajectoryController`` from their YAML and drive it with MoveIt (``follow_joint_trajectory`` action) or
``command`` messages. This module reproduces what the controller does with them, read from
``joint_trajectory_controller_impl.h``, ``hardware_interface_adapter.h`` and ``tolerances.h``:

- :class:`JtcConfig` (:mod:`diffbot_sim.control.joint_trajectory_config`): ``init()``'s parameters with their
  defaults, checked once.
- :class:`JointTrajectoryControllerCore`: ``starting`` (hold at the measured state), ``update`` (sample the
  trajectory at the controller's uptime, check the active goal's path/goal tolerances, compute the
  hardware command, decide whether ``state`` is due), ``goal`` / ``cancel`` (``goalCB`` / ``cancelCB`` with
  control_msgs' error codes), ``command`` (the topic), ``query_state`` (the service), ``stopping``.

Trajectory building and merging live in :mod:`diffbot_sim.control.trajectory`. The ROS side (messages, the
action server and its ``action_monitor_rate`` timer, publishing) belongs to the caller, which passes sim
time in float seconds and the joints' measured positions (rad or m) and velocities.

Upstream's time base: the controller keeps an "uptime" (0 at ``starting``, + ``period`` each update). A
message is read against the *next* update (last update's time + period), whatever the time it arrives, so
the ``time`` arguments of ``goal``/``command``/``cancel``/``stopping`` do not move anything (kept for the
caller's symmetry); ``query_state``'s ``time`` is the requested sample time.
"""
import bisect
import math
from collections.abc import Hashable
from typing import NamedTuple

from diffbot_sim.control.joint_trajectory_config import JtcConfig
from diffbot_sim.control.pid import Pid
from diffbot_sim.control.trajectory import (
    TrajectoryError,
    hold_trajectory,
    joint_mapping,
    merge_trajectory,
    resolve_goal_tolerances,
    sample,
    to_ns,
    to_sec,
)
from diffbot_sim.errors import DiffbotSimError

_PI, _TWO_PI = math.pi, 2.0 * math.pi
_fmod, _bisect_right = math.fmod, bisect.bisect_right
_tuple_new = tuple.__new__

# control_msgs/FollowJointTrajectoryResult error codes.
SUCCESSFUL = 0
INVALID_GOAL = -1
INVALID_JOINTS = -2
OLD_HEADER_TIMESTAMP = -3  # never returned by this controller (a past trajectory is INVALID_GOAL)
PATH_TOLERANCE_VIOLATED = -4
GOAL_TOLERANCE_VIOLATED = -5

NOT_RUNNING = "Can't accept new commands. Controller is not running."
GOAL_NOT_RUNNING = "Can't accept new action goals. Controller is not running."
GOAL_WRONG_JOINTS = "Joints on incoming goal don't match the controller joints."


class ControllerCrash(DiffbotSimError):
    """Upstream would crash the controller manager's process here (Gazebo dies); the message says why."""


class TrajectoryState(NamedTuple):
    """Per-joint values as in ``control_msgs/JointTrajectoryControllerState``'s desired/actual/error.

    ``actual`` and ``error`` accelerations are 0 (upstream has no measured acceleration and does not publish
    them); ``time_from_start`` is in s.
    """

    positions: tuple[float, ...]
    velocities: tuple[float, ...]
    accelerations: tuple[float, ...]
    time_from_start: float


class GoalEvent(NamedTuple):
    """A goal that ended: ``outcome`` is "SUCCEEDED", "ABORTED" (with its code and upstream's
    ``error_string``) or "PREEMPTED" (upstream's ``setCanceled`` of an active goal; empty result)."""

    goal_id: Hashable
    outcome: str
    error_code: int
    error_string: str


class JtcUpdate(NamedTuple):
    """One control update's result.

    ``commands`` go to the joints (position variants: desired positions; velocity/effort: the PID output),
    or None when upstream sends nothing this cycle. ``feedback_goal_id`` is the goal whose feedback
    (desired/actual/error) upstream sets this update (published at ``action_monitor_rate``); ``state_due``
    says whether to publish ``state`` now.
    """

    commands: tuple[float, ...] | None
    desired: TrajectoryState
    actual: TrajectoryState
    error: TrajectoryState
    events: tuple[GoalEvent, ...]
    state_due: bool
    feedback_goal_id: Hashable | None


class GoalAnswer(NamedTuple):
    """``goalCB``'s decision: accepted, or rejected with a control_msgs code and ``error_string`` (upstream
    leaves it empty for rejections other than INVALID_GOAL from the trajectory). ``preempted_goal_id`` is the
    previous goal, now canceled (status PREEMPTED)."""

    accepted: bool
    error_code: int
    error_string: str
    preempted_goal_id: Hashable | None = None


class JointTrajectoryControllerCore:
    """One JointTrajectoryController: trajectory, active goal and command computation.

    Call ``starting`` when the controller starts, ``update`` every control cycle, the other methods when
    messages arrive. ``take_log()`` hands over the lines upstream would log (level, text).
    """

    def __init__(self, cfg: JtcConfig):
        self.cfg = cfg
        n = len(cfg.joints)
        self._pids = [Pid(gains) for gains in cfg.gains] if cfg.variant != "position" else []
        self._running = False
        # Upstream's TimeData, in ns as ros::Time: last update's time and period, and the uptime.
        self._time_ns = self._period_ns = self._uptime_ns = 0
        self._set_trajectory(())
        self._zeros = (0.0,) * n
        self._state_period_ns = to_ns(1.0 / cfg.state_publish_rate) if cfg.state_publish_rate else None
        self._active_goal = None
        self._done: set[str] = set()  # joints inside the goal tolerance; upstream's successful_joint_traj_
        self._desired = ([0.0] * n, [0.0] * n, [0.0] * n)
        self._measured = ([0.0] * n, [0.0] * n)
        self._last_state_publish_ns = 0
        self._pending: list[GoalEvent] = []  # goals preempted by a topic command, reported by the next update
        self._log = list(cfg.log)

    def _set_trajectory(self, trajectory):
        """The trajectory to follow, with each joint's segment start times (``findSegment``'s bisection)."""
        self._trajectory = trajectory
        self._starts = [[segment.start_time for segment in segments] for segments in trajectory]

    @property
    def active_goal(self):
        """The goal id being executed, or None."""
        return self._active_goal

    @property
    def running(self):
        return self._running

    def take_log(self):
        """The ``(level, text)`` lines upstream would have logged since the last call."""
        lines, self._log = self._log, []
        return lines

    def starting(self, time, positions, velocities):
        """Start: hold the measured state; return the adapter's first commands (measured positions, or 0).

        Raises:
            ControllerCrash: a closed-loop variant without gains (upstream crashes here or at the first update).
        """
        if self.cfg.start_crash:
            raise ControllerCrash(self.cfg.start_crash)
        self._time_ns, self._period_ns, self._uptime_ns = to_ns(time), 0, 0
        self._measure(positions, velocities)
        self._desired = (list(self._measured[0]), list(self._measured[1]), self._desired[2])
        self._running = True
        self._hold(self._uptime_ns)
        self._last_state_publish_ns = self._uptime_ns
        for pid in self._pids:
            pid.reset()
        if self.cfg.variant == "position":
            return tuple(self._measured[0])
        return (0.0,) * len(self.cfg.joints)

    def stopping(self, time=None):
        """Stop: the active goal is canceled (PREEMPTED). Returns the goals to report as preempted."""
        self._running = False
        preempted = self._preempt_active_goal()
        if preempted is not None:
            self._pending.append(GoalEvent(preempted, "PREEMPTED", SUCCESSFUL, ""))
        events, self._pending = tuple(self._pending), []
        return events

    def update(self, time, period, positions, velocities):
        """One control cycle at sim ``time`` (s), ``period`` (s) after the last, with the measured joints.

        Returns:
            JtcUpdate.
        """
        if not self._running:
            raise RuntimeError("JointTrajectoryControllerCore.update() before starting()")
        self._time_ns, self._period_ns = to_ns(time), to_ns(period)
        self._uptime_ns += self._period_ns
        self._measure(positions, velocities)
        indexes, desired, actual, error = self._update_states()
        events, self._pending = self._pending, []
        if None in indexes:  # unreachable while uptime grows: upstream returns
            self._log.append(("error", "Unexpected error: No trajectory defined at current time. "
                                       "Please contact the package maintainer."))
            return JtcUpdate(None, desired, actual, error, tuple(events), False, None)
        events.extend(self._check_tolerances(indexes, error))
        if self._active_goal is not None and len(self._done) == len(self.cfg.joints):
            events.append(GoalEvent(self._active_goal, "SUCCEEDED", SUCCESSFUL, ""))
            self._active_goal = None
            self._done.clear()
        commands = self._commands(desired, error)
        return _tuple_new(JtcUpdate, (commands, desired, actual, error, tuple(events), self._state_due(),
                                      self._active_goal))

    def _measure(self, positions, velocities):
        """Keep the joints' measured positions and velocities (one per controller joint, in its order)."""
        if len(positions) != len(self.cfg.joints) or len(velocities) != len(self.cfg.joints):
            raise ValueError(f"{self.cfg.name}: expected positions and velocities of {len(self.cfg.joints)} "
                             f"joints {self.cfg.joints}, got {len(positions)} and {len(velocities)}")
        self._measured = (list(map(float, positions)), list(map(float, velocities)))

    def _update_states(self):
        """``updateStates``: desired from the trajectory at the uptime, errors with the angular distance
        (for every joint type, as upstream), time_from_start from the first joint's segment.

        It runs at every update of every joint (every physics step for the effort variant), so the sampling
        (``trajectory.sample``: the last segment starting at or before the uptime, or the first) and
        ``shortest_angular_distance`` are written out here with the same arithmetic."""
        uptime = to_sec(self._uptime_ns)
        positions, velocities = self._measured
        indexes, desired_p, desired_v, desired_a, error_p, error_v = [], [], [], [], [], []
        for segments, starts, position, velocity in zip(self._trajectory, self._starts, positions, velocities):
            if uptime < starts[0]:
                index = None
                p, v, a = segments[0].values(uptime)
            else:
                index = _bisect_right(starts, uptime) - 1
                p, v, a = segments[index].values(uptime)
            indexes.append(index)
            desired_p.append(p)
            desired_v.append(v)
            desired_a.append(a)
            delta = _fmod(p - position + _PI, _TWO_PI)
            error_p.append(delta + _PI if delta <= 0.0 else delta - _PI)
            error_v.append(v - velocity)
        self._desired = (desired_p, desired_v, desired_a)
        first = self._trajectory[0][indexes[0] if indexes[0] is not None else 0]
        actual_tfs = uptime - first.start_time + first.time_from_start
        zeros = self._zeros  # TrajectoryStates made by tuple.__new__: the named constructor's frame costs more
        desired = _tuple_new(TrajectoryState, (tuple(desired_p), tuple(desired_v), tuple(desired_a),
                                               first.time_from_start))
        actual = _tuple_new(TrajectoryState, (tuple(positions), tuple(velocities), zeros, actual_tfs))
        error = _tuple_new(TrajectoryState, (tuple(error_p), tuple(error_v), zeros,
                                             first.time_from_start - actual_tfs))
        return indexes, desired, actual, error

    def _check_tolerances(self, indexes, error):
        """Path tolerances while a segment of the active goal runs, goal tolerances once its last segment
        has ended (with ``goal_time`` of grace). Returns the abort, if any."""
        goal = self._active_goal
        if goal is None:  # only the active goal's segments are checked
            return []
        uptime = to_sec(self._uptime_ns)
        for joint, (segments, index) in enumerate(zip(self._trajectory, indexes)):
            segment = segments[index]
            if segment.owner != goal:
                continue
            tolerances = segment.tolerances
            position_error, velocity_error = error.positions[joint], error.velocities[joint]
            name = self.cfg.joints[joint]
            if uptime < segment.end_time:
                if tolerances.path.violated(position_error, velocity_error):
                    return [self._abort(PATH_TOLERANCE_VIOLATED, f"{name} path error {position_error:f}")]
            elif index == len(segments) - 1:
                if not tolerances.goal.violated(position_error, velocity_error):
                    self._done.add(joint)
                elif uptime >= segment.end_time + tolerances.goal_time:
                    return [self._abort(GOAL_TOLERANCE_VIOLATED, f"{name} goal error {position_error:f}")]
        return []

    def _abort(self, code, text):
        event = GoalEvent(self._active_goal, "ABORTED", code, text)
        self._active_goal = None
        self._done.clear()
        return event

    def _commands(self, desired, error):
        """The hardware adapter's ``updateCommand``."""
        if self.cfg.variant == "position":
            return desired.positions
        period = to_sec(self._period_ns)
        return tuple([ff * velocity + pid.compute(position_error, period, velocity_error)
                      for ff, velocity, pid, position_error, velocity_error
                      in zip(self.cfg.velocity_ff, desired.velocities, self._pids, error.positions,
                             error.velocities)])

    def _state_due(self):
        """``publishState``: due once more than a publish period has passed since the last slot."""
        period_ns = self._state_period_ns
        if period_ns is None:
            period_ns = to_ns(1.0 / self.cfg.state_publish_rate)
        if self._last_state_publish_ns + period_ns < self._uptime_ns:
            self._last_state_publish_ns += period_ns
            return True
        return False

    def _hold(self, start_uptime_ns, owner=None):
        """``setHoldPosition``: stop at the measured positions, or ramp down from the desired state."""
        if self.cfg.stop_trajectory_duration == 0.0:
            positions, velocities = self._measured
        else:
            positions, velocities = self._desired[0], self._desired[1]
        self._set_trajectory(hold_trajectory(to_sec(start_uptime_ns), positions, velocities,
                                             self.cfg.stop_trajectory_duration, owner))

    def _preempt_active_goal(self):
        goal, self._active_goal = self._active_goal, None
        return goal

    def _update_trajectory(self, joint_names, points, stamp, owner, tolerances):
        """``updateTrajectoryCommand``: None when the trajectory was replaced, else upstream's reason."""
        if not self._running:
            self._log.append(("error", NOT_RUNNING))
            return NOT_RUNNING
        if not points:
            self._hold(self._uptime_ns, owner)
            return None
        try:
            next_update_ns, next_uptime_ns = self._time_ns + self._period_ns, self._uptime_ns + self._period_ns
            merged = merge_trajectory(
                self._trajectory, self.cfg.joints, self.cfg.wraparound, list(joint_names), list(points),
                to_ns(stamp), next_update_ns, next_uptime_ns, owner, tolerances, self.cfg.allow_partial_joints_goal)
        except TrajectoryError as err:
            self._log.append(("warn" if str(err).startswith("Dropping all") else "error", str(err)))
            return str(err)
        if merged.warning:
            self._log.append(("warn", merged.warning))
        if not merged.trajectory:
            return ""
        self._set_trajectory(merged.trajectory)
        return None

    def goal(self, goal_id, joint_names, points, stamp=0.0, path_tolerances=(), goal_tolerances=(),
             goal_time_tolerance=0.0, time=None):
        """A ``follow_joint_trajectory`` goal (``goalCB``).

        ``points``: objects with ``positions``, ``velocities``, ``accelerations``, ``time_from_start`` (s);
        ``stamp``: the trajectory's header stamp (s, 0 = next update); tolerances: ``(name, position,
        velocity, acceleration)`` entries or a mapping name → (p, v, a); ``goal_time_tolerance`` in s.
        """
        if not self._running:
            self._log.append(("error", GOAL_NOT_RUNNING))
            return GoalAnswer(False, INVALID_GOAL, "")
        joint_names = list(joint_names)
        if (not self.cfg.allow_partial_joints_goal and len(joint_names) != len(self.cfg.joints)) \
                or joint_mapping(joint_names, self.cfg.joints) is None:
            self._log.append(("error", GOAL_WRONG_JOINTS))
            return GoalAnswer(False, INVALID_JOINTS, "")
        tolerances = resolve_goal_tolerances(self.cfg.default_tolerances, self.cfg.joints, path_tolerances,
                                             goal_tolerances, goal_time_tolerance)
        reason = self._update_trajectory(joint_names, points, stamp, goal_id, tolerances)
        if reason is not None:
            return GoalAnswer(False, INVALID_GOAL, reason)
        preempted = self._preempt_active_goal()
        self._active_goal = goal_id
        return GoalAnswer(True, SUCCESSFUL, "", preempted)

    def command(self, joint_names, points, stamp=0.0, time=None):
        """A ``command`` topic message: None when executed (an active goal is then preempted, reported by
        the next update), else upstream's reason."""
        reason = self._update_trajectory(joint_names, points, stamp, None, None)
        if reason is None:
            preempted = self._preempt_active_goal()
            if preempted is not None:
                self._pending.append(GoalEvent(preempted, "PREEMPTED", SUCCESSFUL, ""))
        return reason

    def cancel(self, goal_id, time=None):
        """``cancelCB``: hold if ``goal_id`` is the active goal (the caller then sets it canceled)."""
        if self._active_goal is None or self._active_goal != goal_id:
            return False
        self._active_goal = None
        self._hold(self._uptime_ns)
        return True

    def query_state(self, time):
        """``query_state``: the trajectory's (positions, velocities, accelerations) at sim ``time`` (s), or
        None when the controller is not running or ``time`` precedes the trajectory."""
        if not self._running:
            self._log.append(("error", "Can't sample trajectory. Controller is not running."))
            return None
        sample_time = to_sec(self._uptime_ns + (to_ns(time) - self._time_ns))
        states = []
        for segments in self._trajectory:
            index, state = sample(segments, sample_time)
            if index is None:
                self._log.append(("error", "Requested sample time precedes trajectory start time."))
                return None
            states.append(state)
        return tuple(tuple(values) for values in zip(*states))
