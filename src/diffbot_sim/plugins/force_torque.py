"""Force-torque sensing: ``libgazebo_ros_ft_sensor.so`` (ROS 1 model plugin) and ``<sensor type="force_torque">``
(with ROS 2's sensor plugin of the same filename), geometry_msgs/WrenchStamped of a joint's wrench.

The wrench is Gazebo's Joint::GetForceTorque: the force and torque the joint applies on its child link, in the
child's frame, the torque about the joint's origin (:mod:`diffbot_sim.physics.force_torque`). The joint must
exist in Gazebo: a fixed joint that sdformat lumps does not (upstream: "jointName ... does not exist", the
plugin does nothing); ``<gazebo reference="joint"><preserveFixedJoint>true`` keeps it, here too.

ROS 1 model plugin tags: ``robotNamespace``, ``jointName`` and ``topicName`` (both required), ``gaussianNoise``
(stddev added to each of the six values, seeded by ``~seed``), ``updateRate`` (0: every step); frame: the child
link (with tf_prefix); published only while subscribed, as upstream.

``<sensor type="force_torque">`` (on a joint: ``<gazebo reference="joint">``): ``<update_rate>``,
``<force_torque><frame>`` child (default) / parent / sensor and ``<measure_direction>`` child_to_parent
(default: the force on the child, as Gazebo's sensor reads body2Force) / parent_to_child (negated); its ROS 2
plugin publishes on ``<ros><namespace>``/``wrench`` (remappable) in ``frame_name`` (default the child link).
"""
import zlib

import numpy as np
from geometry_msgs.msg import WrenchStamped

from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.errors import ConfigError, PluginNotLoaded
from diffbot_sim.physics.force_torque import enable_sensor, joint_by_name, joint_wrench
from diffbot_sim.plugins.base import Plugin, join, summary_key
from diffbot_sim.transforms import quaternion_matrix, rpy_quaternion
from diffbot_sim.values import tag_number


def _frame_rotation(rpy):
    return np.asarray(quaternion_matrix(rpy_quaternion(*rpy)), float)


class ForceTorque(Plugin):
    filename = "libgazebo_ros_ft_sensor.so"
    sensor = True
    sensor_timer = True  # the model plugin too: its last update time starts at 0, not at Load

    def __init__(self, ctx, path, joint, topic, frame, period, stddev, rotation=None, sign=1.0):
        self.ctx, self.path, self.joint_name = ctx, path, joint
        self.index = joint_by_name(ctx.robot, joint)
        if self.index is None:
            raise PluginNotLoaded(f"{path}: joint '{joint}' does not exist in the simulated model (a fixed joint "
                                  "Gazebo lumps: give it <preserveFixedJoint>true</preserveFixedJoint>); the "
                                  "force-torque plugin is not loaded, as in Gazebo")
        enable_sensor(ctx.robot, self.index)
        self.period, self.stddev, self.frame = period, stddev, frame
        self.rotation, self.sign = rotation, sign  # into the reported frame; -1: parent_to_child
        self.rng = np.random.default_rng([ctx.cfg.seed & 0xFFFFFFFF, zlib.crc32(path.encode())])
        self.pub = ctx.publisher(topic, WrenchStamped)
        self.msg = WrenchStamped()
        self.msg.header.frame_id = frame

    def publishers(self):
        return [self.pub]

    def measure(self):
        """(force, torque) as the plugin reports them, before noise."""
        force, torque = (np.asarray(v, float) for v in joint_wrench(self.ctx.robot, self.index))
        if self.rotation is not None:
            force, torque = self.rotation.T @ force, self.rotation.T @ torque
        return self.sign * force, self.sign * torque

    def after_step(self, now, stamp, transforms):
        if not self.take_due(now, self.period) or not self.pub.get_num_connections():
            return
        force, torque = self.measure()
        if self.stddev > 0:
            force = force + self.rng.normal(0.0, self.stddev, 3)
            torque = torque + self.rng.normal(0.0, self.stddev, 3)
        w = self.msg.wrench
        w.force.x, w.force.y, w.force.z = (float(v) for v in force)
        w.torque.x, w.torque.y, w.torque.z = (float(v) for v in torque)
        self.msg.header.stamp = stamp
        self.pub.publish(self.msg)

    def summary(self):
        return {summary_key("sensor", self.path): f"force-torque of {self.joint_name} on {self.pub.resolved_name} "
                                                  f"in {self.frame}"}


