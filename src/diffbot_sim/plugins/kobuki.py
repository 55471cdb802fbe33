"""``libgazebo_ros_kobuki.so``: the TurtleBot 2 (Kobuki) base, as kobuki_gazebo_plugins (melodic) runs it.

Tags (snake_case): ``left_wheel_joint_name``, ``right_wheel_joint_name``, ``wheel_separation``,
``wheel_diameter``, ``torque``, ``velocity_command_timeout`` (all required by the original, which refuses to
load without them), ``publish_tf`` (default false), ``imu_name``, ``update_rate`` (default 50 Hz);
``cliff_sensor_*``, ``bumper_name``, ``base_collision_model_link`` are accepted.

Topics, in the plugin's namespace (``robotNamespace``; the spawner's ``/`` by default), ``base_prefix`` being
the ROS parameter ``<ns>/base_prefix`` (a ``<base_prefix>`` tag also accepted; default ``mobile_base``):
``<base_prefix>/commands/velocity`` (Twist in), ``<base_prefix>/commands/reset_odometry`` (std_msgs/Empty
in), ``odom`` (frames ``odom`` -> ``base_footprint``, fixed as in the original; TF when ``publish_tf``),
``joint_states`` (both wheels), ``<base_prefix>/sensors/imu_data`` (sensor_msgs/Imu of the base).
Odometry integrates wheel speed x radius for distance and the IMU's yaw rate for heading, as the original
does. With kobuki_msgs (the overlay's): ``<base_prefix>/commands/motor_power`` (MotorPower: off, the wheels
are held at rest), ``events/bumper``, ``events/cliff``, ``events/wheel_drop`` and ``sensors/core``
(:mod:`.kobuki_events`).
"""
import math

import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu, JointState
from std_msgs.msg import Empty

from diffbot_sim.control.command_inbox import CommandInbox
from diffbot_sim.control.kinematics import wheel_speeds
from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.errors import ModelError
from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins.base import DRIVE_TWIST, Plugin, join, twist_callback
from diffbot_sim.plugins.joint_motors import UNLIMITED_EFFORT
from diffbot_sim.plugins.kobuki_events import KobukiEvents
from diffbot_sim.transforms import quaternion_from_yaw
from diffbot_sim.values import check_bool, check_string, tag_number

REQUIRED = ("left_wheel_joint_name", "right_wheel_joint_name", "wheel_separation", "wheel_diameter",
            "torque", "velocity_command_timeout")
ACCEPTED = ("cliff_sensor_left_name", "cliff_sensor_center_name", "cliff_sensor_front_name",
            "cliff_sensor_right_name", "cliff_detection_threshold", "bumper_name", "base_collision_model_link",
            "robotNamespace", "publish_tf", "imu_name", "update_rate", "base_prefix", "alwaysOn",
            "wheel_drop_left_sensor_name", "wheel_drop_right_sensor_name")
#: The original's fixed odometry covariances (pose x, y, yaw; unobserved axes 1e6).
POSE_COVARIANCE = (0.1, 0.1, 1e6, 1e6, 1e6, 0.05)


