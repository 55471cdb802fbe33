"""ros_control's joint_limits_interface as gazebo_ros_control's DefaultRobotHWSim registers and enforces it.

Sources: ros-controls/ros_control noetic-devel (633c374) ``joint_limits_interface/include/joint_limits_interface/``
``joint_limits.h`` (the two structs), ``joint_limits_urdf.h`` (getJointLimits / getSoftJointLimits from a URDF
joint), ``joint_limits_rosparam.h`` (getJointLimits from ``joint_limits/<joint>/``), ``joint_limits_interface.h``
(the six handles); ros-simulation/gazebo_ros_pkgs noetic-devel ``default_robot_hw_sim.cpp``
(``registerJointLimits``). Units: positions rad (prismatic m), velocities rad/s (m/s), efforts N·m (N), s.

Reproduced:

* URDF: only a joint with ``<limit>`` gets limits; revolute/prismatic get position limits, continuous
  ``angle_wraparound``; velocity and effort limits always, acceleration never. Soft limits come only from
  ``<safety_controller>`` (HWSim does not read rosparam soft limits).
* Rosparam overrides, flag by flag, as getJointLimits(name, nh): ``has_X: false`` clears a limit;
  ``has_X: true`` sets it only together with its value(s); ``angle_wraparound`` is read only when
  ``has_position_limits`` is false. A joint without limits from either source gets no handle.
* HWSim's choice (:func:`make_limit_handle`, :func:`register_joint_limits`): soft limits -> the interface's
  SoftLimits handle, else its Saturation handle; the handle constructors' refusals (missing velocity or effort
  limits) raise :class:`JointLimitsInterfaceError` with upstream's message.
* The handles' ``enforceLimits`` formulas exactly, including their state: the position handles remember the last
  command (seeded from the measured position at their first enforcement, and again after a NaN command or
  reset); VelocityJointSaturation remembers its last command from 0.

Not reproduced: the strict rosparam type rules of roscpp that silently ignore a wrongly typed value (here a
wrongly typed value raises ConfigError); MoveIt's other joint_limits keys. A ``<limit>`` without ``velocity`` or
``effort`` (urdfdom refuses such a file; our URDF reader accepts it) gives no limit of that kind.
"""
import math
import sys
from dataclasses import dataclass, replace

from diffbot_sim.errors import ConfigError, DiffbotSimError
from diffbot_sim.values import check_number

#: ``std::numeric_limits<double>::max()``: HWSim's "no limit" for position and effort.
DBL_MAX = sys.float_info.max

INTERFACES = ("PositionJointInterface", "VelocityJointInterface", "EffortJointInterface")


class JointLimitsInterfaceError(DiffbotSimError):
    """A limits handle cannot be built (upstream's JointLimitsInterfaceException, thrown while HWSim loads)."""


@dataclass(frozen=True)
class JointLimits:
    """joint_limits_interface::JointLimits (all zero/false by default, as upstream)."""

    has_position_limits: bool = False
    min_position: float = 0.0
    max_position: float = 0.0
    has_velocity_limits: bool = False
    max_velocity: float = 0.0
    has_acceleration_limits: bool = False
    max_acceleration: float = 0.0
    has_jerk_limits: bool = False
    max_jerk: float = 0.0
    has_effort_limits: bool = False
    max_effort: float = 0.0
    angle_wraparound: bool = False


@dataclass(frozen=True)
class SoftJointLimits:
    """joint_limits_interface::SoftJointLimits: soft position bounds and the gains that push back from them."""

    min_position: float = 0.0
    max_position: float = 0.0
    k_position: float = 0.0
    k_velocity: float = 0.0


def limits_from_urdf(joint):
    """``(JointLimits or None, SoftJointLimits or None)`` of a ``diffbot_sim.description.urdf_model.Joint``, as
    joint_limits_urdf.h's getJointLimits / getSoftJointLimits fill them (None: the function returns false)."""
    limits = None
    if joint.has_limit:
        positional = joint.type in ("revolute", "prismatic")
        limits = JointLimits(
            has_position_limits=positional,
            min_position=joint.lower if positional else 0.0,
            max_position=joint.upper if positional else 0.0,
            angle_wraparound=not positional and joint.type == "continuous",
            has_velocity_limits=joint.velocity_limit is not None,
            max_velocity=joint.velocity_limit if joint.velocity_limit is not None else 0.0,
            has_effort_limits=joint.effort_limit is not None,
            max_effort=joint.effort_limit if joint.effort_limit is not None else 0.0,
        )
    soft = None
    if joint.safety is not None:
        soft = SoftJointLimits(min_position=joint.safety.soft_lower_limit,
                               max_position=joint.safety.soft_upper_limit,
                               k_position=joint.safety.k_position, k_velocity=joint.safety.k_velocity)
    return limits, soft


