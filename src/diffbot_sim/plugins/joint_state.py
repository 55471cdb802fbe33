"""``libgazebo_ros_joint_state_publisher.so``: ``joint_states`` (name, position, velocity, effort) at
``updateRate``; also the drive's wheels when the drive says ``publishWheelJointState``.

Tags and defaults: :class:`diffbot_sim.config.JointStateConfig`.
"""
from sensor_msgs.msg import JointState

from diffbot_sim import config as cfgmod
from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins.base import Plugin, join


class JointStatePublisher(Plugin):
    filename = "libgazebo_ros_joint_state_publisher.so"

    def __init__(self, ctx, cfg, topic=None):
        self.ctx = ctx
        self.cfg = cfg
        self.indices = ctx.robot.indices(cfg.joints)
        self.pub = ctx.publisher(topic or join(cfg.namespace, cfg.topic), JointState)
        ctx.publishes_joint_states(self.pub, cfg.joints)
        self.builder = ros_msgs.JointStateBuilder(list(cfg.joints))
        self.period = 1.0 / cfg.update_rate if cfg.update_rate > 0 else 0.0

    def publishers(self):
        return [self.pub]

    def after_step(self, now, stamp, transforms):
        if not self.take_due(now, self.period):
            return
        if self.pub.get_num_connections():  # nobody listening: skip the read-out and the message
            positions, velocities, efforts = self.ctx.robot.joint_states(self.indices)
            self.pub.publish(self.builder.build(stamp, positions, velocities, efforts))

    def summary(self):
        return {"joint_states": ",".join(self.cfg.joints)}


def create(ctx, block, drive):
    """From the plugin block (may be None) and the drive (its publishWheelJointState); None if no joints."""
    cfg = cfgmod.joint_state_config(ctx.model, block, drive, ctx.warnings)
    if cfg is None:
        return None
    if ctx.namespace:
        cfg.namespace = ctx.namespace
    return JointStatePublisher(ctx, cfg)
