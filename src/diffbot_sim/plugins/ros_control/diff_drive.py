"""``diff_drive_controller/DiffDriveController`` on the hardware: ``<controller>/cmd_vel`` in,
``<controller>/odom`` out, ``/tf`` when ``enable_odom_tf``, ``<controller>/cmd_vel_out`` when ``publish_cmd``;
geometry from the URDF where the YAML gives none (first left/right joint origins, the first left wheel's
cylinder or sphere collision). The controller's logic is :mod:`diffbot_sim.control.diff_drive_controller`."""
from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.msg import Odometry

from diffbot_sim.control import diff_drive_config as ddc_cfg
from diffbot_sim.control.command_inbox import CommandInbox
from diffbot_sim.control.diff_drive_controller import DiffDriveControllerCore
from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins.base import join
from diffbot_sim.plugins.ros_control.controller import Controller
from diffbot_sim.transforms import quaternion_from_yaw


class DiffDriveController(Controller):
    type = ddc_cfg.CONTROLLER_TYPE
    interface = "VelocityJointInterface"

    def __init__(self, ctx, hw, name, params):
        super().__init__(ctx, hw, name, params)
        model = ctx.model
        cfg = ddc_cfg.diff_drive_controller_config(params, name)
        for warning in cfg.warnings:
            ctx.warnings.append(warning)
        if cfg.unknown_keys:
            ctx.warnings.append(f"{name}: parameters DiffDriveController does not read, ignored: "
                                f"{', '.join(cfg.unknown_keys)}")
        for joint in cfg.joints:
            self.require_interface(joint, self.interface)
        separation = radius = None
        if cfg.wheel_separation is None:
            separation = model.wheel_separation(cfg.left_wheels[0], cfg.right_wheels[0], name)
        if cfg.wheel_radius is None:
            radius = model.wheel_radius(cfg.left_wheels[0], name)
        self.core = DiffDriveControllerCore(cfg, separation, radius)
        self.cfg = cfg
        self.odom_frame = ctx.frame(cfg.odom_frame_id)
        self.base_frame = ctx.frame(cfg.base_frame_id)
        self.inbox = CommandInbox(ctx.sim.wake.set)  # (linear.x, angular.z, publishers of cmd_vel then)
        self.sub = self.own(ctx.subscriber(join(name, "cmd_vel"), Twist, self._on_twist, queue_size=1))
        self.odom_pub = self.own(ctx.publisher(join(name, "odom"), Odometry))
        self.cmd_out_pub = (self.own(ctx.publisher(join(name, "cmd_vel_out"), TwistStamped)) if cfg.publish_cmd
                            else None)
        self.odom_builder = ros_msgs.OdometryBuilder(self.odom_frame, self.base_frame, 0, 0, 0,
                                                     pose_diagonal=cfg.pose_covariance_diagonal,
                                                     twist_diagonal=cfg.twist_covariance_diagonal)
        self.tf_builder = ros_msgs.TransformBuilder(self.odom_frame, self.base_frame)

    def _on_twist(self, msg):
        self.inbox.put((msg.linear.x, msg.angular.z, self.sub.get_num_connections()))

    def joints(self):
        return set(self.cfg.joints)

    def publishers(self):
        return [p for p in (self.odom_pub, self.cmd_out_pub) if p is not None]

    def start(self, now):
        super().start(now)
        self.core.starting(now)

    def stop(self, now):
        """diff_drive_controller's stopping(): the wheels are braked."""
        super().stop(now)
        for joint in self.cfg.joints:
            self.hw.set_command(joint, 0.0)

    def update(self, now, period, stamp, transforms):
        command = self.inbox.take()
        if command is not None:
            linear, angular, count = command
            why = self.core.set_command(linear, angular, now, count)
            if why is not None:
                self.ctx.sim.warn(f"ddc:{self.name}", f"{self.name}: {why}")
        left = self.hw.positions(self.cfg.left_wheels)
        right = self.hw.positions(self.cfg.right_wheels)
        step = self.core.update(now, left, right, period)
        for joint in self.cfg.left_wheels:
            self.hw.set_command(joint, step.left)
        for joint in self.cfg.right_wheels:
            self.hw.set_command(joint, step.right)
        if step.publish_odom:
            x, y, yaw = self.core.pose
            linear, angular = self.core.velocity
            orientation = quaternion_from_yaw(yaw)
            if self.odom_pub.get_num_connections():
                self.odom_pub.publish(self.odom_builder.build(stamp, (x, y, 0.0), orientation, (linear, 0.0, 0.0),
                                                              (0.0, 0.0, angular)))
            if self.cfg.enable_odom_tf:
                transforms.append(self.tf_builder.build(stamp, (x, y, 0.0), orientation))
        if self.cmd_out_pub is not None and not step.skipped and self.cmd_out_pub.get_num_connections():
            lin, ang = self.core.last_command
            self.cmd_out_pub.publish(ros_msgs.twist_stamped(stamp, lin, ang))

    def summary(self):
        return {f"{self.name}/wheel_separation": self.core.separation,
                f"{self.name}/wheel_radius": self.core.left_radius,
                "cmd_vel_topic": self.sub.resolved_name, "odom_topic": self.odom_pub.resolved_name}
