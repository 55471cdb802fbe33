"""gripper_action_controller (ros-controls/ros_controllers noetic-devel 678b92a, 0.21.2), pure: the decisions of
``position_controllers/GripperActionController`` and ``effort_controllers/GripperActionController``.

Read from ``gripper_action_controller/include/gripper_action_controller/``: ``gripper_action_controller_impl.h``
(``init``, ``starting``, ``update``, ``goalCB``, ``cancelCB``, ``checkForSuccess``) and
``hardware_interface_adapter.h`` (what each variant writes to its joint). Reproduced:

* Parameters (:func:`gripper_action_config`): ``joint`` (required), ``goal_tolerance`` 0.01 and ``max_effort``
  0.0 (both taken as absolute values), ``stall_velocity_threshold`` 0.001, ``stall_timeout`` 1.0 s,
  ``action_monitor_rate`` 20 Hz. The effort variant reads its PID from ``gains/<joint>``; without a ``p``
  upstream logs two lines and **loads anyway** (``init`` ignores the adapter's failure) with a PID whose gains
  are all 0, so the gripper never pushes: reproduced, the lines are in ``warnings``.
* Goals are always accepted while the controller runs, never checked or clamped; an active goal is cancelled
  (preempted) first. Cancelling the active goal holds the *current* position with the default max effort.
* Each update: ``error = command_position - position``; the goal check runs **before** the new command is
  computed, so a result's ``effort`` is the command of the *previous* update. Success (``|error| <
  goal_tolerance``) is checked first; only otherwise is the stall checked: ``|velocity| >
  stall_velocity_threshold`` refreshes the last-movement time, else ``now - last_movement > stall_timeout``
  aborts with ``stalled=True``. The last-movement time is also set when a goal arrives and at ``starting``.
* Position variant: the command is the goal position, and the reported "effort" is the goal's ``max_effort``
  as sent (not its absolute value). Effort variant: ``clamp(pid(error, -velocity, dt), +-|max_effort|)``, so
  ``max_effort: 0`` (the default, also after a cancel) gives no force (ros_controllers PR #560 refused to
  change that). ``starting`` resets the PID.
* The command stays applied after a goal ends (success or stall).

Deliberately not reproduced: upstream sends a decided result at the next tick of a ``1/action_monitor_rate``
timer (started when the goal arrived) and fills it with the latest update's values; here the event comes out
of the update that decides it (the rate is kept in the config for a wrapper that wants the delay). A goal
cancelled in that gap is cancelled upstream; here it has already finished. No feedback is published
upstream, nor here.
"""
import math
from collections.abc import Hashable
from dataclasses import dataclass
from typing import NamedTuple

from diffbot_sim.control.pid import Pid, PidGains, no_p_gain_message, pid_gains
from diffbot_sim.errors import ConfigError
from diffbot_sim.values import check_mapping, check_number

POSITION_TYPE = "position_controllers/GripperActionController"
EFFORT_TYPE = "effort_controllers/GripperActionController"
#: controller type -> variant
VARIANTS = {POSITION_TYPE: "position", EFFORT_TYPE: "effort"}

SUCCEEDED = "succeeded"
ABORTED = "aborted"
#: upstream's ROS_ERROR when a goal arrives for a stopped controller (the goal is rejected).
NOT_RUNNING = "Can't accept new action goals. Controller is not running."
NO_GAINS_WARNING = "Failed to initialize PID gains from ROS parameter server."


@dataclass(frozen=True)
class GripperActionConfig:
    """A GripperActionController's parameters, validated, noetic defaults filled in.

    ``variant`` is "position" or "effort"; ``gains`` (effort variant only) is None when ``gains/<joint>/p`` is
    missing, which upstream runs as an all-zero PID. ``warnings`` are ready-to-log lines upstream would log.
    Tolerances and thresholds: m or rad (per s for the velocity); ``max_effort`` N or N·m.
    """

    name: str
    variant: str
    joint: str
    goal_tolerance: float = 0.01
    max_effort: float = 0.0
    stall_velocity_threshold: float = 0.001
    stall_timeout: float = 1.0
    action_monitor_rate: float = 20.0
    gains: PidGains | None = None
    warnings: tuple[str, ...] = ()

    @property
    def action_monitor_period(self):
        """Seconds between upstream's result-publishing timer ticks."""
        return 1.0 / self.action_monitor_rate


