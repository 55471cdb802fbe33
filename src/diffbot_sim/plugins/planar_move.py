"""``libgazebo_ros_planar_move.so`` (ROS 1): holonomic base velocity from ``cmd_vel`` (linear.x, linear.y,
angular.z in the robot's heading), set on the body every step as Gazebo sets the model's velocity; odometry
is the world pose at ``odometryRate``.

Tags (defaults): ``commandTopic`` (cmd_vel), ``odometryTopic`` (odom), ``odometryFrame`` (odom),
``robotBaseFrame`` (base_footprint), ``odometryRate`` (20 Hz), ``publishOdometryTf`` (true),
``cmdTimeout`` (s, <= 0: hold the last command; also ~cmd_vel_timeout), ``robotNamespace``.

Every world update, gazebo_ros_pkgs noetic-devel ``gazebo_ros_planar_move.cpp`` calls the model's
``SetLinearVel`` with the command turned by the model's yaw and a vertical velocity of 0, and ``SetAngularVel``
with (0, 0, angular.z), whatever its wheels, casters and joint motors do; here the root gets that velocity
(:meth:`~diffbot_sim.physics.robot.Robot.set_heading_velocity`, so it floats down slopes as Gazebo's does,
gazebo_ros_pkgs #121). What then holds the body back is the step: braked wheels (a ``gazebo_ros_control``
velocity joint with no controller is held at rest) sliding on the ground take up to mu g dt of the velocity
in every step, 5 % of 0.2 m/s at Gazebo's 1 ms but 20 % at our 1/240 s (measured on a steered-caster base:
0.636 m of 0.8 straight, 0.67 of 1.5 rad turning). So each step the velocity set is the command plus what the
last step took of it (:func:`makeup`): the body moves at the command, as the plugin means it to, while a wall
still stops it. Deliberately not reproduced: ODE's own shortfall at 1 ms, which gives each link the same
linear velocity and lets the joints average them (a Summit XL turns at 0.78 of its command in Gazebo,
summit_xl_sim #35); joint rates are not zeroed either (wheels keep their spin).
"""
import math

from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

from diffbot_sim.control.command_inbox import CommandInbox
from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins.base import PLANAR_TWIST, Plugin, join, twist_callback
from diffbot_sim.values import check_bool, check_string, tag_number

#: The most a step's makeup may add to the command: the commanded speed (linear, m/s) and yaw rate (rad/s), each
#: with the other's share at the body's radius of gyration; a body pressed against a wall is pushed at no more
#: than twice its command.
MAKEUP_LIMIT = 1.0

DEFAULTS = {"commandTopic": "cmd_vel", "odometryTopic": "odom", "odometryFrame": "odom",
            "robotBaseFrame": "base_footprint", "odometryRate": 20.0, "publishOdometryTf": True,
            "cmdTimeout": -1.0, "robotNamespace": None}


