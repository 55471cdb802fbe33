"""``{position,effort}_controllers/GripperActionController``: action ``<controller>/gripper_cmd``
(``control_msgs/GripperCommandAction``): every goal accepted while running (the previous one canceled),
SUCCEEDED once within ``goal_tolerance``, ABORTED with ``stalled`` when the joint stops moving for
``stall_timeout`` (a gripper closed on an object usually ends so), canceled goals hold the current position with
the default ``max_effort``. The logic is :mod:`diffbot_sim.control.gripper_action_controller`."""
import rospy

from diffbot_sim.control import gripper_action_controller as gac
from diffbot_sim.messages import controllers as cm
from diffbot_sim.plugins.base import join
from diffbot_sim.plugins.ros_control.controller import Controller, action_server

INTERFACES = {"position": "PositionJointInterface", "effort": "EffortJointInterface"}


class GripperActionController(Controller):
    def __init__(self, ctx, hw, name, params):
        super().__init__(ctx, hw, name, params)
        msg, _ = cm.control_msgs()
        self.type = params.get("type")
        self.cfg = gac.gripper_action_config(params, name, self.type)
        self.interface = INTERFACES[self.cfg.variant]
        self.require_interface(self.cfg.joint, self.interface)
        for text in self.cfg.warnings:
            ctx.warnings.append(text)
        self.core = gac.GripperActionCore(self.cfg)
        #: the effort variant closes a PID loop in software: it runs every physics step (Gazebo's default)
        self.closed_loop = self.cfg.variant == "effort"
        # an effort gripper whose PID cannot run explicitly here squeezes through PyBullet's position motor,
        # capped at the goal's max_effort: the same grip force, the same stall
        self.by_position = bool(self.substitute_unstable([self.cfg.joint], [self.cfg.gains], "position",
                                                         force=abs(self.cfg.max_effort))
                                if self.closed_loop and self.cfg.gains else ())
        self.goals = {}
        self.server = self.own(action_server(join(name, "gripper_cmd"), msg.GripperCommandAction, self._on_goal,
                                             self._on_cancel))

    def _on_goal(self, handle):
        self.ctx.sim.post(lambda: self._goal(handle))

    def _on_cancel(self, handle):
        self.ctx.sim.post(lambda: self._cancel(handle))

    def _goal(self, handle):
        command = handle.get_goal().command
        if not self.running:
            handle.set_rejected(None, gac.NOT_RUNNING)
            return
        if not gac.is_finite_goal(command.position, command.max_effort):
            text = f"goal position {command.position} / max_effort {command.max_effort} is not finite"
            rospy.logerr(f"{self.name}: goal refused: {text}")
            handle.set_rejected(None, text)
            return
        goal_id = handle.get_goal_id().id
        preempted = self.core.goal(goal_id, command.position, command.max_effort, self.ctx.sim.sim_time)
        handle.set_accepted()
        self.goals[goal_id] = handle
        self._cancel_handle(preempted)

    def _cancel(self, handle):
        goal_id = handle.get_goal_id().id
        if self.core.cancel(goal_id, self.ctx.sim.sim_time):
            self._cancel_handle(goal_id)

    def _cancel_handle(self, goal_id):
        handle = self.goals.pop(goal_id, None) if goal_id is not None else None
        if handle is not None:
            handle.set_canceled()

    def joints(self):
        return {self.cfg.joint}

    def start(self, now):
        super().start(now)
        self.core.starting(now, self.hw.positions([self.cfg.joint])[0])
        self._write(self.core.command_position if self.cfg.variant == "position" or self.by_position else 0.0)

    def stop(self, now):
        super().stop(now)
        self._cancel_handle(self.core.stopping(now))

    def update(self, now, period, stamp, transforms):
        joint = self.cfg.joint
        result = self.core.update(now, period, self.hw.positions([joint])[0], self.hw.velocities([joint])[0])
        self._write(self.core.command_position if self.by_position else result.command)
        for event in result.events:
            handle = self.goals.pop(event.goal_id, None)
            if handle is None:
                continue
            if event.outcome == gac.SUCCEEDED:
                handle.set_succeeded(cm.gripper_result(event.result))
            else:
                handle.set_aborted(cm.gripper_result(event.result))

    def _write(self, value):
        if self.by_position:
            self.hw.set_target_force(self.cfg.joint, abs(self.core.command_max_effort))
        self.hw.set_command(self.cfg.joint, value)

    def summary(self):
        return {f"{self.name}/action": join(self.name, "gripper_cmd")}
