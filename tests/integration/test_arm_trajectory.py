#!/usr/bin/env python3
"""arm_trajectory suite: the mobile manipulator's position JointTrajectoryController (gazebo_ros_control
POSITION_PID joints), driven as MoveIt or a user's script drives it, judged by the body.

- A goal reaches its target and SUCCEEDS; every link is where joint_states + the URDF put it (ground truth from
  /gazebo/get_link_state), and the arm holds still under gravity afterwards.
- A new goal preempts a running one (PREEMPTED, then SUCCEEDED at the new target); a cancel holds the arm.
- The command topic and query_state work; the state topic carries desired/actual/error.
- Bad goals get upstream's answer (or a refusal where upstream would follow nonsense) and nothing moves.
- The base still drives (/cmd_vel, ground truth).
"""
import math
import os
import sys
import unittest

import rospy
import rostest
from actionlib_msgs.msg import GoalStatus
from control_msgs.msg import FollowJointTrajectoryResult as Result, JointTrajectoryControllerState
from control_msgs.srv import QueryTrajectoryState
from controller_manager_msgs.srv import ListControllers
from geometry_msgs.msg import Twist
from trajectory_msgs.msg import JointTrajectory

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from armtest import Arm, close, trajectory
from simtest import Latest, wait_for
from traittest import sim_now, sim_sleep

JOINTS = ["shoulder_yaw_joint", "shoulder_pitch_joint", "elbow_joint", "wrist_joint"]
HOME = [0.0, 0.0, 0.0, 0.0]
REACH = [0.6, 0.5, 0.9, 0.4]
MODEL = "diffbot_arm"


