"""FrankaHWSim's ROS services and action (franka_ros 0.10.1's ``franka_hw_sim.cpp`` initServices and the
error recovery server), in ``<robotNamespace>/franka_control``: ``set_EE_frame`` (NE_T_EE), ``set_K_frame``
(EE_T_K), ``set_load`` (m_load, F_x_Cload, I_load: the load's weight joins the gravity compensation),
``set_force_torque_collision_behavior`` (the contact and collision thresholds), ``set_user_stop``
(std_srvs/SetBool) and the action ``error_recovery`` (franka_msgs/ErrorRecovery: the running controllers are
restarted; refused while the user stop is pressed). Every call runs on the simulator's loop.
"""
import math

import rospy

from diffbot_sim.control import franka as fk
from diffbot_sim.control.controller_switching import SwitchError
from diffbot_sim.messages import franka as franka_messages
from diffbot_sim.plugins.base import join
from diffbot_sim.plugins.ros_control.controller import action_server


class FrankaServices:
    """FrankaHWSim's services and its error recovery action in ``<robotNamespace>/franka_control``; every call
    runs on the simulator's loop."""

    def __init__(self, ctx, hw, warnings):
        try:
            msg, srv = franka_messages.franka_msgs()
            from std_srvs.srv import SetBool, SetBoolResponse
        except ImportError:
            warnings.append("FrankaHWSim: franka_msgs is not built (overlay left out): no franka_control services")
            return
        self.ctx, self.hw, self.srv = ctx, hw, srv
        base = join(hw.ns, "franka_control")
        for name, kind, handler in (("set_EE_frame", srv.SetEEFrame, self._set_ee),
                                    ("set_K_frame", srv.SetKFrame, self._set_k),
                                    ("set_load", srv.SetLoad, self._set_load),
                                    ("set_force_torque_collision_behavior", srv.SetForceTorqueCollisionBehavior,
                                     self._set_collision)):
            ctx.service(join(base, name), kind, handler)

        def user_stop(req):
            ctx.sim.call(lambda: hw.user_stop(bool(req.data)))
            return SetBoolResponse(success=True)
        ctx.service(join(base, "set_user_stop"), SetBool, user_stop)
        self.recovery = action_server(join(base, "error_recovery"), msg.ErrorRecoveryAction, self._on_recovery,
                                      lambda handle: None)
        ctx.handles.append(self.recovery)  # removed with the robot
        self.manager = None  # set by the plugin: error recovery restarts its running controllers

    def _set_ee(self, req):
        rospy.loginfo(f"FrankaHWSim: {self.hw.arm_id()}: Setting NE_T_EE transformation")
        self.ctx.sim.call(lambda: self.hw.set_frames(NE_T_EE=req.NE_T_EE))
        return self.srv.SetEEFrameResponse(success=True)

    def _set_k(self, req):
        rospy.loginfo(f"FrankaHWSim: {self.hw.arm_id()}: Setting EE_T_K transformation")
        self.ctx.sim.call(lambda: self.hw.set_frames(EE_T_K=req.EE_T_K))
        return self.srv.SetKFrameResponse(success=True)

    def _set_load(self, req):
        rospy.loginfo(f"FrankaHWSim: {self.hw.arm_id()}: Setting Load")
        if not (math.isfinite(req.mass) and all(math.isfinite(v) for v in list(req.F_x_center_load)
                                                + list(req.load_inertia))):
            return self.srv.SetLoadResponse(success=False, error="a value of the load is not finite")
        self.ctx.sim.call(lambda: self.hw.set_frames(m_load=req.mass, F_x_Cload=req.F_x_center_load,
                                                     I_load=req.load_inertia))
        return self.srv.SetLoadResponse(success=True)

    def _set_collision(self, req):
        rospy.loginfo(f"FrankaHWSim: {self.hw.arm_id()}: Setting Collision Behavior")
        self.ctx.sim.call(lambda: self.hw.set_collision_behavior(
            req.lower_torque_thresholds_nominal, req.upper_torque_thresholds_nominal,
            req.lower_force_thresholds_nominal, req.upper_force_thresholds_nominal))
        return self.srv.SetForceTorqueCollisionBehaviorResponse(success=True)

    def _on_recovery(self, handle):
        """ErrorRecovery: nothing to recover while the user stop is pressed; else every running controller is
        stopped and started again, and an Idle robot moves."""
        handle.set_accepted()

        def recover():
            if self.hw.mode.mode == fk.USER_STOPPED:
                rospy.logwarn("FrankaHWSim: Cannot recover errors since the user stop seems still pressed")
                return
            if self.manager is not None:
                self.manager.reset_controllers(self.ctx.sim.sim_time)
            self.hw.mode.error_recovery()
            self.hw.state.robot_mode = self.hw.mode.mode
            rospy.loginfo("FrankaHWSim: Recovered from error")
        try:
            self.ctx.sim.call(recover)
        except SwitchError as err:
            rospy.logwarn(f"FrankaHWSim: Error recovery failed: {err}")
            handle.set_aborted()
            return
        handle.set_succeeded()
