"""ros_controllers' four_wheel_steering_controller/FourWheelSteeringController (noetic 0.21.2), pure.

Four driven wheels (velocity joints) and four steering joints (position joints), commanded by a
``geometry_msgs/Twist`` on ``cmd_vel`` (front and rear steered opposite: a symmetric turn) or a
``four_wheel_steering_msgs/FourWheelSteering`` on ``cmd_four_wheel_steering`` (front and rear angles of a
virtual middle wheel each, and a speed); whichever arrived last drives. Upstream's rules, read from
``four_wheel_steering_controller.cpp``/``odometry.cpp``, quirks included:

* joint lists are ``[left, right]``; geometry from the URDF as urdf_geometry_parser measures it (joint
  origins summed up the chain to ``base_frame_id``, rotations ignored; planar distances): ``track`` between
  the front wheels, ``wheel_steering_y_offset`` between the first front steering and the first front wheel,
  ``wheel_base`` between the first front and the first rear wheel, the radius of the first front wheel's
  cylinder; the steering track is ``track - 2 · offset``;
* odometry from the wheels' *velocities* and the steering angles (the front speed from the raw wheel
  speeds, the rear one from the offset-corrected ones, as upstream); the odom frame is always ``odom``;
  ``open_loop`` is read and unused; linear x/y limits only (no jerk);
* the steering-angle velocities it reports are ``(previous - current) / dt`` (sign as upstream).
"""
import math
from dataclasses import dataclass, field
from typing import NamedTuple

from diffbot_sim.control.ackermann_steering_controller import RollingMean, covariances, frame_id, rolling_window
from diffbot_sim.control.diff_drive_config import (
    AxisLimits,
    _axis_limits as axis_limits,
    _bool as check_bool,
    _number as check_number,
)
from diffbot_sim.errors import ConfigError

CONTROLLER_TYPE = "four_wheel_steering_controller/FourWheelSteeringController"

_KEYS = frozenset((
    "type", "front_wheel", "rear_wheel", "front_steering", "rear_steering", "publish_rate", "open_loop",
    "velocity_rolling_window_size", "cmd_vel_timeout", "base_frame_id", "enable_odom_tf", "track",
    "wheel_radius", "wheel_base", "wheel_steering_y_offset", "pose_covariance_diagonal",
    "twist_covariance_diagonal", "linear", "angular",
))


@dataclass(frozen=True)
class FourWheelSteeringConfig:
    """A FourWheelSteeringController's parameters, checked; joint pairs are (left, right)."""

    name: str
    front_wheels: tuple[str, str]
    rear_wheels: tuple[str, str]
    front_steerings: tuple[str, str]
    rear_steerings: tuple[str, str]
    track: float | None = None  # m; None: from the URDF (resolve_geometry)
    wheel_radius: float | None = None
    wheel_base: float | None = None
    publish_rate: float = 50.0
    open_loop: bool = False
    velocity_rolling_window_size: int = 10
    cmd_vel_timeout: float = 0.5
    base_frame_id: str = "base_link"
    enable_odom_tf: bool = True
    pose_covariance_diagonal: tuple[float, ...] = (0.0,) * 6
    twist_covariance_diagonal: tuple[float, ...] = (0.0,) * 6
    linear: AxisLimits = field(default_factory=AxisLimits)
    angular: AxisLimits = field(default_factory=AxisLimits)
    unknown_keys: tuple[str, ...] = ()
    warnings: tuple[str, ...] = ()

    @property
    def publish_period(self):
        return math.inf if self.publish_rate == 0 else 1.0 / self.publish_rate

    @property
    def wheels(self):
        return self.front_wheels + self.rear_wheels

    @property
    def steerings(self):
        return self.front_steerings + self.rear_steerings


def _pair(name, value):
    """A wheel parameter as upstream's getWheelNames reads it, then its 'two by axle' rule."""
    names = (value,) if isinstance(value, str) and value else value
    if not isinstance(names, (list, tuple)) or not names:
        raise ConfigError(name, value, "a list of two joint names [left, right]")
    for index, item in enumerate(names):
        if not isinstance(item, str) or not item:
            raise ConfigError(f"{name}[{index}]", item, "a joint name")
    if len(names) != 2:
        raise ConfigError(name, value, "two joints, left and right (four_wheel_steering_controller needs two by "
                                       "axle)")
    return tuple(names)