def _flag(params, name, key):
    """A ``has_*`` flag: None when absent; only a real bool is accepted (roscpp's getParam<bool>)."""
    if key not in params:
        return None
    value = params[key]
    if not isinstance(value, bool):
        raise ConfigError(f"{name}/{key}", value, "true or false")
    return value


def _value(params, name, key):
    """A limit value: None when absent, else a finite number."""
    if key not in params:
        return None
    return check_number(f"{name}/{key}", params[key])


def apply_rosparam_limits(limits, params, name):
    """``(limits, found)``: ``limits`` (None: the defaults) overridden by the rosparam dict ``params`` of the
    namespace ``name`` = ``<robotNamespace>/joint_limits/<joint>``, as joint_limits_rosparam.h's getJointLimits.

    ``found`` is False (and ``limits`` unchanged) when the namespace does not exist (``params`` None).

    Raises:
        ConfigError: a flag that is not a bool, a value that is not a finite number, or ``params`` not a
            dictionary; naming ``<name>/<key>``.
    """
    if params is None:
        return limits, False
    if not isinstance(params, dict):
        raise ConfigError(name, params, "a dictionary of joint limits (has_position_limits, min_position, ...)")
    limits = limits if limits is not None else JointLimits()
    changes = {}

    has_position = _flag(params, name, "has_position_limits")
    if has_position is not None:
        if not has_position:
            changes["has_position_limits"] = False
            wraparound = _flag(params, name, "angle_wraparound")
            if wraparound is not None:
                changes["angle_wraparound"] = wraparound
        else:
            low, high = _value(params, name, "min_position"), _value(params, name, "max_position")
            if low is not None and high is not None:
                changes.update(has_position_limits=True, min_position=low, max_position=high)

    for kind, value_key in (("velocity", "max_velocity"), ("acceleration", "max_acceleration"),
                            ("jerk", "max_jerk"), ("effort", "max_effort")):
        has_key = f"has_{kind}_limits"
        enabled = _flag(params, name, has_key)
        if enabled is None:
            continue
        if not enabled:
            changes[has_key] = False
            continue
        value = _value(params, name, value_key)
        if value is not None:
            changes.update({has_key: True, value_key: value})
    return replace(limits, **changes), True


def _saturate(value, low, high):
    """``std::min(std::max(value, low), high)``: with low > high the result is ``high``."""
    value = low if value < low else value
    return high if high < value else value


def _no_limit_error(joint, what):
    return JointLimitsInterfaceError(f"Cannot enforce limits for joint '{joint}'. It has no {what} specification.")


def _soft_velocity_bounds(limits, soft, position, max_velocity):
    """The velocity window the soft limits allow at ``position``: ``clamp(-k_position (pos - soft bound))``."""
    if not limits.has_position_limits:
        return -max_velocity, max_velocity
    low = _saturate(-soft.k_position * (position - soft.min_position), -max_velocity, max_velocity)
    high = _saturate(-soft.k_position * (position - soft.max_position), -max_velocity, max_velocity)
    return low, high


class PositionJointSaturation:
    """PositionJointSaturationHandle: clamp a position command to the position limits and, with a velocity
    limit, to ``prev_cmd ± max_velocity·period`` (so the URDF velocity rate-limits position commands)."""

    def __init__(self, limits, joint=""):
        self.limits = limits
        self.joint = joint
        self.min_position = limits.min_position if limits.has_position_limits else -DBL_MAX
        self.max_position = limits.max_position if limits.has_position_limits else DBL_MAX
        self.prev_cmd = math.nan

    def enforce(self, command, position, velocity, period):
        """The limited position command; ``velocity`` is unused (upstream is open loop)."""
        if math.isnan(self.prev_cmd):
            self.prev_cmd = position
        low, high = self.min_position, self.max_position
        if self.limits.has_velocity_limits:
            step = self.limits.max_velocity * period
            low = max(self.prev_cmd - step, low)
            high = min(self.prev_cmd + step, high)
        command = _saturate(command, low, high)
        self.prev_cmd = command
        return command

    def reset(self, position=None):
        """Forget the last command (upstream's reset): the next enforcement starts from the measured
        position, or from ``position`` when given."""
        self.prev_cmd = math.nan if position is None else position


