"""ros_controllers' diff_drive_controller/DiffDriveController (noetic): its parameters, checked (pure).

A robot built for Gazebo + gazebo_ros_control loads a DiffDriveController from its YAML; to run it unchanged
the simulator must read the same parameters with the same defaults and precedence.
``diff_drive_controller_config`` turns the controller's parameter dict
(``rospy.get_param('/mobile_base_controller')``) into a validated, frozen ``DiffDriveControllerConfig``: a wrong
value raises ``ConfigError`` naming the full parameter, keys upstream never reads are listed for one warning,
defaults substituted where upstream would fail are said in ``warnings``. The controller that runs on it is
:mod:`diffbot_sim.control.diff_drive_controller`.
"""
import math
from dataclasses import asdict, dataclass, field

from diffbot_sim.control.limits import SpeedLimiter
from diffbot_sim.errors import ConfigError
from diffbot_sim.values import check_mapping

CONTROLLER_TYPE = "diff_drive_controller/DiffDriveController"

_TOP_LEVEL_KEYS = frozenset((
    "type", "left_wheel", "right_wheel", "wheel_separation", "wheel_radius", "wheel_separation_multiplier",
    "wheel_radius_multiplier", "left_wheel_radius_multiplier", "right_wheel_radius_multiplier", "publish_rate",
    "pose_covariance_diagonal", "twist_covariance_diagonal", "open_loop", "velocity_rolling_window_size",
    "cmd_vel_timeout", "allow_multiple_cmd_vel_publishers", "base_frame_id", "odom_frame_id", "enable_odom_tf",
    "publish_cmd", "publish_wheel_joint_controller_state", "linear", "angular",
))
_LIMIT_FLAGS = ("has_velocity_limits", "has_acceleration_limits", "has_jerk_limits")
_LIMIT_PAIRS = (("velocity", "has_velocity_limits"), ("acceleration", "has_acceleration_limits"),
                ("jerk", "has_jerk_limits"))


@dataclass(frozen=True)
class AxisLimits:
    """One axis's ``linear/x/*`` or ``angular/z/*`` limits; field names are the parameter names.

    The ``min_*`` values are already resolved (upstream's default is ``-max_*``), so ``SpeedLimiter(**asdict())``
    builds the limiter.
    """

    has_velocity_limits: bool = False
    has_acceleration_limits: bool = False
    has_jerk_limits: bool = False
    min_velocity: float = 0.0
    max_velocity: float = 0.0
    min_acceleration: float = 0.0
    max_acceleration: float = 0.0
    min_jerk: float = 0.0
    max_jerk: float = 0.0

    def limiter(self):
        """A fresh ``SpeedLimiter`` with these limits."""
        return SpeedLimiter(**asdict(self))


@dataclass(frozen=True)
class DiffDriveControllerConfig:
    """A DiffDriveController's parameters, validated, with the noetic defaults filled in.

    ``wheel_separation`` and ``wheel_radius`` are None when the YAML leaves them to the URDF; the caller
    measures them and hands them to ``DiffDriveControllerCore``. ``unknown_keys`` are full parameter names
    upstream never reads (vendor keys such as ``k_l``), for one warning; ``unsupported`` are parameters read
    but not acted on here; ``warnings`` are ready-to-log sentences (defaults substituted, values fixed up).
    """

    name: str
    left_wheels: tuple[str, ...]
    right_wheels: tuple[str, ...]
    wheel_separation: float | None = None
    wheel_radius: float | None = None
    wheel_separation_multiplier: float = 1.0
    left_wheel_radius_multiplier: float = 1.0
    right_wheel_radius_multiplier: float = 1.0
    publish_rate: float = 50.0
    pose_covariance_diagonal: tuple[float, ...] = (0.0,) * 6
    twist_covariance_diagonal: tuple[float, ...] = (0.0,) * 6
    open_loop: bool = False
    velocity_rolling_window_size: int = 10
    cmd_vel_timeout: float = 0.5
    allow_multiple_cmd_vel_publishers: bool = True
    base_frame_id: str = "base_link"
    odom_frame_id: str = "odom"
    enable_odom_tf: bool = True
    publish_cmd: bool = False
    publish_wheel_joint_controller_state: bool = False
    linear: AxisLimits = field(default_factory=AxisLimits)
    angular: AxisLimits = field(default_factory=AxisLimits)
    unknown_keys: tuple[str, ...] = ()
    unsupported: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()

    @property
    def publish_period(self):
        """Seconds between odom publications; ``inf`` for ``publish_rate: 0`` (never, as upstream's 1/0)."""
        return math.inf if self.publish_rate == 0 else 1.0 / self.publish_rate

    @property
    def joints(self):
        """Every wheel joint the controller commands, left ones first."""
        return self.left_wheels + self.right_wheels