class PlanarMove(Plugin):
    filename = "libgazebo_ros_planar_move.so"
    #: It moves the body itself (no joints): the simulator must not report the robot as undriven.
    moves_base = True

    def __init__(self, ctx, values, path):
        self.ctx = ctx
        self.path = path
        ns = ctx.plugin_namespace(values["robotNamespace"])
        self.odom_frame = ctx.frame(ctx.clean_frame(values["odometryFrame"], path))
        self.base_frame = ctx.frame(ctx.clean_frame(values["robotBaseFrame"], path))
        self.period = 1.0 / values["odometryRate"] if values["odometryRate"] > 0 else 0.0
        self.publish_tf = values["publishOdometryTf"]
        timeout = values["cmdTimeout"]
        self.timeout = timeout if timeout > 0 else ctx.cfg.cmd_vel_timeout
        self.command = (0.0, 0.0, 0.0)
        self.stamp = None
        self.inbox = CommandInbox(ctx.sim.wake.set)  # (vx [m/s], vy [m/s], wz [rad/s]) from cmd_vel
        self.makeup = (0.0, 0.0, 0.0)  # added to the command: what the last step took of the velocity set
        self._set, self._set_at = None, None  # the velocity set before the last step, and when
        mass, inertia = ctx.robot.planar_inertia()
        self.gyration = math.sqrt(inertia / mass) if mass > 0 and inertia > 0 else 1.0  # m
        self.sub = ctx.subscriber(join(ns, values["commandTopic"]), Twist,
                                  twist_callback(ctx, self, self.inbox, PLANAR_TWIST), queue_size=1)
        self.pub = ctx.publisher(join(ns, values["odometryTopic"]), Odometry)
        self.builder = ros_msgs.OdometryBuilder(self.odom_frame, self.base_frame, 1e-5, 1e-5, 1e-3)
        self.tf_builder = ros_msgs.TransformBuilder(self.odom_frame, self.base_frame)
        self.summary_values = {k: v for k, v in values.items() if v is not None}

    def publishers(self):
        return [self.pub]

    def next_control(self):
        return self.ctx.sim.sim_time  # the body velocity is set every step, as Gazebo does

    def before_step(self, now):
        command = self.inbox.take()
        if command is not None:
            self.command = command
            self.stamp = now
        command = self.command
        if self.timeout > 0 and self.stamp is not None and now - self.stamp > self.timeout:
            command = self.command = (0.0, 0.0, 0.0)
            self.stamp = None
        robot = self.ctx.robot
        if self._set_at is not None and now > self._set_at + 1e-9:  # once per step, after it
            self.makeup = makeup(command, self._set, robot.heading_velocity(), self.gyration)
        velocity = tuple(c + m for c, m in zip(command, self.makeup))
        robot.set_heading_velocity(*velocity)
        self._set, self._set_at = velocity, now

    def after_step(self, now, stamp, transforms):
        if not self.take_due(now, self.period):
            return
        robot = self.ctx.robot
        position, orientation = robot.base_pose()
        if self.pub.get_num_connections():
            linear, angular = robot.base_twist((position, orientation))
            self.pub.publish(self.builder.build(stamp, position, orientation, linear, angular))
        if self.publish_tf:
            transforms.append(self.tf_builder.build(stamp, position, orientation))

    def reset(self, now):
        self.inbox.clear()
        self.command, self.stamp = (0.0, 0.0, 0.0), None
        self.makeup, self._set, self._set_at = (0.0, 0.0, 0.0), None, None

    def summary(self):
        return dict(self.summary_values, cmd_vel_topic=self.sub.resolved_name, odom_topic=self.pub.resolved_name)


def makeup(command, velocity_set, velocity_after, gyration, limit=MAKEUP_LIMIT):
    """What to add to ``command`` (vx, vy [m/s] in the heading's axes, wz [rad/s]) so that the body moves at it
    over the next step: what the last step took of the velocity set before it (``velocity_set`` minus
    ``velocity_after``, read back after the step), as long as that is at most ``limit`` times the command's
    size: its speed plus its yaw rate times ``gyration`` [m] (the body's radius of gyration) for the linear
    part, its yaw rate plus its speed over ``gyration`` for the yaw. A zero command gets no makeup (the body
    is set at rest, as Gazebo sets it); a wall takes everything, so the makeup stops at the limit."""
    lost = [s - a for s, a in zip(velocity_set, velocity_after)]
    speed, turn = math.hypot(command[0], command[1]), abs(command[2])
    linear_limit, yaw_limit = limit * (speed + turn * gyration), limit * (turn + speed / gyration)
    size = math.hypot(lost[0], lost[1])
    scale = min(1.0, linear_limit / size) if size > 0 else 0.0
    return lost[0] * scale, lost[1] * scale, max(-yaw_limit, min(yaw_limit, lost[2]))


def create(ctx, element, path, params):
    values = dict(DEFAULTS)
    unknown = []
    for child in element:
        text = tag_value(child)
        label = f"<{child.tag}> of {path}"
        if child.tag in ("odometryRate",):
            values[child.tag] = tag_number(label, text, ctx.warnings, low=0.0)
        elif child.tag == "cmdTimeout":
            values[child.tag] = tag_number(label, text, ctx.warnings)
        elif child.tag == "publishOdometryTf":
            values[child.tag] = check_bool(label, text)
        elif child.tag in DEFAULTS:
            values[child.tag] = check_string(label, text, allow_empty=child.tag == "robotNamespace")
        elif child.tag not in ("alwaysOn", "updateRate", "rosDebugLevel"):
            unknown.append(child.tag)
    if unknown:
        ctx.warnings.append(f"{path}: unknown tags ignored: {', '.join(unknown)}")
    return PlanarMove(ctx, values, path)
