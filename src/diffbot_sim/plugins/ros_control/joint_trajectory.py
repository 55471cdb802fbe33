"""``{position,velocity,effort}_controllers/JointTrajectoryController`` (and ``pos_vel*``): upstream's ROS API
relative to the controller's namespace:

* action ``follow_joint_trajectory`` (``control_msgs/FollowJointTrajectoryAction``; actionlib's Python
  ActionServer, from Debian), feedback at ``action_monitor_rate``;
* topic ``command`` (``trajectory_msgs/JointTrajectory``), topic ``state``
  (``control_msgs/JointTrajectoryControllerState``) at ``state_publish_rate``, service ``query_state``
  (``control_msgs/QueryTrajectoryState``).

The controller itself (parameters, splines, trajectory replacement, tolerances, holds, the PID of the
velocity/effort variants) is :mod:`diffbot_sim.control.joint_trajectory_controller`. Beyond upstream, a goal
or command that would make a joint follow a NaN, name a joint twice or leave a joint's URDF limits is refused
(INVALID_GOAL / INVALID_JOINTS with a sentence naming it): upstream follows such trajectories, and the
hardware then clamps or diverges.
"""
import math

import rospy
from trajectory_msgs.msg import JointTrajectory

from diffbot_sim.control import joint_trajectory_controller as jtc
from diffbot_sim.control.joint_trajectory_config import jtc_config
from diffbot_sim.errors import ConfigError
from diffbot_sim.messages import controllers as cm
from diffbot_sim.plugins.base import join, next_due
from diffbot_sim.plugins.ros_control.controller import Controller, action_server

INTERFACES = {"position": "PositionJointInterface", "velocity": "VelocityJointInterface",
              "effort": "EffortJointInterface"}