class PositionJointSoftLimits:
    """PositionJointSoftLimitsHandle: the command may move from the last command at the velocity the soft
    limits allow (``k_velocity`` unused), and never beyond the hard position limits."""

    def __init__(self, limits, soft, joint=""):
        if not limits.has_velocity_limits:
            raise _no_limit_error(joint, "velocity limits")
        self.limits, self.soft, self.joint = limits, soft, joint
        self.prev_cmd = math.nan

    def enforce(self, command, position, velocity, period):
        if math.isnan(self.prev_cmd):
            self.prev_cmd = position
        base = self.prev_cmd
        min_vel, max_vel = _soft_velocity_bounds(self.limits, self.soft, base, self.limits.max_velocity)
        low, high = base + min_vel * period, base + max_vel * period
        if self.limits.has_position_limits:
            low = max(low, self.limits.min_position)
            high = min(high, self.limits.max_position)
        command = _saturate(command, low, high)
        self.prev_cmd = command
        return command

    reset = PositionJointSaturation.reset


class VelocityJointSaturation:
    """VelocityJointSaturationHandle: clamp to ±max_velocity and, with an acceleration limit, to
    ``prev_cmd ± max_acceleration·period`` (prev_cmd starts at 0)."""

    def __init__(self, limits, joint=""):
        if not limits.has_velocity_limits:
            raise _no_limit_error(joint, "velocity limits")
        self.limits, self.joint = limits, joint
        self.prev_cmd = 0.0

    def enforce(self, command, position, velocity, period):
        max_velocity = self.limits.max_velocity
        low, high = -max_velocity, max_velocity
        if self.limits.has_acceleration_limits:
            step = self.limits.max_acceleration * period
            low = max(self.prev_cmd - step, -max_velocity)
            high = min(self.prev_cmd + step, max_velocity)
        command = _saturate(command, low, high)
        self.prev_cmd = command
        return command

    def reset(self, position=None):
        """Back to the constructed state (prev_cmd 0); upstream has no reset for this handle."""
        self.prev_cmd = 0.0


class VelocityJointSoftLimits:
    """VelocityJointSoftLimitsHandle: the soft-limit velocity window at the measured position (the velocity
    limit is DBL_MAX when absent) and, with an acceleration limit, within ``velocity ± max_acceleration·period``."""

    def __init__(self, limits, soft, joint=""):
        self.limits, self.soft, self.joint = limits, soft, joint
        self.max_velocity = limits.max_velocity if limits.has_velocity_limits else DBL_MAX

    def enforce(self, command, position, velocity, period):
        low, high = _soft_velocity_bounds(self.limits, self.soft, position, self.max_velocity)
        if self.limits.has_acceleration_limits:
            step = self.limits.max_acceleration * period
            low = max(velocity - step, low)
            high = min(velocity + step, high)
        return _saturate(command, low, high)

    def reset(self, position=None):
        """Stateless upstream: nothing to forget."""


class EffortJointSaturation:
    """EffortJointSaturationHandle: clamp to ±max_effort; no effort further out past a position limit (min
    side checked first) or beyond the velocity limit."""

    def __init__(self, limits, joint=""):
        if not limits.has_velocity_limits:
            raise _no_limit_error(joint, "velocity limits")
        if not limits.has_effort_limits:
            raise _no_limit_error(joint, "efforts limits")  # sic: upstream's spelling for this handle
        self.limits, self.joint = limits, joint

    def enforce(self, command, position, velocity, period):
        limits = self.limits
        low, high = -limits.max_effort, limits.max_effort
        if limits.has_position_limits:
            if position < limits.min_position:
                low = 0.0
            elif position > limits.max_position:
                high = 0.0
        if velocity < -limits.max_velocity:
            low = 0.0
        elif velocity > limits.max_velocity:
            high = 0.0
        return _saturate(command, low, high)

    def reset(self, position=None):
        """Stateless upstream: nothing to forget."""


