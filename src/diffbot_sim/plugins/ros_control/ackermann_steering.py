"""``ackermann_steering_controller/AckermannSteeringController`` on the hardware: ``<controller>/cmd_vel`` in
(``linear.x`` m/s, ``angular.z`` the steering angle in rad, as upstream), ``<controller>/odom`` out, ``/tf``
when ``enable_odom_tf``; the ``rear_wheel`` joint by velocity, the ``front_steer`` joint by position. Geometry
from the URDF where the YAML gives none, as upstream measures it: ``wheel_separation_h`` the x distance
between the two joints' origins (each in its parent's frame), the radius of the rear wheel's first collision,
which must be a cylinder. The controller's logic is :mod:`diffbot_sim.control.ackermann_steering_controller`.

Under DefaultRobotHWSim both joints are the model's own (a bicycle model); under SteerBotHardwareGazebo they
are its virtual joints, mapped onto the real wheels and the steering linkage
(:mod:`.steer_bot_hardware`)."""
import threading

from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

from diffbot_sim.control import ackermann_steering_controller as asc
from diffbot_sim.errors import ModelError
from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins.base import join
from diffbot_sim.plugins.ros_control.controller import Controller
from diffbot_sim.transforms import quaternion_from_yaw

VELOCITY, POSITION = "VelocityJointInterface", "PositionJointInterface"


def claim(controller, joint, interface):
    """upstream's getHandle: the hardware must offer ``joint`` under ``interface`` (a virtual joint of a vendor
    hardware need not be in the URDF)."""
    if controller.hw.interface(joint) != interface:
        controller.require_interface(joint, interface)


def cylinder_radius(model, joint_name, referrer):
    """The radius of the first collision of ``joint_name``'s child link, which upstream requires a cylinder."""
    joint = model.joint(joint_name, referrer)
    link = model.links[joint.child]
    if not link.collisions or link.collisions[0].kind != "cylinder":
        raise ModelError(f"wheel link '{link.name}' is not modeled as a cylinder (its first collision), so the "
                         f"controller cannot take its radius; give {referrer}/wheel_radius", model.source)
    return link.collisions[0].radius


class AckermannSteeringController(Controller):
    type = asc.CONTROLLER_TYPE
    interface = None  # two interfaces: the manager lists each joint under the hardware's own

    def __init__(self, ctx, hw, name, params):
        super().__init__(ctx, hw, name, params)
        cfg = asc.ackermann_config(params, name)
        ctx.warnings.extend(cfg.warnings)
        if cfg.unknown_keys:
            ctx.warnings.append(f"{name}: parameters AckermannSteeringController does not read, ignored: "
                                f"{', '.join(cfg.unknown_keys)}")
        claim(self, cfg.rear_wheel, VELOCITY)
        claim(self, cfg.front_steer, POSITION)
        separation = radius = None
        model = ctx.model
        if cfg.wheel_separation_h is None:
            rear = model.joint(cfg.rear_wheel, name).xyz
            steer = model.joint(cfg.front_steer, name).xyz
            separation = abs(rear[0] - steer[0])
        if cfg.wheel_radius is None:
            radius = cylinder_radius(model, cfg.rear_wheel, name)
        self.cfg = cfg
        self.core = asc.AckermannSteeringCore(cfg, separation, radius)
        self._lock = threading.Lock()
        self._pending = None
        self.sub = self.own(ctx.subscriber(join(name, "cmd_vel"), Twist, self._on_twist, queue_size=1))
        self.odom_pub = self.own(ctx.publisher(join(name, "odom"), Odometry))
        self.odom_builder = ros_msgs.OdometryBuilder(ctx.frame(cfg.odom_frame_id), ctx.frame(cfg.base_frame_id),
                                                     0, 0, 0, pose_diagonal=cfg.pose_covariance_diagonal,
                                                     twist_diagonal=cfg.twist_covariance_diagonal)
        self.tf_builder = ros_msgs.TransformBuilder(ctx.frame(cfg.odom_frame_id), ctx.frame(cfg.base_frame_id))

    def _on_twist(self, msg):
        count = self.sub.get_num_connections()
        with self._lock:
            self._pending = (msg.linear.x, msg.angular.z, count)
        self.ctx.sim.wake.set()

    def joints(self):
        return {self.cfg.rear_wheel, self.cfg.front_steer}

    def publishers(self):
        return [self.odom_pub]

    def start(self, now):
        super().start(now)
        self.core.starting(now)
        self._write()

    def stop(self, now):
        super().stop(now)
        self.core.stopping(now)
        self._write()

    def _write(self):
        wheel, steer = self.core.joint_commands
        self.hw.set_command(self.cfg.rear_wheel, wheel)
        self.hw.set_command(self.cfg.front_steer, steer)

    def update(self, now, period, stamp, transforms):
        if self._pending is not None:
            with self._lock:
                (linear, angular, count), self._pending = self._pending, None
            why = self.core.set_command(linear, angular, now, count)
            if why is not None:
                self.ctx.sim.warn(f"asc:{self.name}", f"{self.name}: {why}")
        wheel, steer = self.hw.positions([self.cfg.rear_wheel, self.cfg.front_steer])
        step = self.core.update(now, wheel, steer, period)
        self._write()
        if step.publish_odom:
            x, y, heading = self.core.pose
            linear, angular = self.core.velocity
            orientation = quaternion_from_yaw(heading)
            if self.odom_pub.get_num_connections():
                self.odom_pub.publish(self.odom_builder.build(stamp, (x, y, 0.0), orientation, (linear, 0.0, 0.0),
                                                              (0.0, 0.0, angular)))
            if self.cfg.enable_odom_tf:
                transforms.append(self.tf_builder.build(stamp, (x, y, 0.0), orientation))

    def summary(self):
        return {f"{self.name}/wheel_separation_h": self.core.separation_h,
                f"{self.name}/wheel_radius": self.core.wheel_radius,
                "cmd_vel_topic": self.sub.resolved_name, "odom_topic": self.odom_pub.resolved_name}