def diff_drive_controller_config(params, name):
    """Build a ``DiffDriveControllerConfig`` from the controller's parameter dict.

    Args:
        params: the controller namespace as rospy returns it, e.g. ``rospy.get_param('/mobile_base_controller')``:
            nested dicts (``{'linear': {'x': {...}}}``), ints wherever a float is expected are fine.
        name: the controller namespace (``/mobile_base_controller``), used to name parameters in errors.

    Returns:
        DiffDriveControllerConfig.

    Raises:
        ConfigError: naming the full parameter (``/mobile_base_controller/left_wheel``) whose value is
            missing, of the wrong type or out of range.
    """
    ns = name.rstrip("/")
    if not isinstance(params, dict):
        raise ConfigError(ns, params, "a mapping of the DiffDriveController's parameters")
    warnings, unsupported = [], []
    unknown = [f"{ns}/{key}" for key in params if key not in _TOP_LEVEL_KEYS]

    def pname(key):
        return f"{ns}/{key}"

    kind = params.get("type", CONTROLLER_TYPE)
    if kind != CONTROLLER_TYPE:
        raise ConfigError(pname("type"), kind, repr(CONTROLLER_TYPE))

    left = _wheel_names(pname("left_wheel"), params.get("left_wheel"))
    right = _wheel_names(pname("right_wheel"), params.get("right_wheel"))
    if len(left) != len(right):
        raise ConfigError(pname("right_wheel"), params["right_wheel"],
                          f"as many joints as {pname('left_wheel')} ({len(left)})")

    def number(key, default, **bounds):
        if key not in params:
            return default
        return _number(pname(key), params[key], **bounds)

    def flag(key, default):
        if key not in params:
            return default
        return _bool(pname(key), params[key])

    values = {
        "wheel_separation": number("wheel_separation", None, low=0.0, low_open=True),
        "wheel_radius": number("wheel_radius", None, low=0.0, low_open=True),
        "wheel_separation_multiplier": number("wheel_separation_multiplier", 1.0, low=0.0, low_open=True),
        "publish_rate": number("publish_rate", 50.0, low=0.0),
        "open_loop": flag("open_loop", False),
        "cmd_vel_timeout": number("cmd_vel_timeout", 0.5, low=0.0, allow_inf=True),
        "allow_multiple_cmd_vel_publishers": flag("allow_multiple_cmd_vel_publishers", True),
        "enable_odom_tf": flag("enable_odom_tf", True),
        "publish_cmd": flag("publish_cmd", False),
        "publish_wheel_joint_controller_state": flag("publish_wheel_joint_controller_state", False),
    }
    if values["publish_wheel_joint_controller_state"]:
        unsupported.append(pname("publish_wheel_joint_controller_state"))
        warnings.append(f"{pname('publish_wheel_joint_controller_state')} is true, but the simulator does not "
                        "publish ~wheel_joint_controller_state")

    window = params.get("velocity_rolling_window_size", 10)
    if (isinstance(window, bool) or not isinstance(window, (int, float)) or not math.isfinite(window)
            or window != int(window) or window < 1):
        raise ConfigError(pname("velocity_rolling_window_size"), window, "an integer >= 1")
    values["velocity_rolling_window_size"] = int(window)

    # wheel_radius_multiplier, when set, wins over the per-side ones (upstream's precedence).
    sides = ("left_wheel_radius_multiplier", "right_wheel_radius_multiplier")
    side_values = {key: number(key, 1.0, low=0.0, low_open=True) for key in sides}
    if "wheel_radius_multiplier" in params:
        both = _number(pname("wheel_radius_multiplier"), params["wheel_radius_multiplier"], low=0.0, low_open=True)
        for key in sides:
            if key in params and side_values[key] != both:
                warnings.append(f"{pname(key)} ({side_values[key]:g}) is ignored: "
                                f"{pname('wheel_radius_multiplier')} ({both:g}) overrides it")
            values[key] = both
    else:
        values.update(side_values)

    for key in ("pose_covariance_diagonal", "twist_covariance_diagonal"):
        if key in params:
            values[key] = _covariance(pname(key), params[key])
        else:
            values[key] = (0.0,) * 6
            warnings.append(f"{pname(key)} is not set (diff_drive_controller requires it); using zeros")

    for key, default in (("base_frame_id", "base_link"), ("odom_frame_id", "odom")):
        frame = params.get(key, default)
        if not isinstance(frame, str) or not frame.strip("/"):
            raise ConfigError(pname(key), frame, "a non-empty TF frame id such as " + default)
        if frame.startswith("/"):
            warnings.append(f"{pname(key)} {frame!r}: tf2 frame ids take no leading slash; "
                            f"using {frame.lstrip('/')!r}")
            frame = frame.lstrip("/")
        values[key] = frame

    values["linear"] = _axis_limits(ns, params, "linear", "x", unknown)
    values["angular"] = _axis_limits(ns, params, "angular", "z", unknown)

    return DiffDriveControllerConfig(name=ns, left_wheels=left, right_wheels=right, unknown_keys=tuple(unknown),
                     unsupported=tuple(unsupported), warnings=tuple(warnings), **values)