class Kobuki(Plugin):
    filename = "libgazebo_ros_kobuki.so"

    def __init__(self, ctx, values, path, base_prefix, ns, tags=None):
        self.ctx = ctx
        self.values = values
        tags = tags or {}
        model, robot = ctx.model, ctx.robot
        self.joints_ = [values["left_wheel_joint_name"], values["right_wheel_joint_name"]]
        for name in self.joints_:
            model.joint(name, path)
        self.idx = robot.indices(self.joints_)
        self.radius = values["wheel_diameter"] / 2.0
        self.separation = values["wheel_separation"]
        self.torque = values["torque"] if values["torque"] > 0 else UNLIMITED_EFFORT
        self.timeout = values["velocity_command_timeout"]
        self.period = 1.0 / values["update_rate"] if values["update_rate"] > 0 else 0.0
        self.publish_tf = values["publish_tf"]
        self.odom_frame, self.base_frame = ctx.frame("odom"), ctx.frame("base_footprint")
        self.wheel_cmd = (0.0, 0.0)
        self.cmd_time = None
        self.holding = False  # the wheel motors have been given a target (they keep it between updates)
        self.x = self.y = self.yaw = 0.0
        self.last_time = None
        self._imu_velocity = None  # world velocity of the base frame at the last update (accelerometer)
        self.inbox = CommandInbox(ctx.sim.wake.set)  # (linear.x [m/s], angular.z [rad/s]) from commands/velocity
        self._reset_odom = False
        prefix = base_prefix.strip("/")
        self.cmd_sub = ctx.subscriber(join(ns, f"{prefix}/commands/velocity"), Twist,
                                      twist_callback(ctx, self, self.inbox, DRIVE_TWIST), queue_size=1)
        self.reset_sub = ctx.subscriber(join(ns, f"{prefix}/commands/reset_odometry"), Empty,
                                          self._on_reset, queue_size=1)
        self.odom_pub = ctx.publisher(join(ns, "odom"), Odometry)
        self.js_pub = ctx.publisher(join(ns, "joint_states"), JointState)
        ctx.publishes_joint_states(self.js_pub, self.joints_)
        self.imu_pub = ctx.publisher(join(ns, f"{prefix}/sensors/imu_data"), Imu)
        self.odom_builder = ros_msgs.OdometryBuilder(self.odom_frame, self.base_frame, 0, 0, 0,
                                                     pose_diagonal=POSE_COVARIANCE,
                                                     twist_diagonal=(0.0,) * 6)
        self.tf_builder = ros_msgs.TransformBuilder(self.odom_frame, self.base_frame)
        self.js_builder = ros_msgs.JointStateBuilder(self.joints_)
        self.imu_frame = ctx.frame("base_link")
        self.topics = {"cmd_vel_topic": self.cmd_sub.resolved_name, "odom_topic": self.odom_pub.resolved_name}
        self.motors_enabled = True
        self.events, self.power_sub = None, None
        try:
            from kobuki_msgs.msg import MotorPower

            self.events = KobukiEvents(ctx, tags, path, ns, prefix)
            self.power_sub = ctx.subscriber(join(ns, f"{prefix}/commands/motor_power"), MotorPower,
                                            self._on_motor_power, queue_size=10)
        except ImportError:  # the overlay left out
            ctx.warnings.append(f"{path}: kobuki_msgs is not built (overlay left out): no {join(ns, prefix)}/events/"
                                "bumper, cliff, wheel_drop, sensors/core, commands/motor_power")

    # -- callbacks ----------------------------------------------------------------------------------
    def _on_reset(self, _msg):
        self._reset_odom = True

    def _on_motor_power(self, msg):
        self.motors_enabled = msg.state == msg.ON  # read on the loop's next command update
        self.ctx.sim.wake.set()

    # -- loop ---------------------------------------------------------------------------------------
    def joints(self):
        return set(self.joints_)

    def publishers(self):
        return [self.odom_pub, self.js_pub, self.imu_pub] + (self.events.publishers() if self.events else [])

    def next_control(self):
        if self.cmd_time is not None and self.wheel_cmd != (0.0, 0.0):
            return self.cmd_time + self.timeout
        return math.inf

    def before_step(self, now):
        command = self.inbox.take()
        if command is not None:
            linear, angular = command
            self.wheel_cmd = wheel_speeds(linear, angular, self.separation)
            self.cmd_time = now
        elif self.cmd_time is not None and now - self.cmd_time > self.timeout:
            self.wheel_cmd, self.cmd_time = (0.0, 0.0), None  # stale: stop, as the original does
        elif self.holding and self.motors_enabled:
            return  # the motors keep their targets
        # The original sets the wheel velocities with the torque limit on every update, from the first one: the
        # wheels are held at 0 before any command (free wheels let a robot on frictionless casters roll away).
        self.holding = True
        left, right = self.wheel_cmd if self.motors_enabled else (0.0, 0.0)  # motors off: no speed, as upstream
        self.ctx.robot.set_velocities(self.idx, [left / self.radius, right / self.radius], [self.torque] * 2)

    def after_step(self, now, stamp, transforms):
        if not self.take_due(now, self.period):
            return
        robot = self.ctx.robot
        positions, velocities, efforts = robot.joint_states(self.idx)
        pose = robot.base_pose()
        linear, angular = robot.base_twist(pose)
        dt = 0.0 if self.last_time is None else now - self.last_time
        self.last_time = now
        if self._reset_odom:
            self._reset_odom = False
            self.x = self.y = self.yaw = 0.0
        distance = dt * self.radius * (velocities[0] + velocities[1]) / 2.0
        yaw_rate = angular[2]  # the IMU's rate about its z (the base's; the IMU sits on the rigid base)
        self.x += distance * math.cos(self.yaw)
        self.y += distance * math.sin(self.yaw)
        self.yaw += yaw_rate * dt
        orientation = quaternion_from_yaw(self.yaw)
        speed = distance / dt if dt > 0 else 0.0
        if self.odom_pub.get_num_connections():
            self.odom_pub.publish(self.odom_builder.build(stamp, (self.x, self.y, 0.0), orientation,
                                                          (speed, 0.0, 0.0), (0.0, 0.0, yaw_rate)))
        if self.publish_tf:
            transforms.append(self.tf_builder.build(stamp, (self.x, self.y, 0.0), orientation))
        if self.js_pub.get_num_connections():
            self.js_pub.publish(self.js_builder.build(stamp, positions, velocities, efforts))
        # The accelerometer differences the base's velocity over each update, subscribed or not, so the
        # first message after an idle spell is not a difference over the whole spell.
        _, rates, accel, self._imu_velocity = robot.link_imu(self.ctx.model.root, self._imu_velocity, dt)
        if self.imu_pub.get_num_connections():
            self.imu_pub.publish(ros_msgs.imu(stamp, self.imu_frame, pose[1], rates, accel))
        if self.events is not None:
            self.events.update(stamp)

    def start(self, now):
        self.next, self.last_time = self.first_due(now, self.period), now
        self._imu_velocity = None
        self.x = self.y = self.yaw = 0.0

    def reset(self, now):
        self.inbox.clear()
        self.wheel_cmd, self.cmd_time = (0.0, 0.0), None
        self.ctx.robot.set_velocities(self.idx, [0.0, 0.0], [self.torque] * 2)
        self.start(now)

    def summary(self):
        return dict(self.values, **self.topics)