def gripper_action_config(params, name, controller_type):
    """Build a :class:`GripperActionConfig` from the controller's parameter dict.

    Args:
        params: the controller namespace as rospy returns it (``rospy.get_param('/gripper_controller')``).
        name: that namespace, e.g. ``/gripper_controller``, to name parameters in errors.
        controller_type: ``position_controllers/GripperActionController`` or
            ``effort_controllers/GripperActionController``.

    Raises:
        ConfigError: naming the full parameter: ``joint`` missing or not a non-empty string (upstream: "Could not
            find joint name on param server", init fails), a number that is not finite, ``action_monitor_rate``
            <= 0 (upstream divides by it), malformed gains; or an unknown ``controller_type``.
    """
    ns = name.rstrip("/")
    if controller_type not in VARIANTS:
        raise ConfigError(f"{ns}/type", controller_type, " or ".join(VARIANTS))
    if not isinstance(params, dict):
        raise ConfigError(ns, params, "a mapping of the GripperActionController's parameters")
    joint = params.get("joint")
    if not isinstance(joint, str) or not joint.strip():
        raise ConfigError(f"{ns}/joint", joint, "the name of the gripper joint")
    joint = joint.strip()

    def number(key, default, **limits):
        return check_number(f"{ns}/{key}", params.get(key, default), **limits)

    variant = VARIANTS[controller_type]
    gains, warnings = None, []
    if variant == "effort":
        gains_ns = f"{ns}/gains/{joint}"
        all_gains = check_mapping(f"{ns}/gains", params.get("gains"), "a mapping of joint name -> PID gains")
        gains = pid_gains(all_gains.get(joint), gains_ns)
        if gains is None:
            warnings += [no_p_gain_message(gains_ns), NO_GAINS_WARNING]
    return GripperActionConfig(
        name=ns, variant=variant, joint=joint,
        goal_tolerance=abs(number("goal_tolerance", 0.01)),
        max_effort=abs(number("max_effort", 0.0)),
        stall_velocity_threshold=number("stall_velocity_threshold", 0.001),
        stall_timeout=number("stall_timeout", 1.0),
        action_monitor_rate=number("action_monitor_rate", 20.0, low=0.0, low_open=True),
        gains=gains, warnings=tuple(warnings))


class GripperResult(NamedTuple):
    """``control_msgs/GripperCommandResult``: position (m or rad), effort (N or N·m), stalled, reached_goal."""

    position: float
    effort: float
    stalled: bool
    reached_goal: bool


class GripperEvent(NamedTuple):
    """A goal that ended in an update: its id, SUCCEEDED or ABORTED, and the result to send."""

    goal_id: Hashable
    outcome: str
    result: GripperResult


class GripperUpdate(NamedTuple):
    """What one update produced.

    ``command``: what to write to the joint's command handle: the commanded position (position variant,
    m or rad) or the effort (effort variant, N or N·m). ``effort``: upstream's "computed command" (the goal's
    max_effort for the position variant, the effort for the effort variant), reported as a later result's
    effort. ``events``: goals that ended in this update.
    """

    command: float
    effort: float
    events: tuple[GripperEvent, ...]


