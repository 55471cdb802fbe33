"""The force-based move plugin family (``libgazebo_ros_force_based_move.so``, Team Hector's, and the vendor
copies ``libridgeback_ros_force_based_move.so`` and ``libnexus_ros_force_based_move.so``): a holonomic base
pushed by a force and a yaw torque from P gains on its velocity error, every step; odometry integrated from
the body's own velocity at ``odometryRate``, TF only when ``publishOdometryTf``. What each copy does, its
tags and what is deliberately different: :mod:`diffbot_sim.control.force_based_move`.

Such a robot's wheels carry no friction (mu 0) and often a ``gazebo_ros_control`` transmission for a
``mecanum_drive_controller`` that Gazebo does not need to move it: that controller type is not simulated (one
warning), and its odometry topic does not exist here; this plugin's own ``odometryTopic`` does, as in Gazebo.
"""

from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

from diffbot_sim.control import force_based_move as fbm
from diffbot_sim.control.command_inbox import CommandInbox
from diffbot_sim.description.plugin_tags import plugin_filename
from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.errors import PluginNotLoaded
from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins.base import PLANAR_TWIST, Plugin, join, twist_callback
from diffbot_sim.transforms import quaternion_from_yaw, rotate

#: The gain tags, in the order of the pure module's gains (x, y, yaw).
GAIN_TAGS = ("x_velocity_p_gain", "y_velocity_p_gain", "yaw_velocity_p_gain")


class ForceBasedMove(Plugin):
    """One force-based move plugin of a robot."""

    #: It moves the body itself (no joints): the simulator must not report the robot as undriven.
    moves_base = True

    def __init__(self, ctx, cfg, variant, path):
        self.ctx, self.cfg, self.path = ctx, cfg, path
        self.filename = variant.filename
        ns = ctx.plugin_namespace(cfg.robot_namespace, "")
        link = cfg.robot_base_frame
        if link not in ctx.model.links:
            raise PluginNotLoaded(f"robotBaseFrame '{link}' is not a link of the model: Gazebo's plugin finds no "
                                  "link to push and crashes at its first update; it is not loaded", None, path)
        carrier = ctx.robot.frames[link][0] if ctx.robot.frames else link
        if carrier != link:
            ctx.warnings.append(f"{path}: robotBaseFrame '{link}' is lumped into '{carrier}' (fixed joint), where "
                                "Gazebo's plugin finds no link and crashes; the force goes to the link carrying it")
        self.link = link
        self.gains = self._gains(ctx, cfg, path)
        self.odom_frame = ctx.frame(ctx.clean_frame(cfg.odometry_frame, path))
        self.base_frame = ctx.frame(ctx.clean_frame(link, path))
        self.command = (0.0, 0.0, 0.0)
        self.last_command = None  # sim time the last command arrived (None: none since load or reset)
        self.inbox = CommandInbox(ctx.sim.wake.set)  # (vx [m/s], vy [m/s], wz [rad/s]) from cmd_vel
        self._pushed_at = None  # sim time of the step the wrench was last added for (once per step)
        self.odometry = fbm.OdometryIntegrator(cfg.odometry_rate)
        self.sub = ctx.subscriber(join(ns, cfg.command_topic), Twist,
                                  twist_callback(ctx, self, self.inbox, PLANAR_TWIST), queue_size=1)
        self.pub = ctx.publisher(join(ns, cfg.odometry_topic), Odometry)
        self.builders = {still: ros_msgs.OdometryBuilder(self.odom_frame, self.base_frame, 0, 0, 0, *fbm.covariances(
            0.0 if still else 1.0)) for still in (True, False)}
        self.tf_builder = ros_msgs.TransformBuilder(self.odom_frame, self.base_frame)

    @staticmethod
    def _gains(ctx, cfg, path):
        """The P gains, each replaced by its exact discrete form where it is too stiff for our step."""
        mass, inertia = ctx.robot.planar_inertia()
        gains = []
        for tag, gain, moved in zip(GAIN_TAGS, (cfg.x_gain, cfg.y_gain, cfg.yaw_gain), (mass, mass, inertia)):
            used, kept = fbm.stable_gain(gain, ctx.cfg.time_step, moved)
            if not kept:
                ctx.warnings.append(
                    f"<{tag}> of {path}: {gain:g} on {moved:.3g} {'kg·m^2' if tag.startswith('yaw') else 'kg'} "
                    f"overshoots at a {ctx.cfg.time_step * 1000:.2f} ms step (Gazebo's is 1 ms); using {used:.4g}, "
                    "the same loop's exact response at this step")
            gains.append(used)
        return tuple(gains)

    def publishers(self):
        return [self.pub]

    def next_control(self):
        return self.ctx.sim.sim_time  # the wrench is added every step, as upstream does each world update

    def next_publish(self):
        return self.odometry.next_due()

    def before_step(self, now):
        command = self.inbox.take()
        if command is not None:
            self.command = command
            self.last_command = now
        if fbm.command_expired(now, self.last_command, self.cfg.cmd_vel_timeout):
            self.command = (0.0, 0.0, 0.0)
        if self._pushed_at == now:
            return  # PyBullet adds up external forces until the step: one wrench per step
        robot = self.ctx.robot
        pose = robot.base_pose()
        linear, angular = robot.base_twist(pose)  # the model's own frame (RelativeLinearVel)
        world_yaw_rate = rotate(pose[1], angular)[2]  # WorldAngularVel().Z()
        fx, fy, torque = fbm.wrench(self.command, linear, world_yaw_rate, self.gains)
        robot.push_link(self.link, (fx, fy, 0.0), (0.0, 0.0, torque))
        self._pushed_at = now

    def after_step(self, now, stamp, transforms):
        if not self.odometry.due(now):
            return
        linear, angular = self.ctx.robot.base_twist()
        x, y, yaw = self.odometry.advance(now, linear[0], linear[1], angular[2])
        position, orientation = (x, y, 0.0), quaternion_from_yaw(yaw)
        if self.pub.get_num_connections():
            builder = self.builders[abs(angular[2]) < fbm.STILL_YAW_RATE]
            self.pub.publish(builder.build(stamp, position, orientation, (linear[0], linear[1], 0.0),
                                           (0.0, 0.0, angular[2])))
        if self.cfg.publish_odometry_tf:
            transforms.append(self.tf_builder.build(stamp, position, orientation))

    def start(self, now):
        self.odometry.restart(now)

    def reset(self, now):
        self.inbox.clear()
        self.command, self.last_command, self._pushed_at = (0.0, 0.0, 0.0), None, None
        self.odometry.restart(now)

    def summary(self):
        cfg = self.cfg
        return {"cmd_vel_topic": self.sub.resolved_name, "odom_topic": self.pub.resolved_name,
                "force_based_move/robot_base_frame": self.link, "force_based_move/odometry_rate": cfg.odometry_rate,
                "force_based_move/cmd_vel_timeout": -1.0 if cfg.cmd_vel_timeout is None else cfg.cmd_vel_timeout,
                "force_based_move/publish_odometry_tf": cfg.publish_odometry_tf,
                "force_based_move/gains": [round(g, 6) for g in self.gains]}


def create(ctx, element, path, params):
    variant = fbm.VARIANTS[plugin_filename(element.get("filename"))]
    tags = [(child.tag, tag_value(child)) for child in element]
    cfg, unknown = fbm.read_config(tags, variant, path, ctx.warnings)
    if unknown:
        ctx.warnings.append(f"{path}: unknown tags ignored: {', '.join(unknown)}")
    return ForceBasedMove(ctx, cfg, variant, path)
