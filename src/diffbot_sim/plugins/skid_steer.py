"""``libgazebo_ros_skid_steer_drive.so`` (ROS 1): four wheels, two per side, driven like a diff drive.

What differs from the diff drive is only configuration (:func:`diffbot_sim.config.skid_steer_config`):
tags ``leftFrontJoint``... ``torque``, ``broadcastTF`` (default false); odometry is always the world pose
with covariances ``covariance_x/y/yaw`` (1e-4, 1e-4, 0.01); no acceleration limit, no timeout.
"""
from diffbot_sim import config as cfgmod
from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.plugins.diff_drive import GazeboDiffDrive

#: Tags the ROS 1 plugin has (or had) that change nothing here.
IGNORED = {"alwaysOn", "rosDebugLevel", "legacyMode", "publishWheelTF", "publishWheelJointState",
           "wheelAcceleration"}


class SkidSteerDrive(GazeboDiffDrive):
    filename = "libgazebo_ros_skid_steer_drive.so"


def create(ctx, element, path, params):
    values = {child.tag: tag_value(child) for child in element}
    drive = cfgmod.skid_steer_config(ctx.model, values, path, ctx.warnings)
    drive.namespace = ctx.plugin_namespace(drive.namespace)
    drive.odometry_frame = ctx.frame(ctx.clean_frame(drive.odometry_frame, path))
    drive.robot_base_frame = ctx.frame(ctx.clean_frame(drive.robot_base_frame, path))
    unknown = sorted(set(values) - set(cfgmod.SKID_STEER_TAGS) - IGNORED)
    if unknown:
        ctx.warnings.append(f"{path}: unknown tags ignored: {', '.join(unknown)}")
    return SkidSteerDrive(ctx, drive)