class GripperActionCore:
    """One GripperActionController: goals in, joint commands and goal outcomes out. Time is sim time (s).

    Lifecycle as controller_manager drives it: :meth:`starting`, then :meth:`update` every control period,
    :meth:`goal` / :meth:`cancel` from the action server between updates, :meth:`stopping`.
    """

    def __init__(self, config: GripperActionConfig):
        self.config = config
        self.running = False
        self.command_position = 0.0
        self.command_max_effort = config.max_effort
        self.active_goal = None
        self._computed_command = 0.0  # upstream leaves it uninitialised until the first update
        self._last_movement_time = 0.0
        self._last_position = 0.0
        self._pid = Pid(config.gains or PidGains(p=0.0)) if config.variant == "effort" else None

    def starting(self, time, position):
        """Start holding ``position`` (the joint's current one) with the default max effort."""
        self.command_position = position
        self.command_max_effort = self.config.max_effort
        self._last_position = position
        self._last_movement_time = time
        if self._pid is not None:
            self._pid.reset()
        self.running = True

    def stopping(self, time):
        """Stop; returns the id of the goal this cancels (upstream marks it canceled), or None."""
        self.running = False
        return self._preempt()

    def goal(self, goal_id, position, max_effort, time):
        """Accept a goal (``command.position``, ``command.max_effort``) arriving at ``time``.

        Returns:
            the id of the goal it preempts (to be marked canceled), or None.

        Raises:
            RuntimeError: with :data:`NOT_RUNNING`, when the controller is not running (upstream rejects the goal).
        """
        if not self.running:
            raise RuntimeError(NOT_RUNNING)
        preempted = self._preempt()
        self.command_position = position
        self.command_max_effort = max_effort
        self._last_movement_time = time
        self.active_goal = goal_id
        return preempted

    def cancel(self, goal_id, time, position=None):
        """A cancel request for ``goal_id``. Only the active goal is cancelled: the gripper then holds
        ``position`` (default: the last measured one) with the default max effort.

        Returns:
            True when ``goal_id`` was the active goal (to be marked canceled), else False (nothing changes).
        """
        if self.active_goal is None or self.active_goal != goal_id:
            return False
        self.active_goal = None
        self.command_position = self._last_position if position is None else position
        self.command_max_effort = self.config.max_effort
        return True

    def update(self, time, period, position, velocity):
        """One control period: check the active goal, then compute the joint command.

        Args:
            time: sim time (s). period: seconds since the last update. position: joint position (m or rad).
            velocity: joint velocity (m/s or rad/s).
        """
        if not self.running:
            raise RuntimeError("update() of a GripperActionController that is not running")
        self._last_position = position
        error = self.command_position - position
        event = self._check_goal(time, error, position, velocity)
        if self._pid is None:
            command = self.command_position
            self._computed_command = self.command_max_effort
        else:
            limit = abs(self.command_max_effort)
            effort = self._pid.compute(error, period, error_dot=-velocity)
            command = self._computed_command = min(limit, max(-limit, effort))
        return GripperUpdate(command, self._computed_command, (event,) if event else ())

    def _check_goal(self, time, error, position, velocity):
        """``checkForSuccess``: success first; the stall is only looked at while the goal is not reached."""
        if self.active_goal is None:
            return None
        if abs(error) < self.config.goal_tolerance:
            return self._finish(SUCCEEDED, GripperResult(position, self._computed_command, False, True))
        if abs(velocity) > self.config.stall_velocity_threshold:
            self._last_movement_time = time
        elif time - self._last_movement_time > self.config.stall_timeout:
            return self._finish(ABORTED, GripperResult(position, self._computed_command, True, False))
        return None

    def _finish(self, outcome, result):
        goal_id, self.active_goal = self.active_goal, None
        return GripperEvent(goal_id, outcome, result)

    def _preempt(self):
        goal_id, self.active_goal = self.active_goal, None
        return goal_id


def is_finite_goal(position, max_effort):
    """Whether a goal's numbers are finite. Upstream accepts anything; a NaN position makes every error NaN,
    so such a goal never succeeds and only ends by stalling: a wrapper may warn about it."""
    return math.isfinite(position) and math.isfinite(max_effort)