class JointTrajectoryController(Controller):
    def __init__(self, ctx, hw, name, params):
        super().__init__(ctx, hw, name, params)
        msg, srv = cm.control_msgs()
        self.type = params.get("type")
        self.cfg = jtc_config(params, name, self.urdf_joints())
        self.interface = INTERFACES[self.cfg.variant]
        for joint in self.cfg.joints:
            self.require_interface(joint, self.interface)
        for level, text in self.cfg.log:
            ctx.warnings.append(f"{name}: {text}" if level != "error" else f"{name}: ERROR {text}")
        self.core = jtc.JointTrajectoryControllerCore(self.cfg)
        #: the velocity/effort variants close a PID loop in software: they run every physics step, as at
        #: Gazebo's default controlPeriod; the position variant hands targets to the joints' motors.
        self.closed_loop = self.cfg.variant != "position"
        # the effort variant's PID is an explicit force; the velocity variant's drives velocity motors
        self.by_position = (self.substitute_unstable(self.cfg.joints, self.cfg.gains, "position")
                            if self.cfg.variant == "effort" and self.cfg.gains else set())
        self.goals = {}  # goal id -> actionlib ServerGoalHandle
        self.state_pub = self.own(ctx.publisher(join(name, "state"), msg.JointTrajectoryControllerState))
        self.command_sub = self.own(ctx.subscriber(join(name, "command"), JointTrajectory, self._on_command,
                                                   queue_size=1))
        self.query = self.own(ctx.service(join(name, "query_state"), srv.QueryTrajectoryState, self._on_query))
        self.server = self.own(action_server(join(name, "follow_joint_trajectory"), msg.FollowJointTrajectoryAction,
                                             self._on_goal, self._on_cancel))
        self.next_feedback = 0.0
        self.limits = {j: ctx.model.joints[j] for j in self.cfg.joints}

    # -- endpoints (rospy's threads: hand the work to the loop) ------------------------------------------
    def publishers(self):
        return [self.state_pub]

    def _on_goal(self, handle):
        self.ctx.sim.post(lambda: self._goal(handle))

    def _on_cancel(self, handle):
        self.ctx.sim.post(lambda: self._cancel(handle))

    def _on_command(self, msg):
        self.ctx.sim.post(lambda: self._command(msg))

    def _on_query(self, request):
        values = self.ctx.sim.call(lambda: self.core.query_state(request.time.to_sec()))
        self._flush_log()
        if values is None:
            return None  # rospy answers a failed call (upstream returns false)
        return cm.query_state_response(self.cfg.joints, values)

    # -- on the loop ---------------------------------------------------------------------------------------
    def _goal(self, handle):
        goal = handle.get_goal()
        trajectory = goal.trajectory
        refused = self._refuse(trajectory)
        if refused is not None:
            code, text = refused
            rospy.logerr(f"{self.name}: goal refused: {text}")
            handle.set_rejected(cm.trajectory_result(code, text), text)
            return
        answer = self.core.goal(handle.get_goal_id().id, trajectory.joint_names, cm.trajectory_points(trajectory),
                                trajectory.header.stamp.to_sec(), cm.tolerances(goal.path_tolerance),
                                cm.tolerances(goal.goal_tolerance), goal.goal_time_tolerance.to_sec(),
                                self.ctx.sim.sim_time)
        self._flush_log()
        if not answer.accepted:
            handle.set_rejected(cm.trajectory_result(answer.error_code, answer.error_string), answer.error_string)
            return
        handle.set_accepted()
        self.goals[handle.get_goal_id().id] = handle
        self._finish_preempted(answer.preempted_goal_id)

    def _cancel(self, handle):
        goal_id = handle.get_goal_id().id
        if self.core.cancel(goal_id, self.ctx.sim.sim_time):
            self._finish_preempted(goal_id)

    def _command(self, msg):
        refused = self._refuse(msg)
        if refused is not None:
            rospy.logerr(f"{self.name}: command ignored: {refused[1]}")
            return
        self.core.command(msg.joint_names, cm.trajectory_points(msg), msg.header.stamp.to_sec(),
                          self.ctx.sim.sim_time)
        self._flush_log()

    def _refuse(self, trajectory):
        """(error code, sentence) for what upstream would follow but no joint should: a non-finite number, a
        joint named twice, a position outside a joint's URDF limits. None when the trajectory is sound."""
        bad = cm.finite_trajectory(trajectory)
        if bad is not None:
            return jtc.INVALID_GOAL, f"trajectory {bad}"
        names = list(trajectory.joint_names)
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            return jtc.INVALID_JOINTS, f"joint(s) named more than once: {', '.join(twice)}"
        for k, point in enumerate(trajectory.points):
            for name, position in zip(names, point.positions):
                joint = self.limits.get(name)
                if joint is not None and joint.has_position_limits and not \
                        joint.lower - 1e-9 <= position <= joint.upper + 1e-9:
                    return jtc.INVALID_GOAL, (f"point {k}: {name} position {position:g} is outside its limits "
                                              f"[{joint.lower:g}, {joint.upper:g}]")
        return None

    def _finish_preempted(self, goal_id):
        handle = self.goals.pop(goal_id, None) if goal_id is not None else None
        if handle is not None:
            handle.set_canceled()

    def _flush_log(self):
        for level, text in self.core.take_log():
            (rospy.logerr if level == "error" else rospy.logwarn)(f"{self.name}: {text}")

    # -- the controller ------------------------------------------------------------------------------------
    def joints(self):
        return set(self.cfg.joints)

    def start(self, now):
        try:
            commands = self.core.starting(now, self.hw.positions(self.cfg.joints), self.hw.velocities(self.cfg.joints))
        except jtc.ControllerCrash as err:
            raise ConfigError(f"{self.name}/gains", self.params.get("gains"),
                              f"gains for every joint ({err}: upstream's controller_manager crashes here)") from None
        super().start(now)
        self._write(commands, self.hw.positions(self.cfg.joints))
        self.next_feedback = now

    def stop(self, now):
        super().stop(now)
        for event in self.core.stopping(now):
            self._finish(event)

    def update(self, now, period, stamp, transforms):
        joints, hw = self.cfg.joints, self.hw
        result = self.core.update(now, period, hw.positions(joints), hw.velocities(joints))
        self._flush_log()
        if result.commands is not None:
            self._write(result.commands, result.desired.positions)
        for event in result.events:
            self._finish(event)
        if result.state_due and self.state_pub.get_num_connections():
            self.state_pub.publish(cm.trajectory_state(stamp, joints, result))
        if result.feedback_goal_id is not None and now + 1e-9 >= self.next_feedback:
            self.next_feedback = next_due(self.next_feedback, 1.0 / self.cfg.action_monitor_rate, now)
            handle = self.goals.get(result.feedback_goal_id)
            if handle is not None:
                handle.publish_feedback(cm.trajectory_feedback(stamp, joints, result))

    def _finish(self, event):
        handle = self.goals.pop(event.goal_id, None)
        if handle is None:
            return
        if event.outcome == "SUCCEEDED":
            handle.set_succeeded(cm.trajectory_result(event.error_code, event.error_string))
        elif event.outcome == "ABORTED":
            handle.set_aborted(cm.trajectory_result(event.error_code, event.error_string), event.error_string)
        else:
            handle.set_canceled()

    def _write(self, commands, desired_positions):
        """The adapter's commands, or for a joint run by position targets (``by_position``) its desired
        position."""
        by_position, set_command = self.by_position, self.hw.set_command
        for joint, value, desired in zip(self.cfg.joints, commands, desired_positions):
            if joint in by_position:
                value = desired
            if math.isfinite(value):
                set_command(joint, value)

    def summary(self):
        return {f"{self.name}/action": join(self.name, "follow_joint_trajectory")}