def four_wheel_steering_config(params, name):
    """Build a ``FourWheelSteeringConfig`` from the controller's parameter dict.

    Raises:
        ConfigError: naming the full parameter at fault (a missing wheel list among them, as upstream).
    """
    ns = name.rstrip("/")
    if not isinstance(params, dict):
        raise ConfigError(ns, params, "a mapping of the FourWheelSteeringController's parameters")
    warnings = []
    unknown = [f"{ns}/{key}" for key in params if key not in _KEYS]

    def number(key, default, **bounds):
        return default if key not in params else check_number(f"{ns}/{key}", params[key], **bounds)

    def flag(key, default):
        return default if key not in params else check_bool(f"{ns}/{key}", params[key])

    if "wheel_steering_y_offset" in params:
        warnings.append(f"{ns}/wheel_steering_y_offset is measured from the URDF (upstream overwrites the "
                        "parameter)")
    linear = axis_limits(ns, params, "linear", "x", unknown)
    angular = axis_limits(ns, params, "angular", "z", unknown)
    for group, limits in (("linear/x", linear), ("angular/z", angular)):  # no jerk limits upstream
        if limits.has_jerk_limits:
            unknown.append(f"{ns}/{group}/has_jerk_limits")
    linear = AxisLimits(**{**linear.__dict__, "has_jerk_limits": False})
    angular = AxisLimits(**{**angular.__dict__, "has_jerk_limits": False})
    values = {
        "front_wheels": _pair(f"{ns}/front_wheel", params.get("front_wheel")),
        "rear_wheels": _pair(f"{ns}/rear_wheel", params.get("rear_wheel")),
        "front_steerings": _pair(f"{ns}/front_steering", params.get("front_steering")),
        "rear_steerings": _pair(f"{ns}/rear_steering", params.get("rear_steering")),
        "track": number("track", None, low=0.0, low_open=True),
        "wheel_radius": number("wheel_radius", None, low=0.0, low_open=True),
        "wheel_base": number("wheel_base", None, low=0.0, low_open=True),
        "publish_rate": number("publish_rate", 50.0, low=0.0),
        "open_loop": flag("open_loop", False),
        "cmd_vel_timeout": number("cmd_vel_timeout", 0.5, low=0.0, allow_inf=True),
        "enable_odom_tf": flag("enable_odom_tf", True),
        "velocity_rolling_window_size": rolling_window(f"{ns}/velocity_rolling_window_size",
                                                       params.get("velocity_rolling_window_size", 10)),
        "base_frame_id": frame_id(f"{ns}/base_frame_id", params.get("base_frame_id"), "base_link", warnings),
        "linear": linear,
        "angular": angular,
    }
    if values["open_loop"]:
        warnings.append(f"{ns}/open_loop is read but not used by four_wheel_steering_controller: odometry comes "
                        "from the joints")
    values.update(covariances(ns, params, warnings, "four_wheel_steering_controller"))
    return FourWheelSteeringConfig(name=ns, unknown_keys=tuple(unknown), warnings=tuple(warnings), **values)


def joint_offset(joints, joint, base_link):
    """urdf_geometry_parser's getTransformVector: ``joint``'s origin xyz summed with its ancestors' up to
    ``base_link`` (rotations ignored, as upstream).

    Args:
        joints: {joint name: (parent link, child link, (x, y, z))} of the URDF.
    Raises:
        KeyError: with upstream's reason, when the joint is missing or the chain never reaches ``base_link``.
    """
    if joint not in joints:
        raise KeyError(f"{joint} couldn't be retrieved from model description")
    by_child = {child: (name, parent, xyz) for name, (parent, child, xyz) in joints.items()}
    parent, _, xyz = joints[joint]
    total = list(xyz)
    while parent != base_link:
        if parent not in by_child:
            raise KeyError(f"{parent} couldn't be retrieved from model description or his parent joint")
        _, parent, xyz = by_child[parent]
        total = [a + b for a, b in zip(total, xyz)]
    return tuple(total)


def joint_distance(joints, first, second, base_link):
    """urdf_geometry_parser's getDistanceBetweenJoints: the planar (x, y) distance of the two offsets."""
    a, b = joint_offset(joints, first, base_link), joint_offset(joints, second, base_link)
    return math.hypot(a[0] - b[0], a[1] - b[1])


