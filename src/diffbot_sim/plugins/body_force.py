"""``libgazebo_ros_force.so`` (ROS 1 model plugin): a geometry_msgs/Wrench on ``topicName`` pushes ``bodyName``,
as gazebo_ros_force does: the last wrench received is applied at every physics step, the force in world axes
at the link's centre of mass (Link::AddForce), the torque in world axes (Link::AddTorque), until another
arrives. Tags: ``robotNamespace``, ``bodyName`` and ``topicName`` (both required: upstream does not load
without them), a link Gazebo has (a lumped one is its carrier here)."""
import numpy as np
from geometry_msgs.msg import Wrench

from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.errors import PluginNotLoaded
from diffbot_sim.plugins.base import Plugin, join, summary_key
from diffbot_sim.transforms import quaternion_matrix


class BodyForce(Plugin):
    filename = "libgazebo_ros_force.so"

    def __init__(self, ctx, link, topic):
        self.ctx, self.link = ctx, link
        self.wrench = None  # (force, torque) in world axes, or None before the first message
        self.sub = ctx.subscriber(topic, Wrench, self._on_wrench, queue_size=1)

    def _on_wrench(self, msg):
        self.wrench = ((msg.force.x, msg.force.y, msg.force.z), (msg.torque.x, msg.torque.y, msg.torque.z))
        self.ctx.sim.wake.set()

    def next_control(self):
        return self.ctx.sim.sim_time if self.wrench is not None else float("inf")

    def before_step(self, now):
        if self.wrench is None:
            return
        force, torque = self.wrench
        rotation = np.asarray(quaternion_matrix(self.ctx.robot.link_pose(self.link)[1]), float)
        self.ctx.robot.push_link(self.link, tuple(rotation.T @ np.asarray(force, float)), torque)

    def reset(self, now):
        self.wrench = None

    def summary(self):
        return {summary_key("plugin", f"force/{self.link}"): self.sub.resolved_name}


def create(ctx, element, path, params):
    tags = {child.tag: tag_value(child) for child in element}
    for key in ("bodyName", "topicName"):
        if not tags.get(key):
            raise PluginNotLoaded(f"{path}: force plugin missing <{key}>, cannot proceed (as upstream)")
    link = tags["bodyName"].strip()
    try:
        ctx.robot.link_pose(link)
    except KeyError:
        raise PluginNotLoaded(f"{path}: <bodyName> '{link}' is no link of the model; not loaded") from None
    ns = ctx.plugin_namespace(tags["robotNamespace"].strip() if "robotNamespace" in tags else None, "/")
    return BodyForce(ctx, link, join(ns, tags["topicName"].strip()))
