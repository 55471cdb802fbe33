"""``franka_gazebo/FrankaGripperSim`` (franka_ros 0.10.1, ``franka_gazebo/src/franka_gripper_sim.cpp``): the Franka
Hand's two fingers (``<arm_id>_finger_joint1/2``, EffortJointInterface) as franka_gripper's node serves a real
one, relative to the controller's namespace (``franka_gripper`` in franka_gazebo's launch files):

* actions ``homing``, ``move``, ``grasp`` (width, epsilon inner/outer, speed, force), ``stop``
  (franka_gripper/*Action, from the overlay) and ``gripper_action`` (control_msgs/GripperCommand: position is
  one finger's, half the width);
* ``joint_states`` (the two fingers) at 30 Hz.

The logic (states, PIDs, what each goal waits for and answers) is :mod:`diffbot_sim.control.franka_gripper`; it
runs every physics step, as at franka_gazebo's 1 ms controlPeriod. Each action takes one goal at a time, as
upstream's SimpleActionServers: a new goal on an action preempts that action's previous one.
"""
import rospy
from sensor_msgs.msg import JointState

from diffbot_sim.control import franka_gripper as fg
from diffbot_sim.messages import common as ros_msgs, controllers as cm, franka as franka_messages
from diffbot_sim.plugins.base import join, next_due
from diffbot_sim.plugins.ros_control.controller import Controller, action_server

PUBLISH_RATE = 30.0  # [Hz]: franka_hw's TriggerRate of the gripper's joint_states
ACTIONS = ("homing", "move", "grasp", "stop")


