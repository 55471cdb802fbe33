"""ros_controllers' ackermann_steering_controller/AckermannSteeringController (noetic 0.21.2), pure.

A car-like robot built for Gazebo + gazebo_ros_control drives through this controller: one velocity joint
(``rear_wheel``, the middle of the rear axle of a bicycle model) and one position joint (``front_steer``).
To run such a robot unchanged the simulator must read the same parameters and move and integrate the same
way, quirks included (each is upstream's, read from ``ackermann_steering_controller.cpp``/``odometry.cpp``):

* ``cmd_vel.angular.z`` is the **steering angle** [rad] handed to ``front_steer``, not a yaw rate; the
  ``angular/z`` limits therefore limit the steering angle and its rate;
* the wheel command is ``linear.x / wheel_radius`` with the radius *before* ``wheel_radius_multiplier``;
* odometry from the joints: the rear wheel's travel and ``tan(steer · steer_pos_multiplier) / wheel_separation_h``;
  open loop it integrates the last limited command as (v, w) with the steering angle taken as w;
* no ``publish_cmd`` (only diff_drive_controller has ``cmd_vel_out``), no NaN check on ``cmd_vel`` upstream
  (here a non-finite command is refused with a warning instead of reaching the physics).

``ackermann_config`` checks the parameters; ``AckermannSteeringCore`` is the per-update core; publishing and
reading the URDF belong to the caller (:mod:`diffbot_sim.plugins.ros_control.ackermann_steering`).
"""
import math
from collections import deque
from dataclasses import dataclass, field
from typing import NamedTuple

from diffbot_sim.control.diff_drive_config import (
    AxisLimits,
    _axis_limits as axis_limits,
    _bool as check_bool,
    _covariance as covariance,
    _number as check_number,
)
from diffbot_sim.control.odometry import integrate_exact
from diffbot_sim.errors import ConfigError

CONTROLLER_TYPE = "ackermann_steering_controller/AckermannSteeringController"

_KEYS = frozenset((
    "type", "rear_wheel", "front_steer", "publish_rate", "open_loop", "wheel_separation_h", "wheel_radius",
    "wheel_separation_h_multiplier", "wheel_radius_multiplier", "steer_pos_multiplier",
    "velocity_rolling_window_size", "cmd_vel_timeout", "allow_multiple_cmd_vel_publishers", "base_frame_id",
    "odom_frame_id", "enable_odom_tf", "pose_covariance_diagonal", "twist_covariance_diagonal", "linear",
    "angular",
))


@dataclass(frozen=True)
class AckermannConfig:
    """An AckermannSteeringController's parameters, checked, with upstream's defaults.

    ``wheel_separation_h`` / ``wheel_radius`` are None when the YAML leaves them to the URDF (the caller
    measures them). ``unknown_keys``: full names of parameters upstream never reads (``publish_cmd``,
    ``estimate_velocity_from_position``, ...), for one warning.
    """

    name: str
    rear_wheel: str = "rear_wheel_joint"
    front_steer: str = "front_steer_joint"
    wheel_separation_h: float | None = None
    wheel_radius: float | None = None
    wheel_separation_h_multiplier: float = 1.0
    wheel_radius_multiplier: float = 1.0
    steer_pos_multiplier: float = 1.0
    publish_rate: float = 50.0
    open_loop: bool = False
    velocity_rolling_window_size: int = 10
    cmd_vel_timeout: float = 0.5
    allow_multiple_cmd_vel_publishers: bool = True
    base_frame_id: str = "base_link"
    odom_frame_id: str = "odom"
    enable_odom_tf: bool = True
    pose_covariance_diagonal: tuple[float, ...] = (0.0,) * 6
    twist_covariance_diagonal: tuple[float, ...] = (0.0,) * 6
    linear: AxisLimits = field(default_factory=AxisLimits)
    angular: AxisLimits = field(default_factory=AxisLimits)
    unknown_keys: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()

    @property
    def publish_period(self):
        """Seconds between odom publications (``inf`` for ``publish_rate: 0``)."""
        return math.inf if self.publish_rate == 0 else 1.0 / self.publish_rate