class ArmTrajectory(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_arm_trajectory")
        rospy.wait_for_service("/controller_manager/list_controllers", 60)
        cls.list = rospy.ServiceProxy("/controller_manager/list_controllers", ListControllers)
        wait_for(lambda: {c.name for c in cls.list().controller if c.state == "running"} >=
                 {"arm_controller", "gripper_controller", "joint_state_controller"}, 60,
                 "the spawner to start the controllers")
        cls.arm = Arm("/arm_controller", MODEL)
        cls.state = Latest("/arm_controller/state", JointTrajectoryControllerState)
        cls.command = rospy.Publisher("/arm_controller/command", JointTrajectory, queue_size=1)

    def under_way(self, start, goal, fraction, what):
        """Wait until joint_states show the arm ``fraction`` of the way from ``start`` to ``goal`` (the joint with
        the longest way decides): a moment inside a running trajectory judged by where the arm is, not by this
        node's clock, which lags a busy machine's sim time."""
        i = max(range(len(goal)), key=lambda j: abs(goal[j] - start[j]))

        def gone():
            q = self.arm.states.get(JOINTS)[i]
            return q is not None and (q - start[i]) / (goal[i] - start[i]) >= fraction
        wait_for(gone, 30, f"{what} ({JOINTS[i]} {fraction:.2f} of the way from {start[i]:.3f} to {goal[i]:.3f})")

    def go_home(self):
        state, _ = self.arm.run(trajectory(JOINTS, (1.5, HOME)))
        self.assertEqual(state, GoalStatus.SUCCEEDED)

    def test_1_goal_reached_and_the_body_agrees(self):
        states = []
        recorder = rospy.Subscriber("/arm_controller/state", JointTrajectoryControllerState, states.append,
                                    queue_size=10000)
        try:
            # Receiving before the goal goes: a subscription made just before it connects after the start in
            # fast mode, and the first message received would pass for the start.
            wait_for(lambda: states, 20, "the controller's state")
            state, result = self.arm.run(trajectory(JOINTS, (1.0, [0.3, 0.2, 0.4, 0.1]), (2.0, REACH)))
            wait_for(lambda: states and close(list(states[-1].actual.positions), REACH, 0.03), 20,
                     "the controller's state at the goal")
        finally:
            recorder.unregister()
        self.assertEqual((state, result.error_code), (GoalStatus.SUCCEEDED, Result.SUCCESSFUL), result.error_string)
        # Timed by the controller's own stamps (sim time), not by this node's clock, which lags when it is busy:
        # the desired trajectory leaves HOME and reaches REACH 2.0 s apart, and the joints follow within 1 s.
        # Each moment is bracketed by the last message before it and the first after (50 Hz; a message this busy
        # node did not get widens a bracket, it does not move the moment): the trajectory took between
        # shortest and longest, and 2.0 s must lie within that, give or take one controller period.
        stamps = [m.header.stamp.to_sec() for m in states]
        moved = next(i for i, m in enumerate(states) if not close(list(m.desired.positions), HOME, 1e-4))
        there = next(i for i, m in enumerate(states) if close(list(m.desired.positions), REACH, 1e-4))
        self.assertGreater(moved, 0, "no state message before the trajectory started")
        left_lo, left_hi = stamps[moved - 1], stamps[moved]
        reached_lo, reached_hi = stamps[there - 1], stamps[there]
        arrived = next(m.header.stamp.to_sec() for m in states if close(list(m.actual.positions), REACH, 0.03))
        shortest, longest = reached_lo - left_hi, reached_hi - left_lo
        print(f"FIGURE trajectory: desired from HOME to REACH in {shortest:.3f}-{longest:.3f} s of sim time, the "
              f"joints within 0.03 rad of it {arrived - reached_hi:.3f} s after", flush=True)
        self.assertTrue(shortest - 0.01 <= 2.0 <= longest + 0.01,
                        f"the trajectory was not followed in its time: {shortest:.3f}-{longest:.3f} s, not 2.0 "
                        f"(state messages around its start {left_lo:.3f}/{left_hi:.3f}, end "
                        f"{reached_lo:.3f}/{reached_hi:.3f})")
        self.assertLess(longest - shortest, 0.5, "too few state messages to time the trajectory")
        reached = reached_hi
        self.assertLess(arrived - reached, 1.0, "the joints reached the goal long after the trajectory's end")
        rest = self.arm.states.settled(JOINTS)
        self.assertTrue(close(rest, REACH, 0.03), f"joints at {rest}, goal {REACH}")
        self.arm.assert_body_agrees(self)
        # holds under gravity: the forearm stays put for 2 s of sim time (the simulator's)
        before = self.arm.world_pose("forearm_link")[0]
        sim_sleep(2.0)
        after = self.arm.world_pose("forearm_link")[0]
        self.assertLess(math.dist(before, after), 0.003, "the arm sagged or drifted while holding")

    def test_2_preempted_by_a_new_goal_then_cancel_holds(self):
        self.go_home()
        start = self.arm.states.fresh(JOINTS)
        self.arm.client.send_goal(self.arm.goal(trajectory(JOINTS, (4.0, REACH))))
        self.under_way(start, REACH, 0.25, "a quarter of the way into the first goal")
        first = self.arm.client.gh  # the first goal's handle, to read its end state
        state, result = self.arm.run(trajectory(JOINTS, (1.5, [-0.4, 0.3, 0.3, 0.0])))
        self.assertEqual(state, GoalStatus.SUCCEEDED)
        self.assertEqual(first.get_goal_status(), GoalStatus.PREEMPTED)
        start = self.arm.states.fresh(JOINTS)
        self.assertTrue(close(start, [-0.4, 0.3, 0.3, 0.0], 0.03))
        # cancel a third of the way: PREEMPTED, and the arm stops where it is (settled), and stays there for 1 s
        self.arm.client.send_goal(self.arm.goal(trajectory(JOINTS, (3.0, REACH))))
        self.under_way(start, REACH, 1.0 / 3.0, "a third of the way into the goal")
        self.arm.client.cancel_goal()
        wait_for(lambda: self.arm.client.get_state() == GoalStatus.PREEMPTED, 10, "the goal PREEMPTED")
        stopped = self.arm.states.settled(JOINTS)
        sim_sleep(1.0)
        later = self.arm.states.fresh(JOINTS)
        self.assertTrue(close(later, stopped, 0.03), f"the arm moved on after the cancel: {stopped} -> {later}")
        self.assertFalse(close(later, REACH, 0.05), "the cancelled goal was completed anyway")

    def test_3_command_topic_state_topic_and_query_state(self):
        self.go_home()
        target = [0.2, 0.4, 0.6, -0.2]
        self.command.publish(trajectory(JOINTS, (1.0, target)))
        wait_for(lambda: close(self.arm.states.get(JOINTS), target, 0.03), 30, "the command topic's target")
        # the controller's own state once it says so too: the newest state message can be older than the joint
        # states above (once, in .ci/run, it did not yet show the arm within 0.03 rad)

        def at_target():
            msg = self.state.get()
            return msg if msg is not None and close(msg.desired.positions, target, 1e-6) and close(
                msg.actual.positions, target, 0.03) else None
        msg = wait_for(at_target, 10, "/arm_controller/state with the target desired and reached")
        self.assertEqual(list(msg.joint_names), JOINTS)
        self.assertTrue(close(msg.desired.positions, target, 1e-6))
        self.assertTrue(close(msg.actual.positions, target, 0.03))
        query = rospy.ServiceProxy("/arm_controller/query_state", QueryTrajectoryState)
        answer = query(rospy.Time.from_sec(sim_now() + 1.0))  # the simulator's time: this node's clock may lag
        self.assertEqual(list(answer.name), JOINTS)
        self.assertTrue(close(answer.position, target, 1e-6))

    def test_4_bad_goals_get_upstreams_answer_and_nothing_moves(self):
        self.go_home()
        before = self.arm.states.settled(JOINTS)  # held within 1 mrad for 0.3 s of sim time, not one still instant
        cases = [
            ("NaN", trajectory(JOINTS, (1.0, [0.1, float("nan"), 0.0, 0.0])), Result.INVALID_GOAL),
            ("Inf", trajectory(JOINTS, (1.0, [0.1, 0.0, float("inf"), 0.0])), Result.INVALID_GOAL),
            ("unknown joint", trajectory(JOINTS[:3] + ["no_such_joint"], (1.0, [0.1] * 4)), Result.INVALID_JOINTS),
            ("duplicate joint", trajectory(JOINTS[:3] + [JOINTS[0]], (1.0, [0.1] * 4)), Result.INVALID_JOINTS),
            ("missing joint", trajectory(JOINTS[:3], (1.0, [0.1] * 3)), Result.INVALID_JOINTS),
            ("times not increasing", trajectory(JOINTS, (1.0, [0.1] * 4), (1.0, [0.2] * 4)), Result.INVALID_GOAL),
            ("outside the limits", trajectory(JOINTS, (1.0, [0.1, 9.0, 0.0, 0.0])), Result.INVALID_GOAL),
        ]
        for what, msg, code in cases:
            state, result = self.arm.run(msg)
            self.assertEqual(state, GoalStatus.REJECTED, what)
            self.assertEqual(result.error_code, code, f"{what}: {result.error_string}")
        self.assertIn("not strictly increasing", self.arm.run(cases[5][1])[1].error_string)
        state, result = self.arm.run(trajectory(JOINTS))  # empty: upstream holds and succeeds
        self.assertEqual(state, GoalStatus.SUCCEEDED)
        after = self.arm.states.fresh(JOINTS)  # from a message stamped after the last goal's end
        self.assertTrue(close(after, before, 0.02), f"a refused goal moved the arm: {before} -> {after}")

    def test_5_the_base_still_drives(self):
        """0.2 m/s forward until the body has gone 0.3 m (ground truth), at the commanded speed once under way
        (the body's own twist: immune to this node's lag), level at its rest height."""
        base = self.arm.world_pose(self.arm.model.root)[0]
        cmd = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
        wait_for(lambda: cmd.get_num_connections() > 0, 10, "bullet_sim subscribed to /cmd_vel")
        twist = Twist()
        twist.linear.x = 0.2
        speeds = []

        def moved():
            cmd.publish(twist)
            resp = self.arm.link_state(f"{self.arm.model_name}::{self.arm.model.root}", "")
            p, v = resp.link_state.pose.position, resp.link_state.twist.linear
            gone = math.dist(base[:2], (p.x, p.y))
            if gone > 0.1:
                speeds.append(math.hypot(v.x, v.y))
            return gone > 0.3
        try:
            wait_for(moved, 60, "the base to drive 0.3 m", poll=0.05)
        finally:
            cmd.publish(Twist())
        speeds.sort()
        speed = speeds[len(speeds) // 2]
        print(f"FIGURE base: median speed {speed:.3f} m/s over {len(speeds)} samples once under way", flush=True)
        self.assertAlmostEqual(speed, 0.2, delta=0.02, msg="the base does not drive at the commanded speed")
        self.assertLess(abs(self.arm.world_pose(self.arm.model.root)[0][2] - base[2]), 0.01,
                        "the base left its rest height")

if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "arm_trajectory", ArmTrajectory, sys.argv)