def create(ctx, element, path, params):
    tags = {child.tag: tag_value(child) for child in element}
    missing = [t for t in REQUIRED if t not in tags]
    if missing:
        raise ModelError(f"the Kobuki plugin needs <{missing[0]}> (it refuses to load without it)",
                         ctx.model.source, path)
    notes = ctx.warnings
    values = {
        "left_wheel_joint_name": check_string(f"<left_wheel_joint_name> of {path}", tags["left_wheel_joint_name"]),
        "right_wheel_joint_name": check_string(f"<right_wheel_joint_name> of {path}", tags["right_wheel_joint_name"]),
        "wheel_separation": tag_number(f"<wheel_separation> of {path}", tags["wheel_separation"], notes,
                                       low=0.0, low_open=True),
        "wheel_diameter": tag_number(f"<wheel_diameter> of {path}", tags["wheel_diameter"], notes, low=0.0,
                                     low_open=True),
        "torque": tag_number(f"<torque> of {path}", tags["torque"], notes, low=0.0),
        "velocity_command_timeout": tag_number(f"<velocity_command_timeout> of {path}",
                                               tags["velocity_command_timeout"], notes, low=0.0),
        "publish_tf": check_bool(f"<publish_tf> of {path}", tags.get("publish_tf", "false")),
        "update_rate": tag_number(f"<update_rate> of {path}", tags.get("update_rate", 50.0), notes, low=0.0),
    }
    unknown = sorted(set(tags) - set(REQUIRED) - set(ACCEPTED))
    if unknown:
        ctx.warnings.append(f"{path}: unknown tags ignored: {', '.join(unknown)}")
    ns = ctx.plugin_namespace(tags.get("robotNamespace"), "/")
    # The original reads base_prefix as a ROS parameter of its node handle (<ns>/base_prefix).
    base_prefix = tags.get("base_prefix") or rospy.get_param(join(ns, "base_prefix"), "mobile_base")
    return Kobuki(ctx, values, path, str(base_prefix), ns, tags)