def frame_id(name, value, default, warnings):
    """A TF frame parameter: tf2 takes no leading slash (``'/odom'`` in published YAMLs): stripped, one warning."""
    frame = default if value is None else value
    if not isinstance(frame, str) or not frame.strip("/"):
        raise ConfigError(name, frame, "a non-empty TF frame id such as " + default)
    if frame.startswith("/"):
        warnings.append(f"{name} {frame!r}: tf2 frame ids take no leading slash; using {frame.lstrip('/')!r}")
    return frame.lstrip("/")


def rolling_window(name, value):
    """``velocity_rolling_window_size``: an integer >= 1."""
    if (isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value)
            or value != int(value) or value < 1):
        raise ConfigError(name, value, "an integer >= 1")
    return int(value)


def covariances(ns, params, warnings, controller="ackermann_steering_controller"):
    """Both covariance diagonals; a missing one is zeros (upstream's XmlRpc reading of an absent list)."""
    out = {}
    for key in ("pose_covariance_diagonal", "twist_covariance_diagonal"):
        if key in params:
            out[key] = covariance(f"{ns}/{key}", params[key])
        else:
            out[key] = (0.0,) * 6
            warnings.append(f"{ns}/{key} is not set ({controller} reads it); using zeros")
    return out


def ackermann_config(params, name):
    """Build an ``AckermannConfig`` from the controller's parameter dict (as rospy returns it).

    Raises:
        ConfigError: naming the full parameter whose value is of the wrong type or out of range.
    """
    ns = name.rstrip("/")
    if not isinstance(params, dict):
        raise ConfigError(ns, params, "a mapping of the AckermannSteeringController's parameters")
    warnings = []
    unknown = [f"{ns}/{key}" for key in params if key not in _KEYS]

    def number(key, default, **bounds):
        return default if key not in params else check_number(f"{ns}/{key}", params[key], **bounds)

    def flag(key, default):
        return default if key not in params else check_bool(f"{ns}/{key}", params[key])

    def joint(key, default):
        value = params.get(key, default)
        if not isinstance(value, str) or not value:
            raise ConfigError(f"{ns}/{key}", value, "a joint name")
        return value

    values = {
        "rear_wheel": joint("rear_wheel", "rear_wheel_joint"),
        "front_steer": joint("front_steer", "front_steer_joint"),
        "wheel_separation_h": number("wheel_separation_h", None, low=0.0, low_open=True),
        "wheel_radius": number("wheel_radius", None, low=0.0, low_open=True),
        "wheel_separation_h_multiplier": number("wheel_separation_h_multiplier", 1.0, low=0.0, low_open=True),
        "wheel_radius_multiplier": number("wheel_radius_multiplier", 1.0, low=0.0, low_open=True),
        "steer_pos_multiplier": number("steer_pos_multiplier", 1.0),
        "publish_rate": number("publish_rate", 50.0, low=0.0),
        "open_loop": flag("open_loop", False),
        "cmd_vel_timeout": number("cmd_vel_timeout", 0.5, low=0.0, allow_inf=True),
        "allow_multiple_cmd_vel_publishers": flag("allow_multiple_cmd_vel_publishers", True),
        "enable_odom_tf": flag("enable_odom_tf", True),
        "velocity_rolling_window_size": rolling_window(f"{ns}/velocity_rolling_window_size",
                                                       params.get("velocity_rolling_window_size", 10)),
        "base_frame_id": frame_id(f"{ns}/base_frame_id", params.get("base_frame_id"), "base_link", warnings),
        "odom_frame_id": frame_id(f"{ns}/odom_frame_id", params.get("odom_frame_id"), "odom", warnings),
        "linear": axis_limits(ns, params, "linear", "x", unknown),
        "angular": axis_limits(ns, params, "angular", "z", unknown),
    }
    values.update(covariances(ns, params, warnings))
    return AckermannConfig(name=ns, unknown_keys=tuple(unknown), warnings=tuple(warnings), **values)


