"""The force-based move plugin family: a holonomic base pushed by forces and a yaw torque, a P loop on its
velocity, and odometry integrated from the body's own velocity (pure; no rospy, no physics).

Team Hector's ``GazeboRosForceBasedMove`` (tu-darmstadt-ros-pkg/hector_gazebo melodic-devel,
hector_gazebo_plugins/src/gazebo_ros_force_based_move.cpp, ``libgazebo_ros_force_based_move.so``) and the
vendor copies robots ship: ridgeback/ridgeback_simulator noetic-devel
ridgeback_gazebo_plugins/src/ridgeback_ros_force_based_move.cpp (``libridgeback_ros_force_based_move.so``) and
RBinsonB/nexus_4wd_mecanum_simulator nexus_4wd_mecanum_gazebo/src/nexus_ros_force_based_move.cpp
(``libnexus_ros_force_based_move.so``). Every world update (before the step):

* the command (``commandTopic``, a Twist: linear.x, linear.y, angular.z) is zeroed when none came for
  ``cmdVelTimeOut`` s of sim time (the vendor copies; Hector's has no timeout and holds the last command);
* a force ``(x_velocity_p_gain * (x - vx), y_velocity_p_gain * (y - vy), 0)`` in the axes of the
  ``robotBaseFrame`` link (AddRelativeForce: at its centre of mass), ``vx, vy`` the model's velocity in its own
  frame (RelativeLinearVel), and a world torque ``(0, 0, yaw_velocity_p_gain * (rot - wz))``, ``wz`` the model's
  world yaw rate (AddTorque);
* odometry, once more than ``1 / odometryRate`` s passed since the last (strictly more; rate <= 0: none): the
  pose composed with the motion of the body's own velocity (vx, vy, wz) over that time along an arc
  (:func:`motion`), published with its twist, and as TF odometryFrame -> robotBaseFrame when
  ``publishOdometryTf`` (default true). Covariance: x, y 0.001, z/roll/pitch 1e12, yaw 0.01 while |wz| <
  1e-4 rad/s else 100; the twist's z is 0.001.

Tags and defaults (all three): ``robotNamespace`` (""), ``commandTopic`` (cmd_vel), ``odometryTopic`` (odom),
``odometryFrame`` (odom), ``robotBaseFrame`` (base_footprint), ``odometryRate`` (20 Hz), ``publishOdometryTf``
(true), ``x_velocity_p_gain`` / ``y_velocity_p_gain`` (10000 N per m/s), ``yaw_velocity_p_gain`` (100 N·m per
rad/s); ``cmdVelTimeOut`` (0.25 s) in the vendor copies only.

Deliberately not reproduced: the vendor copies integrate only vx and wz (their odometry misses a strafe);
Hector added vy (hector_gazebo #71, 2020), which is used for all three. A P loop tuned for Gazebo's 1 ms step
can be too stiff for ours: where ``gain * dt / inertia`` passes 2 * STABILITY_MARGIN (the explicit loop
overshoots), :func:`stable_gain` gives the gain of the exact discrete form of the same continuous loop.
"""
import math
from dataclasses import dataclass, replace

from diffbot_sim.control.pid import STABILITY_MARGIN
from diffbot_sim.transforms import wrap_angle
from diffbot_sim.values import check_bool, check_string, tag_number

#: |wz| [rad/s] below which a motion is straight, and its yaw variance small (upstream's 0.0001).
STILL_YAW_RATE = 1e-4
#: A motion shorter than this along x and y [m] over the period turns in place (Hector's rotate-on-spot case).
SPOT_DISTANCE = 1e-4
#: Upstream's covariance diagonals: pose x, y, z, roll, pitch, yaw; the twist's z is 0.001.
POSE_COVARIANCE = (0.001, 0.001, 1e12, 1e12, 1e12)
TWIST_COVARIANCE = (0.001, 0.001, 0.001, 1e12, 1e12)
YAW_COVARIANCE_STILL, YAW_COVARIANCE_TURNING = 0.01, 100.0


@dataclass(frozen=True)
class Variant:
    """What one published copy of the plugin does differently."""

    filename: str
    source: str  # repository and file it was read from
    cmd_vel_timeout: float | None  # default of <cmdVelTimeOut> [s]; None: the copy has no timeout (no tag)