@dataclass(frozen=True)
class Geometry:
    """The controller's geometry [m]: ``steering_track`` = track - 2 · wheel_steering_y_offset."""

    track: float
    wheel_steering_y_offset: float
    wheel_radius: float
    wheel_base: float

    @property
    def steering_track(self):
        return self.track - 2.0 * self.wheel_steering_y_offset


def resolve_geometry(config, track, offset, radius, wheel_base):
    """Parameters win over the URDF's measures (``offset`` always from the URDF, as upstream)."""
    values = {"track": config.track if config.track is not None else track,
              "wheel_radius": config.wheel_radius if config.wheel_radius is not None else radius,
              "wheel_base": config.wheel_base if config.wheel_base is not None else wheel_base}
    for key, value in values.items():
        if value is None or not math.isfinite(value) or value <= 0:
            raise ConfigError(f"{config.name}/{key}", value, "a number > 0, in the parameter or measurable "
                                                             "from the URDF")
    return Geometry(values["track"], offset, values["wheel_radius"], values["wheel_base"])


def axle_steering(left, right):
    """The virtual middle wheel's angle of an axle whose wheels are at ``left``/``right`` [rad]."""
    if abs(left) > 0.001 or abs(right) > 0.001:
        return math.atan(2 * math.tan(left) * math.tan(right) / (math.tan(left) + math.tan(right)))
    return 0.0


class FourWheelSteeringOdometry:
    """four_wheel_steering_controller's Odometry (from wheel velocities and axle steering angles)."""

    def __init__(self, geometry, window=10):
        self.g = geometry
        self.x = self.y = self.heading = 0.0
        self.linear = self.linear_x = self.linear_y = self.angular = 0.0
        self._time = 0.0
        self._accel, self._jerk = RollingMean(window), RollingMean(window)
        self._front_vel, self._rear_vel = RollingMean(window), RollingMean(window)
        self._linear_prev = self._accel_prev = self._front_prev = self._rear_prev = 0.0

    def init(self, time):
        for acc in (self._accel, self._jerk, self._front_vel, self._rear_vel):
            acc.clear()
        self._time = time

    def _axle_speed(self, left, right, steering, tmp_angle, corrected):
        g = self.g
        track, offset = g.steering_track, g.wheel_steering_y_offset
        tmp = math.cos(steering) * tmp_angle / g.wheel_base
        left_tmp = tmp / math.sqrt(1 - track * tmp * math.cos(steering) + (track * tmp / 2) ** 2)
        right_tmp = tmp / math.sqrt(1 + track * tmp * math.cos(steering) + (track * tmp / 2) ** 2)
        left_c = left * (1 / (1 - offset * left_tmp))
        right_c = right * (1 / (1 - offset * right_tmp))
        a, b = (left_c, right_c) if corrected else (left, right)
        speed = g.wheel_radius * math.copysign(1.0, left_c + right_c) * math.sqrt(
            (a ** 2 + b ** 2) / (2 + (track * tmp) ** 2 / 2.0))
        return speed, tmp

    def update(self, fl, fr, rl, rr, front_steering, rear_steering, time):
        """Wheel velocities [rad/s] and axle steering angles [rad] at ``time``; False when dt < 0.1 ms."""
        diff = math.tan(front_steering) - math.tan(rear_steering)
        front_speed, front_tmp = self._axle_speed(fl, fr, front_steering, diff, corrected=False)
        rear_speed, rear_tmp = self._axle_speed(rl, rr, rear_steering, diff, corrected=True)
        base = self.g.wheel_base
        self.angular = (front_speed * front_tmp + rear_speed * rear_tmp) / 2.0
        self.linear_x = (front_speed * math.cos(front_steering) + rear_speed * math.cos(rear_steering)) / 2.0
        self.linear_y = (front_speed * math.sin(front_steering) - base * self.angular / 2.0
                         + rear_speed * math.sin(rear_steering) + base * self.angular / 2.0) / 2.0
        self.linear = math.copysign(1.0, rear_speed) * math.hypot(self.linear_x, self.linear_y)
        dt = time - self._time
        if dt < 0.0001:
            return False
        self._time = time
        dx, dy, dyaw = self.linear_x * dt, self.linear_y * dt, self.angular * dt
        self.x += dx * math.cos(self.heading) - dy * math.sin(self.heading)
        self.y += dx * math.sin(self.heading) + dy * math.cos(self.heading)
        self.heading += dyaw
        self._accel.add((self._linear_prev - self.linear) / dt)
        self._linear_prev = self.linear
        self._jerk.add((self._accel_prev - self._accel.mean) / dt)
        self._accel_prev = self._accel.mean
        self._front_vel.add((self._front_prev - front_steering) / dt)
        self._front_prev = front_steering
        self._rear_vel.add((self._rear_prev - rear_steering) / dt)
        self._rear_prev = rear_steering
        return True

    @property
    def linear_acceleration(self):
        return self._accel.mean

    @property
    def linear_jerk(self):
        return self._jerk.mean

    @property
    def front_steer_velocity(self):
        return self._front_vel.mean

    @property
    def rear_steer_velocity(self):
        return self._rear_vel.mean


