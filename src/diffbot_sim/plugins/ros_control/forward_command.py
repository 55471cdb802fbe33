"""forward_command_controller and its typedefs (``position_controllers/JointGroupPositionController``,
``velocity_controllers/JointVelocityController``, ...) and the PID controllers built on it
(``effort_controllers/JointPositionController``, ``JointGroupPositionController``, ``JointVelocityController``,
``velocity_controllers/JointPositionController``): ``<controller>/command`` (``std_msgs/Float64`` for one
``joint``, ``std_msgs/Float64MultiArray`` for ``joints``) to the joints; the single PID controllers publish
``control_msgs/JointControllerState`` on ``<controller>/state`` every 10th update. The mathematics is
:mod:`diffbot_sim.control.forward_command`."""
import math

import rospy
from std_msgs.msg import Float64, Float64MultiArray

from diffbot_sim.control import forward_command as fwd
from diffbot_sim.control.command_inbox import CommandInbox
from diffbot_sim.messages import controllers as control_messages
from diffbot_sim.plugins.base import join
from diffbot_sim.plugins.ros_control.controller import Controller


class ForwardCommandController(Controller):
    """Any type of :data:`diffbot_sim.control.forward_command.CONTROLLER_TYPES`."""

    def __init__(self, ctx, hw, name, params):
        super().__init__(ctx, hw, name, params)
        self.type = params.get("type")
        self.cfg = fwd.forward_config(params, name, self.type, self.urdf_joints())
        self.interface = self.cfg.interface
        for joint in self.cfg.joints:
            self.require_interface(joint, self.interface)
        self.core = fwd.make_core(self.cfg)
        #: PID controllers close their loop in software: they run every physics step, as at Gazebo's default
        #: controlPeriod (forwarding ones only pass a value on, and run at the manager's period).
        self.closed_loop = self.cfg.kind.startswith("pid_")
        self.inbox = CommandInbox(ctx.sim.wake.set)  # the newest finite command message's data
        kind = Float64 if self.cfg.single else Float64MultiArray
        self.sub = self.own(ctx.subscriber(join(name, "command"), kind, self._on_command, queue_size=1))
        self.state_pub = None
        if self.closed_loop and self.cfg.single:
            try:
                msg, _ = control_messages.control_msgs()
                self.state_pub = self.own(ctx.publisher(join(name, "state"), msg.JointControllerState))
            except ImportError:
                ctx.warnings.append(f"{name}: control_msgs is not built (overlay left out): no state topic")

    def _on_command(self, msg):
        values = msg.data
        if not all(math.isfinite(v) for v in (values if isinstance(values, (list, tuple)) else [values])):
            self.ctx.sim.warn(f"cmd:{self.name}", f"{self.name}: ignored a command with a non-finite value")
            return
        self.inbox.put(values)

    def joints(self):
        return set(self.cfg.joints)

    def publishers(self):
        return [self.state_pub] if self.state_pub is not None else []

    def start(self, now):
        super().start(now)
        self.core.start(self.hw.positions(self.cfg.joints))
        self._write(self.core.update(self.hw.positions(self.cfg.joints), self.hw.velocities(self.cfg.joints), 0.0)
                    if not self.closed_loop else [0.0] * len(self.cfg.joints))

    def update(self, now, period, stamp, transforms):
        values = self.inbox.take()
        if values is not None:
            error = self.core.command(values)
            if error is not None:
                rospy.logerr(f"{self.name}: {error}")
        joints = self.cfg.joints
        self._write(self.core.update(self.hw.positions(joints), self.hw.velocities(joints), period))
        state = getattr(self.core, "state", None)
        if state is not None and self.state_pub is not None and self.state_pub.get_num_connections():
            self.state_pub.publish(control_messages.joint_controller_state(stamp, state))

    def _write(self, commands):
        for joint, value in zip(self.cfg.joints, commands):
            self.hw.set_command(joint, value)

    def summary(self):
        return {f"{self.name}/command": self.sub.resolved_name}