VARIANTS = {v.filename: v for v in (
    Variant("libgazebo_ros_force_based_move.so",
            "tu-darmstadt-ros-pkg/hector_gazebo melodic-devel gazebo_ros_force_based_move.cpp", None),
    Variant("libridgeback_ros_force_based_move.so",
            "ridgeback/ridgeback_simulator noetic-devel ridgeback_ros_force_based_move.cpp", 0.25),
    Variant("libnexus_ros_force_based_move.so",
            "RBinsonB/nexus_4wd_mecanum_simulator nexus_ros_force_based_move.cpp", 0.25),
    # Robotnik's copy (Summit XL, RB-Kairos): its <commandWatchdog>, which freezes the base's pose once expired,
    # is not read (one unknown-tag warning): the base coasts to rest under the P loop instead
    Variant("librobotnik_force_based_move.so",
            "RobotnikAutomation/robotnik_gazebo_plugins robotnik_force_based_move.cpp", None),
)}


@dataclass(frozen=True)
class ForceBasedMoveConfig:
    """The plugin's tags, read once (defaults as upstream)."""

    robot_namespace: str | None = None  # None: absent (the spawner's namespace applies)
    command_topic: str = "cmd_vel"
    odometry_topic: str = "odom"
    odometry_frame: str = "odom"
    robot_base_frame: str = "base_footprint"
    odometry_rate: float = 20.0  # Hz; <= 0: no odometry and no TF
    cmd_vel_timeout: float | None = 0.25  # s; None: none (the last command holds)
    publish_odometry_tf: bool = True
    x_gain: float = 10000.0  # N per m/s
    y_gain: float = 10000.0  # N per m/s
    yaw_gain: float = 100.0  # N·m per rad/s


#: tag -> (field, kind) of ForceBasedMoveConfig.
TAGS = {
    "robotNamespace": ("robot_namespace", "namespace"),
    "commandTopic": ("command_topic", "string"),
    "odometryTopic": ("odometry_topic", "string"),
    "odometryFrame": ("odometry_frame", "string"),
    "robotBaseFrame": ("robot_base_frame", "string"),
    "odometryRate": ("odometry_rate", "number"),
    "cmdVelTimeOut": ("cmd_vel_timeout", "number"),
    "publishOdometryTf": ("publish_odometry_tf", "bool"),
    "x_velocity_p_gain": ("x_gain", "number"),
    "y_velocity_p_gain": ("y_gain", "number"),
    "yaw_velocity_p_gain": ("yaw_gain", "number"),
}
#: Tags Gazebo's own plugin loader or common robot files add, which no copy reads.
IGNORED_TAGS = ("alwaysOn", "updateRate", "rosDebugLevel")


def read_config(tags, variant, path, notes):
    """The config from ``tags`` [(tag, text)] of the plugin element at ``path``, for ``variant``; numbers read
    as Gazebo reads them (:func:`diffbot_sim.values.tag_number`, its remarks into ``notes``). Returns
    (config, unknown tags): a tag this copy does not read (``cmdVelTimeOut`` for Hector's) is unknown.

    Raises:
        ConfigError: a value that is not a number, a boolean or a non-empty string, naming the tag.
    """
    values = {"cmd_vel_timeout": variant.cmd_vel_timeout}
    unknown = []
    for tag, text in tags:
        field_kind = TAGS.get(tag)
        if field_kind is None or (tag == "cmdVelTimeOut" and variant.cmd_vel_timeout is None):
            if tag not in IGNORED_TAGS:
                unknown.append(tag)
            continue
        field, kind = field_kind
        label = f"<{tag}> of {path}"
        if kind == "number":
            values[field] = tag_number(label, text, notes)
        elif kind == "bool":
            values[field] = check_bool(label, text)
        else:
            values[field] = check_string(label, text, allow_empty=kind == "namespace")
    return replace(ForceBasedMoveConfig(), **values), unknown


def stable_gain(gain, dt, inertia):
    """(gain to use, True when it is ``gain`` itself) for a P loop pushing ``inertia`` [kg or kg·m^2] towards a
    velocity with force ``gain * error`` applied for whole steps of ``dt`` [s].

    The explicit loop removes ``a = gain * dt / inertia`` of the error per step: well damped while a <=
    2 * STABILITY_MARGIN (as :func:`diffbot_sim.control.pid.explicit_loop_margin` judges velocity loops),
    overshooting beyond, diverging past 2. Gazebo runs it at 1 ms; at a longer step a stiff gain is replaced by
    the one whose step removes what the continuous loop removes in ``dt``: ``inertia * (1 - exp(-a)) / dt``
    (never more than the dead-beat ``inertia / dt``). A non-positive inertia or gain is kept as given."""
    if inertia <= 0 or gain <= 0 or dt <= 0:
        return gain, True
    a = gain * dt / inertia
    if a <= 2.0 * STABILITY_MARGIN:
        return gain, True
    return inertia * -math.expm1(-a) / dt, False