class EffortJointSoftLimits:
    """EffortJointSoftLimitsHandle: the effort window ``clamp(-k_velocity (vel - v_bound), ±max_effort)`` for
    the soft-limit velocity bounds at the measured position."""

    def __init__(self, limits, soft, joint=""):
        if not limits.has_velocity_limits:
            raise _no_limit_error(joint, "velocity limits")
        if not limits.has_effort_limits:
            raise _no_limit_error(joint, "effort limits")
        self.limits, self.soft, self.joint = limits, soft, joint

    def enforce(self, command, position, velocity, period):
        limits, soft = self.limits, self.soft
        min_vel, max_vel = _soft_velocity_bounds(limits, soft, position, limits.max_velocity)
        low = _saturate(-soft.k_velocity * (velocity - min_vel), -limits.max_effort, limits.max_effort)
        high = _saturate(-soft.k_velocity * (velocity - max_vel), -limits.max_effort, limits.max_effort)
        return _saturate(command, low, high)

    def reset(self, position=None):
        """Stateless upstream: nothing to forget."""


_HANDLES = {
    "PositionJointInterface": (PositionJointSaturation, PositionJointSoftLimits),
    "VelocityJointInterface": (VelocityJointSaturation, VelocityJointSoftLimits),
    "EffortJointInterface": (EffortJointSaturation, EffortJointSoftLimits),
}


def make_limit_handle(interface, limits, soft, joint=""):
    """The handle HWSim registers for a joint commanded through ``interface`` (``PositionJointInterface`` ...,
    with or without ``hardware_interface/``): None without ``limits``, the SoftLimits handle with ``soft``, else
    the Saturation handle.

    Raises:
        JointLimitsInterfaceError: the handle needs a limit that is missing (upstream's exception text).
        ValueError: ``interface`` is not one of :data:`INTERFACES`.
    """
    interface = interface.split("/")[-1]
    if interface not in _HANDLES:
        raise ValueError(f"unknown joint command interface {interface!r}; expected one of {INTERFACES}")
    if limits is None:
        return None
    saturation, soft_limits = _HANDLES[interface]
    if soft is not None:
        return soft_limits(limits, soft, joint)
    return saturation(limits, joint)


@dataclass(frozen=True)
class RegisteredLimits:
    """What HWSim's registerJointLimits leaves for one joint: the limits its PID and writeSim use, and the
    enforcement handle (None without limits)."""

    joint_type: str  # "revolute", "continuous", "prismatic", ... or "unknown" (no URDF joint, no limits)
    lower: float  # rad or m; -DBL_MAX without position limits
    upper: float  # +DBL_MAX without position limits
    effort_limit: float  # N·m or N; DBL_MAX without effort limits
    limits: JointLimits | None = None
    soft: SoftJointLimits | None = None
    handle: object = None


def register_joint_limits(joint_name, interface, urdf_joint, params, namespace):
    """HWSim's registerJointLimits: URDF limits (``urdf_joint`` may be None), then the overrides in ``params``
    = the rosparam dict at ``<namespace>/joint_limits/<joint_name>`` (None when absent), the joint type inferred
    when unknown (position limits -> revolute, else wraparound -> continuous, else prismatic), and the handle.

    Raises:
        ConfigError: a bad rosparam limit (see :func:`apply_rosparam_limits`).
        JointLimitsInterfaceError: the handle for ``interface`` needs a missing limit.
    """
    joint_type, limits, soft = "unknown", None, None
    if urdf_joint is not None:
        joint_type = urdf_joint.type
        limits, soft = limits_from_urdf(urdf_joint)
    prefix = namespace.rstrip("/")
    limits, found = apply_rosparam_limits(limits, params, f"{prefix}/joint_limits/{joint_name}")
    if limits is None:
        return RegisteredLimits(joint_type, -DBL_MAX, DBL_MAX, DBL_MAX)
    if joint_type == "unknown":
        if limits.has_position_limits:
            joint_type = "revolute"
        else:
            joint_type = "continuous" if limits.angle_wraparound else "prismatic"
    lower = limits.min_position if limits.has_position_limits else -DBL_MAX
    upper = limits.max_position if limits.has_position_limits else DBL_MAX
    effort = limits.max_effort if limits.has_effort_limits else DBL_MAX
    handle = make_limit_handle(interface, limits, soft, joint_name)
    return RegisteredLimits(joint_type, lower, upper, effort, limits, soft, handle)
