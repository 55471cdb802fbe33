"""``libgazebo_ros_diff_drive.so`` (ROS 1 and ROS 2 tags) and, with other tags and defaults,
``libgazebo_ros_skid_steer_drive.so`` (see :mod:`diffbot_sim.plugins.skid_steer`).

Tags, defaults and validation: :class:`diffbot_sim.config.GazeboDiffDriveConfig` (one place). What it does
each step (commands, schedule, timeout, limits, wheel speeds):
:class:`diffbot_sim.control.gazebo_diff_drive.GazeboDiffDriveCore`, the one engine the Gymnasium scene drives
too; this module adds the ROS side and the odometry.

Topics (relative to the plugin's namespace): ``cmd_vel`` in (Twist: linear.x, angular.z), ``odom`` out,
``/tf`` odometry frame -> base frame when publish_odom_tf; ``~debug/cmd_applied`` when asked.
"""
import time

import rospy
from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.msg import Odometry

from diffbot_sim import config as cfgmod
from diffbot_sim.control.gazebo_diff_drive import DriveWheels, GazeboDiffDriveCore
from diffbot_sim.control.odometry import EncoderOdometry
from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins.base import DRIVE_TWIST, Plugin, join, next_due, twist_callback
from diffbot_sim.transforms import quaternion_from_yaw


class GazeboDiffDrive(Plugin):
    """One differential (or skid-steer) drive: cmd_vel -> wheel velocity motors; odometry out."""

    filename = "libgazebo_ros_diff_drive.so"

    def __init__(self, ctx, drive):
        """``drive``: a validated GazeboDiffDriveConfig (frames already prefixed and namespace placed)."""
        self.ctx = ctx
        self.drive = drive
        cfg, robot = ctx.cfg, ctx.robot
        self.max_wheel_velocity = cfgmod.max_wheel_velocity(cfg, ctx.model, drive)
        self.core = GazeboDiffDriveCore(drive.wheel_separation, drive.wheel_radius, self.max_wheel_velocity,
                                        drive.max_wheel_acceleration, cfg.cmd_vel_timeout, drive.update_rate,
                                        cfg.time_step, ctx.sim.wake.set)
        self.left_idx = robot.indices(drive.left_joints)
        self.right_idx = robot.indices(drive.right_joints)
        self.wheels = DriveWheels(robot, self.left_idx, self.right_idx, cfgmod.wheel_efforts(ctx.model, drive))
        self.update_period = self.core.update_period
        self.next_odom = 0.0
        self.encoder = EncoderOdometry(drive.wheel_radius, drive.wheel_separation)
        ns = drive.namespace
        # Validated here, on rospy's thread: a good command followed by a NaN one keeps the good one, as
        # diff_drive_controller does; the loop takes the newest at once in real time, at the next step in fast mode.
        self.cmd_sub = ctx.subscriber(join(ns, drive.command_topic), Twist,
                                      twist_callback(ctx, self, self.core.inbox, DRIVE_TWIST), queue_size=1)
        self.odom_pub = ctx.publisher(join(ns, drive.odometry_topic), Odometry) if drive.publish_odom else None
        self.odom_builder = ros_msgs.OdometryBuilder(drive.odometry_frame, drive.robot_base_frame,
                                                     drive.covariance_x, drive.covariance_y, drive.covariance_yaw)
        self.tf_builder = ros_msgs.TransformBuilder(drive.odometry_frame, drive.robot_base_frame)
        self.debug_pub = (ctx.publisher(ctx.private + "debug/cmd_applied", TwistStamped)
                          if cfg.debug_cmd_applied else None)

    # -- loop ---------------------------------------------------------------------------------------
    def joints(self):
        return set(self.drive.left_joints + self.drive.right_joints)

    def publishers(self):
        return [p for p in (self.odom_pub, self.debug_pub) if p is not None]

    def next_control(self):
        return self.core.next_update

    def next_publish(self):
        return self.next_odom

    def before_step(self, now):
        applied = self.core.before_step(now, self.wheels)
        if applied is not None and self.debug_pub is not None:
            self.debug_pub.publish(ros_msgs.twist_stamped(rospy.Time.from_sec(time.time()), *applied))

    def after_step(self, now, stamp, transforms):
        if now + 1e-9 < self.next_odom:
            return
        self.next_odom = next_due(self.next_odom, self.update_period, now)
        drive, robot = self.drive, self.ctx.robot
        if drive.odometry_source == "encoder":
            positions, _, _ = robot.joint_states([self.left_idx[0], self.right_idx[0]])
            self.encoder.update(positions[0], positions[1], now)
            enc = self.encoder
            position = (enc.x, enc.y, 0.0)
            orientation = quaternion_from_yaw(enc.yaw)
            linear, angular = (enc.linear, 0.0, 0.0), (0.0, 0.0, enc.angular)
        else:
            position, orientation = robot.base_pose()
            linear, angular = robot.base_twist((position, orientation))
        if self.odom_pub is not None and self.odom_pub.get_num_connections():
            self.odom_pub.publish(self.odom_builder.build(stamp, position, orientation, linear, angular))
        if drive.publish_odom_tf:
            transforms.append(self.tf_builder.build(stamp, position, orientation))

    def start(self, now):
        self.core.start(now)
        self.next_odom = self.first_due(now, self.update_period)
        positions, _, _ = self.ctx.robot.joint_states([self.left_idx[0], self.right_idx[0]])
        self.encoder.reset(positions[0], positions[1], now)

    def reset(self, now):
        self.core.reset()
        self.wheels.brake()

    def summary(self):
        params = cfgmod.as_params(self.drive)
        params["wheel_radius"] = self.drive.wheel_radius
        params["effective_max_wheel_velocity"] = self.max_wheel_velocity
        params["cmd_vel_topic"] = self.cmd_sub.resolved_name
        if self.odom_pub is not None:
            params["odom_topic"] = self.odom_pub.resolved_name
        return params


def create(ctx, block, params):
    """The model's diff drive (``block`` may be None when ``~left_joints`` describes one), or None."""
    drive = cfgmod.gazebo_diff_drive_config(ctx.model, block, params, ctx.warnings)
    if drive is None:
        return None
    where = block.path if block is not None else "private parameters"
    drive.odometry_frame = ctx.clean_frame(drive.odometry_frame, where)
    drive.robot_base_frame = ctx.clean_frame(drive.robot_base_frame, where)
    if ctx.namespace:
        cfgmod.place_in_namespace(ctx.spec, drive, None)
    else:  # a spawned robot: the tf_prefix its namespace's searchParam found (Noetic's gazebo_ros_utils)
        drive.odometry_frame = ctx.frame(drive.odometry_frame)
        drive.robot_base_frame = ctx.frame(drive.robot_base_frame)
    return GazeboDiffDrive(ctx, drive)