def command_expired(now, last_command, timeout):
    """True when the command must be zeroed: a timeout is set and more than ``timeout`` s of sim time passed
    since the last command arrived at ``last_command`` (None: none ever did)."""
    if timeout is None:
        return False
    return last_command is None or now - last_command > timeout


def wrench(command, body_velocity, world_yaw_rate, gains):
    """(fx, fy) [N] in the base link's axes and the yaw torque [N·m] about the world z that upstream adds
    each update: ``gains`` (x, y, yaw) times the error of ``command`` (x [m/s], y [m/s], yaw rate [rad/s])
    against ``body_velocity`` (vx, vy [m/s], the model's own frame) and ``world_yaw_rate`` [rad/s]."""
    kx, ky, kyaw = gains
    return (kx * (command[0] - body_velocity[0]), ky * (command[1] - body_velocity[1]),
            kyaw * (command[2] - world_yaw_rate))


def motion(vx, vy, wz, dt):
    """(dx, dy, dyaw) [m, m, rad] in the frame at the start of a motion at body velocity (vx, vy) [m/s] and
    yaw rate wz [rad/s] held for ``dt`` [s], as upstream's getTransformForMotion: straight when |wz| <
    STILL_YAW_RATE, in place when the distance along x and along y are both under SPOT_DISTANCE, else along the
    arc of radius distance / angle, turned to the direction of travel."""
    if abs(wz) < STILL_YAW_RATE:
        return vx * dt, vy * dt, 0.0
    dist_x, dist_y, angle = vx * dt, vy * dt, wz * dt
    if abs(dist_x) < SPOT_DISTANCE and abs(dist_y) < SPOT_DISTANCE:
        return 0.0, 0.0, angle
    radius = math.hypot(dist_x, dist_y) / angle
    ax, ay = math.sin(angle) * radius, radius - math.cos(angle) * radius
    heading = math.atan2(dist_y, dist_x)
    c, s = math.cos(heading), math.sin(heading)
    return c * ax - s * ay, s * ax + c * ay, angle


def compose(pose, delta):
    """``pose`` (x, y, yaw) moved by ``delta`` (dx, dy, dyaw) given in its own frame; yaw wrapped to
    (-pi, pi]."""
    x, y, yaw = pose
    dx, dy, dyaw = delta
    c, s = math.cos(yaw), math.sin(yaw)
    return x + c * dx - s * dy, y + s * dx + c * dy, wrap_angle(yaw + dyaw)


def covariances(yaw_rate):
    """(pose diagonal, twist diagonal), six values each, for the odometry at ``yaw_rate`` [rad/s]."""
    yaw = YAW_COVARIANCE_STILL if abs(yaw_rate) < STILL_YAW_RATE else YAW_COVARIANCE_TURNING
    return POSE_COVARIANCE + (yaw,), TWIST_COVARIANCE + (yaw,)


class OdometryIntegrator:
    """The plugin's odometry: a pose (x, y, yaw) in the odometry frame, starting at the origin when the plugin
    loads, moved at each publication by the body's velocity over the time since the last one."""

    def __init__(self, rate, now=0.0):
        self.period = 1.0 / rate if rate > 0 else math.inf
        self.pose = (0.0, 0.0, 0.0)
        self.last = now

    def restart(self, now):
        """Count the next period from ``now`` (sim time restarted: reset_simulation); the pose is kept."""
        self.last = now

    def due(self, now):
        """True once strictly more than a period passed since the last publication (never with rate <= 0)."""
        return now - self.last > self.period + 1e-9

    def next_due(self):
        """Sim time after which :meth:`due` turns true (inf without odometry)."""
        return self.last + self.period + 2e-9

    def advance(self, now, vx, vy, wz):
        """Move the pose by the body velocity (vx, vy [m/s] in its frame, wz [rad/s]) held since the last
        publication, which is now; returns the new pose."""
        self.pose = compose(self.pose, motion(vx, vy, wz, now - self.last))
        self.last = now
        return self.pose