class RollingMean:
    """boost's rolling_mean over the last ``size`` samples (0 before the first)."""

    def __init__(self, size):
        self.samples = deque(maxlen=size)

    def add(self, value):
        self.samples.append(value)

    def clear(self):
        self.samples.clear()

    @property
    def mean(self):
        return sum(self.samples) / len(self.samples) if self.samples else 0.0


class AckermannOdometry:
    """ackermann_steering_controller's Odometry: a bicycle model from the rear wheel's angle and the steer.

    As upstream: the pose integrates every update (exact arc, or 2nd-order Runge-Kutta below 1e-6 rad); the
    velocities are rolling means of increment/dt, skipped when dt < 0.1 ms; the wheel's previous travel
    starts at 0 (a wheel already turned at the first reading counts as travel, as upstream's does).
    """

    def __init__(self, wheel_separation_h, wheel_radius, window=10):
        self.separation_h, self.radius = wheel_separation_h, wheel_radius
        self.x = self.y = self.heading = 0.0
        self.linear = self.angular = 0.0
        self._old_travel = 0.0
        self._time = 0.0
        self._linear = RollingMean(window)
        self._angular = RollingMean(window)

    def init(self, time):
        """``starting()``: clear the velocity windows and measure dt from ``time``; the pose is kept."""
        self._linear.clear()
        self._angular.clear()
        self._time = time

    def update(self, wheel_position, steer_position, time):
        """Integrate the rear wheel's travel since the last call at steering angle ``steer_position`` [rad]."""
        travel = wheel_position * self.radius
        linear = travel - self._old_travel
        self._old_travel = travel
        angular = math.tan(steer_position) * linear / self.separation_h
        self.x, self.y, self.heading = integrate_exact(self.x, self.y, self.heading, linear, angular)
        dt = time - self._time
        if dt < 0.0001:
            return False
        self._time = time
        self._linear.add(linear / dt)
        self._angular.add(angular / dt)
        self.linear, self.angular = self._linear.mean, self._angular.mean
        return True

    def update_open_loop(self, linear, angular, time):
        """Integrate a command (v, w) held since the last update; the velocities are the command itself."""
        self.linear, self.angular = linear, angular
        dt = time - self._time
        self._time = time
        self.x, self.y, self.heading = integrate_exact(self.x, self.y, self.heading, linear * dt, angular * dt)


class AckermannStep(NamedTuple):
    """What one update asks of the caller: the rear wheel's velocity [rad/s] and the steer's position [rad]
    commands, whether to publish odom (and TF) now, and whether the update was skipped (a NaN joint
    position: nothing integrated, nothing published, the previous commands stay)."""

    wheel_velocity: float
    steer_position: float
    publish_odom: bool
    skipped: bool = False