def twist_commands(lin_x, ang, g):
    """Wheel velocities (fl, fr, rl, rr) [rad/s] and steering angles (fl, fr, rl, rr) [rad] for a Twist."""
    track, offset, radius, base = g.steering_track, g.wheel_steering_y_offset, g.wheel_radius, g.wheel_base
    fl = fr = rl = rr = 0.0
    if abs(lin_x) > 0.001:
        steer_offset = ang * offset / radius
        sign = math.copysign(1.0, lin_x)
        left = sign * math.hypot(lin_x - ang * track / 2, base * ang / 2.0) / radius - steer_offset
        right = sign * math.hypot(lin_x + ang * track / 2, base * ang / 2.0) / radius + steer_offset
        fl = rl = left
        fr = rr = right
    front_left = front_right = 0.0
    if abs(2.0 * lin_x) > abs(ang * track):
        front_left = math.atan(ang * base / (2.0 * lin_x - ang * track))
        front_right = math.atan(ang * base / (2.0 * lin_x + ang * track))
    elif abs(lin_x) > 0.001:
        front_left = front_right = math.copysign(math.pi / 2, ang)
    return (fl, fr, rl, rr), (front_left, front_right, -front_left, -front_right)


def four_wheel_steering_commands(speed, front_steering, rear_steering, g):
    """Wheel velocities and steering angles (fl, fr, rl, rr) for a FourWheelSteering command (speed m/s,
    axle angles clamped to ±pi/2)."""
    track, offset, radius, base = g.steering_track, g.wheel_steering_y_offset, g.wheel_radius, g.wheel_base
    front_steering = min(max(front_steering, -math.pi / 2), math.pi / 2)
    rear_steering = min(max(rear_steering, -math.pi / 2), math.pi / 2)
    tan_front, tan_rear = math.tan(front_steering), math.tan(rear_steering)
    steering_diff = track * (tan_front - tan_rear) / 2.0
    fl_s = fr_s = rl_s = rr_s = 0.0
    if abs(base - abs(steering_diff)) > 0.001:
        fl_s = math.atan(base * tan_front / (base - steering_diff))
        fr_s = math.atan(base * tan_front / (base + steering_diff))
        rl_s = math.atan(base * tan_rear / (base - steering_diff))
        rr_s = math.atan(base * tan_rear / (base + steering_diff))
    fl = fr = rl = rr = 0.0
    if abs(speed) > 0.001:
        def cir(left, right):  # distance from the axle to the centre of rotation's projection
            tl, tr = math.tan(left), math.tan(right)
            return tr * tl * track / (tl - tr) if abs(tl - tr) > 0.01 else 0.0
        l_front, l_rear = cir(fl_s, fr_s), cir(rl_s, rr_s)
        angular = speed * (tan_front - tan_rear) / base
        steer_offset = angular * offset / radius
        sign = math.copysign(1.0, speed)
        fl = sign * math.hypot(speed - angular * track / 2, l_front * angular) / radius - steer_offset
        fr = sign * math.hypot(speed + angular * track / 2, l_front * angular) / radius + steer_offset
        rl = sign * math.hypot(speed - angular * track / 2, l_rear * angular) / radius - steer_offset
        rr = sign * math.hypot(speed + angular * track / 2, l_rear * angular) / radius + steer_offset
    return (fl, fr, rl, rr), (fl_s, fr_s, rl_s, rr_s)


