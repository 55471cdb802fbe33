"""``libgazebo_ros_planar_move.so`` (ROS 1): holonomic base velocity from ``cmd_vel`` (linear.x, linear.y,
angular.z in the robot's heading), set on the body every step as Gazebo sets the model's velocity; odometry
is the world pose at ``odometryRate``.

Tags (defaults): ``commandTopic`` (cmd_vel), ``odometryTopic`` (odom), ``odometryFrame`` (odom),
``robotBaseFrame`` (base_footprint), ``odometryRate`` (20 Hz), ``publishOdometryTf`` (true),
``cmdTimeout`` (s, <= 0: hold the last command; also ~cmd_vel_timeout), ``robotNamespace``.
"""
import threading

from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

from diffbot_sim.description.urdf_model import tag_value
from diffbot_sim.plugins.base import Plugin, finite_twist, join
from diffbot_sim.ros import messages as ros_msgs
from diffbot_sim.values import check_bool, check_string, tag_number

DEFAULTS = {"commandTopic": "cmd_vel", "odometryTopic": "odom", "odometryFrame": "odom",
            "robotBaseFrame": "base_footprint", "odometryRate": 20.0, "publishOdometryTf": True,
            "cmdTimeout": -1.0, "robotNamespace": None}


class PlanarMove(Plugin):
    filename = "libgazebo_ros_planar_move.so"

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
        self._lock = threading.Lock()
        self._pending = None
        self.sub = ctx.subscriber(join(ns, values["commandTopic"]), Twist, self._on_twist, queue_size=1)
        self.pub = ctx.publisher(join(ns, values["odometryTopic"]), Odometry)
        self.builder = ros_msgs.OdometryBuilder(self.odom_frame, self.base_frame, 1e-5, 1e-5, 1e-3)
        self.tf_builder = ros_msgs.TransformBuilder(self.odom_frame, self.base_frame)
        self.summary_values = {k: v for k, v in values.items() if v is not None}

    def _on_twist(self, msg):
        values = finite_twist(self.ctx, msg, self)
        if values is None:
            return
        with self._lock:
            self._pending = (values[0], values[1], values[5])
        self.ctx.sim.wake.set()

    def publishers(self):
        return [self.pub]

    def next_due(self):
        return self.ctx.sim.sim_time  # the body velocity is set every step, as Gazebo does

    def before_step(self, now):
        if self._pending is not None:
            with self._lock:
                self.command, self._pending = self._pending, None
            self.stamp = now
        command = self.command
        if self.timeout > 0 and self.stamp is not None and now - self.stamp > self.timeout:
            command = self.command = (0.0, 0.0, 0.0)
            self.stamp = None
        self.ctx.robot.set_planar_velocity(*command)

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
        with self._lock:
            self._pending = None
        self.command, self.stamp = (0.0, 0.0, 0.0), None

    def summary(self):
        return dict(self.summary_values, cmd_vel_topic=self.sub.resolved_name, odom_topic=self.pub.resolved_name)


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