class AckermannSteeringCore:
    """One AckermannSteeringController minus ROS: ``starting(now)``, then ``update`` every control period and
    ``set_command`` on every ``cmd_vel``.

    Args:
        config: an ``AckermannConfig``.
        wheel_separation_h, wheel_radius: m, measured from the URDF by the caller; used only where the config
            leaves the parameter unset.
    """

    def __init__(self, config, wheel_separation_h=None, wheel_radius=None):
        self.config = config
        separation = config.wheel_separation_h if config.wheel_separation_h is not None else wheel_separation_h
        radius = config.wheel_radius if config.wheel_radius is not None else wheel_radius
        for key, value in (("wheel_separation_h", separation), ("wheel_radius", radius)):
            if value is None or not math.isfinite(value) or value <= 0:
                raise ConfigError(f"{config.name}/{key}", value,
                                  "a number > 0, in the parameter or measurable from the URDF")
        self.wheel_radius = radius  # the command's radius: upstream divides by it unmultiplied
        self.separation_h = config.wheel_separation_h_multiplier * separation
        self.odometry = AckermannOdometry(self.separation_h, config.wheel_radius_multiplier * radius,
                                          config.velocity_rolling_window_size)
        self.linear_limiter = config.linear.limiter()
        self.angular_limiter = config.angular.limiter()
        self.running = False
        self._command = (0.0, 0.0, 0.0)  # linear, angular (the steering angle), receipt time (0: never)
        self._last0 = (0.0, 0.0)
        self._last1 = (0.0, 0.0)
        self._joints = (0.0, 0.0)  # wheel velocity, steer position commands
        self._last_publish_ns = 0

    def starting(self, now):
        """Brake, restart the publish schedule and the odometry's dt at sim time ``now``."""
        self.running = True
        self.brake()
        self._last_publish_ns = _ns(now)
        self.odometry.init(now)

    def stopping(self, now=None):
        self.running = False
        self.brake()

    def brake(self):
        """Rear wheel stopped, steering straight."""
        self._joints = (0.0, 0.0)

    def set_command(self, linear, angular, now, num_publishers=1):
        """A ``cmd_vel`` (``linear.x`` m/s, ``angular.z`` the steering angle in rad) received at ``now``.

        Returns None when taken, else the reason it was refused (for a throttled log).
        """
        if not self.running:
            return "Can't accept new commands. Controller is not running."
        if not self.config.allow_multiple_cmd_vel_publishers and num_publishers > 1:
            self.brake()
            return f"Detected {num_publishers} publishers. Only 1 publisher is allowed. Going to brake."
        if not (math.isfinite(linear) and math.isfinite(angular)):
            return "Received a non-finite cmd_vel; ignored (upstream would pass it to the joints)."
        self._command = (float(linear), float(angular), now)
        return None

    def update(self, now, wheel_position=0.0, steer_position=0.0, period=0.0):
        """One control period at sim time ``now``: odometry, the publish decision, timeout, limits, commands."""
        if not self.running:
            raise RuntimeError("AckermannSteeringCore.update() before starting()")
        if self.config.open_loop:
            self.odometry.update_open_loop(self._last0[0], self._last0[1], now)
        else:
            if math.isnan(wheel_position) or math.isnan(steer_position):
                return AckermannStep(self._joints[0], self._joints[1], False, True)
            self.odometry.update(wheel_position, steer_position * self.config.steer_pos_multiplier, now)

        period_ns = None if math.isinf(self.config.publish_period) else _ns(self.config.publish_period)
        publish = period_ns is not None and self._last_publish_ns + period_ns < _ns(now)
        if publish:
            self._last_publish_ns += period_ns

        linear, angular, stamp = self._command
        if now - stamp > self.config.cmd_vel_timeout:
            linear = angular = 0.0
        linear = self.linear_limiter.limit(linear, self._last0[0], self._last1[0], period)
        angular = self.angular_limiter.limit(angular, self._last0[1], self._last1[1], period)
        self._last1, self._last0 = self._last0, (linear, angular)
        self._joints = (linear / self.wheel_radius, angular)
        return AckermannStep(self._joints[0], self._joints[1], publish, False)

    @property
    def pose(self):
        """(x, y, heading) in the odom frame; the heading is not wrapped, as upstream."""
        return self.odometry.x, self.odometry.y, self.odometry.heading

    @property
    def velocity(self):
        """(linear m/s, angular rad/s) of the odometry."""
        return self.odometry.linear, self.odometry.angular

    @property
    def joint_commands(self):
        """(rear wheel velocity rad/s, steer position rad)."""
        return self._joints


def turning_radius(wheel_separation_h, steer):
    """Radius [m] of the rear axle's middle on a bicycle model steered by ``steer`` [rad] (inf: straight)."""
    return math.inf if abs(math.tan(steer)) < 1e-12 else wheel_separation_h / math.tan(steer)


def _ns(seconds):
    return int(round(seconds * 1e9))