# -- helpers --------------------------------------------------------------------------------------------

def _wheel_names(name, value):
    expected = "a joint name or a non-empty list of joint names"
    if isinstance(value, str):
        if not value:
            raise ConfigError(name, value, expected)
        return (value,)
    if isinstance(value, (list, tuple)) and value:
        for index, item in enumerate(value):
            if not isinstance(item, str) or not item:
                raise ConfigError(f"{name}[{index}]", item, "a joint name (a non-empty string)")
        return tuple(value)
    raise ConfigError(name, value, expected)


def _number(name, value, low=None, low_open=False, allow_inf=False):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ConfigError(name, value, "a number")
    value = float(value)
    if math.isnan(value) or (math.isinf(value) and not (allow_inf and value > 0)):
        raise ConfigError(name, value, "a finite number")
    if low is not None and (value < low or (low_open and value == low)):
        raise ConfigError(name, value, f"a number {'>' if low_open else '>='} {low:g}")
    return value


def _bool(name, value):
    if not isinstance(value, bool):
        raise ConfigError(name, value, "true or false")
    return value


def _covariance(name, value):
    if not isinstance(value, (list, tuple)) or len(value) != 6:
        raise ConfigError(name, value, "a list of 6 numbers (the diagonal: x, y, z, roll, pitch, yaw)")
    return tuple(_number(f"{name}[{index}]", item) for index, item in enumerate(value))


def _axis_limits(ns, params, group, axis, unknown):
    """Read ``<group>/<axis>/*`` (e.g. ``linear/x``); other axes and keys go to ``unknown``."""
    prefix = f"{ns}/{group}"
    block = check_mapping(prefix, params.get(group),
                          f"a mapping such as {{{axis}: {{has_velocity_limits: true, ...}}}}")
    unknown.extend(f"{prefix}/{key}" for key in block if key != axis)
    prefix = f"{prefix}/{axis}"
    limits = check_mapping(prefix, block.get(axis), "a mapping such as {has_velocity_limits: true, max_velocity: 1.0}")
    known = set(_LIMIT_FLAGS)
    values = {}
    for flag in _LIMIT_FLAGS:
        values[flag] = _bool(f"{prefix}/{flag}", limits[flag]) if flag in limits else False
    for quantity, flag in _LIMIT_PAIRS:
        high_key, low_key = f"max_{quantity}", f"min_{quantity}"
        known.update((high_key, low_key))
        high = _number(f"{prefix}/{high_key}", limits[high_key]) if high_key in limits else 0.0
        low = _number(f"{prefix}/{low_key}", limits[low_key]) if low_key in limits else -high
        if values[flag] and low > high:
            # upstream would pin every command to max_*; almost surely a sign slip in the YAML
            raise ConfigError(f"{prefix}/{low_key}", low, f"a number <= {prefix}/{high_key} ({high:g})")
        values[high_key], values[low_key] = high, low
    unknown.extend(f"{prefix}/{key}" for key in limits if key not in known)
    return AxisLimits(**values)