def create_model(ctx, element, path, params):
    """ROS 1's model plugin."""
    tags = {child.tag: tag_value(child) for child in element}
    for key in ("jointName", "topicName"):
        if not tags.get(key):
            raise PluginNotLoaded(f"{path}: ft_sensor plugin missing <{key}>, cannot proceed (as upstream)")
    joint = ctx.model.joint(tags["jointName"].strip(), path)
    ns = ctx.plugin_namespace(tags["robotNamespace"].strip() if "robotNamespace" in tags else None, "/")
    stddev = tag_number(f"<gaussianNoise> of {path}", tags["gaussianNoise"], ctx.warnings, low=0.0) \
        if tags.get("gaussianNoise") else 0.0
    rate = tag_number(f"<updateRate> of {path}", tags["updateRate"], ctx.warnings, low=0.0) \
        if tags.get("updateRate") else 0.0
    return ForceTorque(ctx, path, joint.name, join(ns, tags["topicName"].strip()), ctx.frame(joint.child),
                       1.0 / rate if rate > 0 else 0.0, stddev)


def create_sensor(ctx, sensor, element, params):
    """``<sensor type="force_torque">`` with ROS 2's plugin."""
    path = f"{sensor.path}/plugin[@name='{element.get('name')}']"
    if sensor.type != "force_torque":
        raise ConfigError(f"<sensor type> of {path}", sensor.type, "force_torque")
    joint = ctx.model.joint(sensor.link or "", sensor.path)
    ft = sensor.element.find("force_torque")
    frame_kind = ((ft.findtext("frame") if ft is not None else None) or "child").strip()
    direction = ((ft.findtext("measure_direction") if ft is not None else None) or "child_to_parent").strip()
    if frame_kind not in ("child", "parent", "sensor"):
        raise ConfigError(f"{sensor.path}/force_torque/frame", frame_kind, "child, parent or sensor")
    if direction not in ("child_to_parent", "parent_to_child"):
        raise ConfigError(f"{sensor.path}/force_torque/measure_direction", direction,
                          "child_to_parent or parent_to_child")
    rotation = None
    if frame_kind == "parent":
        rotation = _frame_rotation(joint.rpy).T  # child frame -> parent frame: R_joint, applied as R^T^T
    elif frame_kind == "sensor":
        pose = (sensor.element.findtext("pose") or "0 0 0 0 0 0").split()
        rotation = _frame_rotation(tuple(float(v) for v in pose[3:6])) if len(pose) == 6 else None
    if ft is not None and ft.find("force") is not None:
        ctx.warnings.append(f"{sensor.path}/force_torque: per-axis <noise> not simulated")
    rate_el = sensor.element.find("update_rate")
    rate = tag_number(f"{sensor.path}/update_rate", tag_value(rate_el), ctx.warnings, low=0.0) \
        if rate_el is not None else 0.0
    ros = element.find("ros")
    ns = (ros.findtext("namespace") or "").strip() if ros is not None else ""
    topic = "wrench"
    if ros is not None:
        for remap in ros.findall("remapping"):
            src, _, dst = (remap.text or "").partition(":=")
            if src.strip().lstrip("~/") in ("out", "wrench") and dst.strip():
                topic = dst.strip()
    frame = (element.findtext("frame_name") or "").strip() or joint.child
    return ForceTorque(ctx, path, joint.name, join(ctx.plugin_namespace(ns or None, "/"), topic), ctx.frame(frame),
                       1.0 / rate if rate > 0 else 0.0, 0.0, rotation, -1.0 if direction == "parent_to_child" else 1.0)