class FourWheelSteeringStep(NamedTuple):
    """Commands for (fl, fr, rl, rr) wheels [rad/s] and steerings [rad]; publish odom now; skipped (NaN
    joint readings: no odometry this update, the commands are still computed as upstream)."""

    wheels: tuple[float, float, float, float]
    steerings: tuple[float, float, float, float]
    publish_odom: bool
    front_steering: float = 0.0
    rear_steering: float = 0.0


class FourWheelSteeringCore:
    """One FourWheelSteeringController minus ROS."""

    def __init__(self, config, geometry):
        self.config, self.geometry = config, geometry
        self.odometry = FourWheelSteeringOdometry(geometry, config.velocity_rolling_window_size)
        self.linear_limiter = config.linear.limiter()
        self.angular_limiter = config.angular.limiter()
        self.running = False
        # stamps -inf until received (upstream's 0: a command at sim time 0 would tie with none)
        self._twist = (0.0, 0.0, 0.0, -math.inf)  # lin_x, lin_y, ang, stamp
        self._four = (0.0, 0.0, 0.0, -math.inf)  # speed, front, rear, stamp
        self._last0 = (0.0, 0.0)  # lin_x, ang
        self._last1 = (0.0, 0.0)
        self._last_publish_ns = 0
        self.twist_mode = False
        self.axle_steering = (0.0, 0.0)

    def starting(self, now):
        self.running = True
        self._last_publish_ns = _ns(now)
        self.odometry.init(now)

    def stopping(self, now=None):
        self.running = False

    def set_twist(self, lin_x, lin_y, ang, now):
        """``cmd_vel``; None when taken, else the reason it was refused."""
        if not self.running:
            return "Can't accept new commands. Controller is not running."
        if math.isnan(ang) or math.isnan(lin_x):
            return "Received NaN in geometry_msgs::Twist. Ignoring command."
        self._twist = (float(lin_x), float(lin_y), float(ang), now)
        return None

    def set_four_wheel_steering(self, speed, front, rear, now):
        """``cmd_four_wheel_steering``; None when taken, else the reason it was refused."""
        if not self.running:
            return "Can't accept new commands. Controller is not running."
        if math.isnan(front) or math.isnan(rear) or math.isnan(speed):
            return "Received NaN in four_wheel_steering_msgs::FourWheelSteering. Ignoring command."
        self._four = (float(speed), float(front), float(rear), now)
        return None

    def update(self, now, wheel_velocities, steering_positions, period):
        """One control period: odometry from (fl, fr, rl, rr) wheel velocities and steering positions, then
        the newer command turned into joint commands."""
        publish = False
        readings = tuple(wheel_velocities) + tuple(steering_positions)
        if not any(math.isnan(v) for v in readings):
            front = axle_steering(steering_positions[0], steering_positions[1])
            rear = axle_steering(steering_positions[2], steering_positions[3])
            self.axle_steering = (front, rear)
            self.odometry.update(*wheel_velocities, front, rear, now)
            period_ns = None if math.isinf(self.config.publish_period) else _ns(self.config.publish_period)
            publish = period_ns is not None and self._last_publish_ns + period_ns < _ns(now)
            if publish:
                self._last_publish_ns += period_ns
        wheels, steerings = self._command(now, period)
        return FourWheelSteeringStep(wheels, steerings, publish, *self.axle_steering)

    def _command(self, now, period):
        lin_x, _lin_y, ang, twist_stamp = self._twist
        speed, front, rear, four_stamp = self._four
        self.twist_mode = not four_stamp >= twist_stamp
        stamp = twist_stamp if self.twist_mode else four_stamp
        if now - stamp > self.config.cmd_vel_timeout:
            lin_x = ang = speed = front = rear = 0.0
        if self.twist_mode:
            lin_x = self.linear_limiter.limit(lin_x, self._last0[0], self._last1[0], period)
            ang = self.angular_limiter.limit(ang, self._last0[1], self._last1[1], period)
            self._last1, self._last0 = self._last0, (lin_x, ang)
            return twist_commands(lin_x, ang, self.geometry)
        speed = self.linear_limiter.limit(speed, self._last0[0], self._last1[0], period)
        self._last1, self._last0 = self._last0, (speed, self._last0[1])
        return four_wheel_steering_commands(speed, front, rear, self.geometry)

    @property
    def pose(self):
        return self.odometry.x, self.odometry.y, self.odometry.heading


def _ns(seconds):
    return int(round(seconds * 1e9))