class FrankaGripperSim(Controller):
    type = fg.CONTROLLER_TYPE
    interface = "EffortJointInterface"
    #: a PID on efforts: every physics step
    closed_loop = True

    def __init__(self, ctx, hw, name, params):
        super().__init__(ctx, hw, name, params)
        self.cfg = fg.gripper_config(params, name, set(ctx.model.joints))
        self.fingers = [self.cfg.finger1, self.cfg.finger2]
        for joint in self.fingers:
            self.require_interface(joint, self.interface)
        self.core = fg.FrankaGripperCore(self.cfg)
        self._warn_unstable(ctx)
        self.goals = {}  # goal id -> (action, actionlib goal handle)
        gripper = franka_messages.franka_gripper_msgs()
        specs = {"homing": gripper.HomingAction, "move": gripper.MoveAction, "grasp": gripper.GraspAction,
                 "stop": gripper.StopAction, "gripper_action": cm.control_msgs()[0].GripperCommandAction}
        self.servers = {kind: self.own(action_server(join(name, kind), spec, self._goal_callback(kind),
                                                     self._on_cancel))
                        for kind, spec in specs.items()}
        self.pub = self.own(ctx.publisher(join(name, "joint_states"), JointState))
        self.builder = ros_msgs.JointStateBuilder(self.fingers)
        self.next = 0.0

    def _warn_unstable(self, ctx):
        """The fingers' gains were tuned at Gazebo's 1 ms step; say so where they ring at ours (they still run
        explicitly: the grasp's force is an effort, which a motor would not give)."""
        from diffbot_sim.control.pid import STABILITY_MARGIN, loop_verdict

        for joint, gains in zip(self.fingers, (self.cfg.gains1, self.cfg.gains2)):
            margin, inertia = self.hw.explicit_margin(joint, gains, "position")
            if margin > STABILITY_MARGIN:
                ctx.warnings.append(f"{self.name}: gains of {joint} (p={gains.p:g}, d={gains.d:g}) are "
                                    f"{loop_verdict(gains, margin, 'position')} explicit loop at a "
                                    f"{ctx.cfg.time_step * 1000:.2f} ms step (the finger moves {inertia:.3g} kg, "
                                    f"{margin:.2g} of the stability bound)")

    # -- goals (rospy's threads: the loop does the work) ----------------------------------------------------
    def _goal_callback(self, kind):
        def callback(handle):
            self.ctx.sim.post(lambda: self._goal(kind, handle))
        return callback

    def _on_cancel(self, handle):
        self.ctx.sim.post(lambda: self._cancel(handle))

    def _goal(self, kind, handle):
        if not self.running:
            handle.set_rejected(None, "the gripper controller is not running")
            return
        goal, goal_id = handle.get_goal(), handle.get_goal_id().id
        for other_id, (other_kind, other) in list(self.goals.items()):
            if other_kind == kind:  # SimpleActionServer: a new goal preempts the action's current one
                self.goals.pop(other_id)
                self.core.cancel(other_id)
                other.set_canceled()
        handle.set_accepted()
        self.goals[goal_id] = (kind, handle)
        positions = self.hw.positions(self.fingers)
        width = sum(positions)
        rospy.loginfo(f"FrankaGripperSim: New {kind} goal received")
        if kind == "homing":
            refused = self.core.homing(goal_id)
        elif kind == "move":
            refused = self.core.move(goal_id, goal.width, goal.speed)
        elif kind == "grasp":
            refused = self.core.grasp(goal_id, goal.width, goal.speed, goal.force, goal.epsilon.inner,
                                      goal.epsilon.outer, width)
        elif kind == "stop":
            refused = self.core.stop(goal_id)
        else:
            refused = self.core.gripper_command(goal_id, goal.command.position, goal.command.max_effort, width)
            if refused:
                rospy.logerr(f"FrankaGripperSim: {refused}")
        if refused:
            self.goals.pop(goal_id, None)
            handle.set_aborted(self._result(kind, False, refused, width), refused)
        self._answer()

    def _cancel(self, handle):
        goal_id = handle.get_goal_id().id
        entry = self.goals.pop(goal_id, None)
        if entry is not None:
            self.core.cancel(goal_id)
            entry[1].set_canceled()

    def _answer(self):
        """The goals the core finished: their results, as upstream's callbacks set them."""
        for done in self.core.take_finished():
            entry = self.goals.pop(done.goal_id, None)
            if entry is None:
                continue
            kind, handle = entry
            result = self._result(kind, done.success, done.error, done.width)
            if done.outcome == "succeeded":
                handle.set_succeeded(result)
            else:
                handle.set_aborted(result, done.error)

    def _result(self, kind, success, error, width):
        if kind == "gripper_action":
            result = cm.control_msgs()[0].GripperCommandResult()
            result.position, result.effort, result.stalled, result.reached_goal = width, 0.0, False, success
            return result
        return franka_messages.gripper_result(kind, success, error)

    # -- the controller ---------------------------------------------------------------------------------------
    def joints(self):
        return set(self.fingers)

    def publishers(self):
        return [self.pub]

    def start(self, now):
        super().start(now)
        self.core.starting()
        self.next = now + 1.0 / PUBLISH_RATE  # franka_hw's TriggerRate: one period after the start

    def stop(self, now):
        super().stop(now)
        for goal_id, (_, handle) in list(self.goals.items()):
            self.goals.pop(goal_id)
            self.core.cancel(goal_id)
            handle.set_aborted(None, "the gripper controller was stopped")
        for joint in self.fingers:
            self.hw.set_command(joint, 0.0)

    def update(self, now, period, stamp, transforms):
        positions, velocities = self.hw.positions(self.fingers), self.hw.velocities(self.fingers)
        if now + 1e-9 >= self.next:
            self.next = next_due(self.next, 1.0 / PUBLISH_RATE, now)
            if self.pub.get_num_connections():
                efforts = [self.hw.joints[j].effort for j in self.fingers]
                self.pub.publish(self.builder.build(stamp, positions, velocities, efforts))
        if period <= 0:
            return
        for joint, effort in zip(self.fingers, self.core.update(period, positions, velocities)):
            self.hw.set_command(joint, effort)
        self._answer()

    def summary(self):
        return {f"{self.name}/actions": ", ".join(join(self.name, k) for k in ACTIONS + ("gripper_action",))}
