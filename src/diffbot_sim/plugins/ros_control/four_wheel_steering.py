"""``four_wheel_steering_controller/FourWheelSteeringController`` on the hardware: ``<controller>/cmd_vel``
(Twist: a symmetric turn, front and rear steered opposite) and ``<controller>/cmd_four_wheel_steering``
(four_wheel_steering_msgs/FourWheelSteering: front and rear axle angles and a speed) in, the newer one
driving; ``<controller>/odom`` (frame ``odom`` always, as upstream), ``<controller>/odom_steer``
(FourWheelSteeringStamped) and ``/tf`` when ``enable_odom_tf`` out. Four velocity wheels and four position
steerings, ``[left, right]`` per axle. Geometry from the URDF as urdf_geometry_parser measures it (and written
back to the parameter server, as upstream does). The logic is
:mod:`diffbot_sim.control.four_wheel_steering_controller`."""
import threading

import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

from diffbot_sim.control import four_wheel_steering_controller as fws
from diffbot_sim.errors import ModelError
from diffbot_sim.messages import common as ros_msgs, steering
from diffbot_sim.plugins.base import join
from diffbot_sim.plugins.ros_control.ackermann_steering import POSITION, VELOCITY, claim, cylinder_radius
from diffbot_sim.plugins.ros_control.controller import Controller
from diffbot_sim.transforms import quaternion_from_yaw


class FourWheelSteeringController(Controller):
    type = fws.CONTROLLER_TYPE
    interface = None

    def __init__(self, ctx, hw, name, params):
        super().__init__(ctx, hw, name, params)
        cfg = fws.four_wheel_steering_config(params, name)
        ctx.warnings.extend(cfg.warnings)
        if cfg.unknown_keys:
            ctx.warnings.append(f"{name}: parameters FourWheelSteeringController does not read, ignored: "
                                f"{', '.join(cfg.unknown_keys)}")
        for joint in cfg.wheels:
            claim(self, joint, VELOCITY)
        for joint in cfg.steerings:
            claim(self, joint, POSITION)
        self.cfg = cfg
        self.core = fws.FourWheelSteeringCore(cfg, self._geometry(ctx.model, cfg, name))
        try:
            self.msgs = steering.four_wheel_steering_msgs()
        except ImportError:
            self.msgs = None
            ctx.warnings.append(f"{name}: four_wheel_steering_msgs is not built (overlay left out): no "
                                "cmd_four_wheel_steering, no odom_steer")
        self._lock = threading.Lock()
        # the newest commands from the callbacks: (linear x, linear y, angular z), (speed, front, rear steering)
        self._twist: tuple[float, float, float] | None = None
        self._four: tuple[float, float, float] | None = None
        self.sub = self.own(ctx.subscriber(join(name, "cmd_vel"), Twist, self._on_twist, queue_size=1))
        self.sub_4ws = (self.own(ctx.subscriber(join(name, "cmd_four_wheel_steering"), self.msgs.FourWheelSteering,
                                                self._on_four, queue_size=1)) if self.msgs else None)
        self.odom_pub = self.own(ctx.publisher(join(name, "odom"), Odometry))
        self.steer_pub = (self.own(ctx.publisher(join(name, "odom_steer"), self.msgs.FourWheelSteeringStamped))
                          if self.msgs else None)
        odom, base = ctx.frame("odom"), ctx.frame(cfg.base_frame_id)
        self.odom_frame = odom
        self.odom_builder = ros_msgs.OdometryBuilder(odom, base, 0, 0, 0, pose_diagonal=cfg.pose_covariance_diagonal,
                                                     twist_diagonal=cfg.twist_covariance_diagonal)
        self.tf_builder = ros_msgs.TransformBuilder(odom, base)

    def _geometry(self, model, cfg, name):
        joints = {j.name: (j.parent, j.child, j.xyz) for j in model.joints.values()}
        base = cfg.base_frame_id
        try:
            track = (fws.joint_distance(joints, cfg.front_wheels[0], cfg.front_wheels[1], base)
                     if cfg.track is None else None)
            offset = fws.joint_distance(joints, cfg.front_steerings[0], cfg.front_wheels[0], base)
            base_len = (fws.joint_distance(joints, cfg.front_wheels[0], cfg.rear_wheels[0], base)
                        if cfg.wheel_base is None else None)
        except KeyError as err:
            raise ModelError(f"controller {name}: {err.args[0]} (measuring from {base})", model.source) from None
        radius = cylinder_radius(model, cfg.front_wheels[0], name) if cfg.wheel_radius is None else None
        for key, value in (("track", track), ("wheel_steering_y_offset", offset), ("wheel_radius", radius),
                           ("wheel_base", base_len)):
            if value is not None:  # upstream writes what it measured back to the parameter server
                rospy.set_param(join(name, key), value)
        return fws.resolve_geometry(cfg, track, offset, radius, base_len)

    def _on_twist(self, msg):
        with self._lock:
            self._twist = (msg.linear.x, msg.linear.y, msg.angular.z)
        self.ctx.sim.wake.set()

    def _on_four(self, msg):
        with self._lock:
            self._four = steering.four_wheel_steering_command(msg)
        self.ctx.sim.wake.set()

    def joints(self):
        return set(self.cfg.wheels + self.cfg.steerings)

    def publishers(self):
        return [p for p in (self.odom_pub, self.steer_pub) if p is not None]

    def start(self, now):
        super().start(now)
        self.core.starting(now)
        self._brake()

    def stop(self, now):
        super().stop(now)
        self.core.stopping(now)
        self._brake()

    def _brake(self):
        for joint in self.cfg.wheels + self.cfg.steerings:
            self.hw.set_command(joint, 0.0)

    def update(self, now, period, stamp, transforms):
        with self._lock:
            twist, four, self._twist, self._four = self._twist, self._four, None, None
        for why in (self.core.set_four_wheel_steering(*four, now) if four else None,
                    self.core.set_twist(*twist, now) if twist else None):
            if why is not None:
                self.ctx.sim.warn(f"fws:{self.name}", f"{self.name}: {why}")
        step = self.core.update(now, self.hw.velocities(self.cfg.wheels), self.hw.positions(self.cfg.steerings),
                                period)
        for joint, value in zip(self.cfg.wheels, step.wheels):
            self.hw.set_command(joint, value)
        for joint, value in zip(self.cfg.steerings, step.steerings):
            self.hw.set_command(joint, value)
        if not step.publish_odom:
            return
        odom = self.core.odometry
        orientation = quaternion_from_yaw(odom.heading)
        if self.odom_pub.get_num_connections():
            self.odom_pub.publish(self.odom_builder.build(stamp, (odom.x, odom.y, 0.0), orientation,
                                                          (odom.linear_x, odom.linear_y, 0.0),
                                                          (0.0, 0.0, odom.angular)))
        if self.steer_pub is not None and self.steer_pub.get_num_connections():
            self.steer_pub.publish(steering.odom_steer(stamp, self.odom_frame, odom.linear, odom.linear_acceleration,
                                                       odom.linear_jerk, step.front_steering,
                                                       odom.front_steer_velocity, step.rear_steering,
                                                       odom.rear_steer_velocity))
        if self.cfg.enable_odom_tf:
            transforms.append(self.tf_builder.build(stamp, (odom.x, odom.y, 0.0), orientation))

    def summary(self):
        g = self.core.geometry
        return {f"{self.name}/track": g.track, f"{self.name}/wheel_base": g.wheel_base,
                f"{self.name}/wheel_radius": g.wheel_radius, "cmd_vel_topic": self.sub.resolved_name,
                "odom_topic": self.odom_pub.resolved_name}
