#!/usr/bin/env python3
"""manipulator_way suite: a published mobile manipulator's own Gazebo launch file (its traits: see
manipulator_way.test) runs unchanged: the spawner starts its controllers, the arm reaches and holds
FollowJointTrajectory goals with the body where TF puts it, the gripper opens and closes with the mimic finger
following, and the base still drives."""
import math
import os
import sys
import unittest

import rospy
import rostest
from actionlib_msgs.msg import GoalStatus
from control_msgs.msg import FollowJointTrajectoryResult as Result
from controller_manager_msgs.srv import ListControllers
from geometry_msgs.msg import Twist

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from armtest import Arm, close, trajectory
from simtest import wait_for
from traittest import sim_sleep

ARM = ["joint1", "joint2", "joint3", "joint4"]
MODEL = "robot"  # spawn_model -model robot


class ManipulatorWay(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_manipulator_way")
        rospy.wait_for_service("/controller_manager/list_controllers", 90)
        listing = rospy.ServiceProxy("/controller_manager/list_controllers", ListControllers)
        wait_for(lambda: {c.name for c in listing().controller if c.state == "running"} >=
                 {"arm_controller", "gripper_controller", "joint_state_controller"}, 90,
                 "the spawners to start the controllers")
        cls.arm = Arm("/arm_controller", MODEL)
        cls.gripper = Arm("/gripper_controller", MODEL)

    def test_1_arm_reaches_holds_and_agrees_with_tf(self):
        target = [0.5, -0.6, 0.4, 0.7]
        state, result = self.arm.run(trajectory(ARM, (2.0, target)))
        self.assertEqual((state, result.error_code), (GoalStatus.SUCCEEDED, Result.SUCCESSFUL), result.error_string)
        self.assertTrue(close(self.arm.states.fresh(ARM), target, 0.1))  # a message stamped after the result
        self.arm.assert_body_agrees(self, distance=0.003, angle=0.01)
        hand = self.arm.world_pose("link5")[0]
        sim_sleep(2.0, timeout=60)  # holds for 2 s of the simulator's sim time
        self.assertLess(math.dist(hand, self.arm.world_pose("link5")[0]), 0.003, "the arm did not hold still")

    def test_2_gripper_opens_and_the_mimic_finger_follows(self):
        for opening in (0.015, -0.005):
            state, result = self.gripper.run(trajectory(["gripper"], (1.0, [opening])))
            self.assertEqual(state, GoalStatus.SUCCEEDED, result.error_string)
            # where the jaws came to rest (within 0.1 mm over 0.3 s of sim time), not one message after the result
            positions = self.gripper.states.settled(["gripper", "gripper_sub"], band=0.0001)
            positions = dict(zip(["gripper", "gripper_sub"], positions))
            self.assertAlmostEqual(positions["gripper"], opening, delta=0.003)
            self.assertAlmostEqual(positions["gripper_sub"], opening, delta=0.003, msg="gripper_sub does not mimic")
        self.gripper.assert_body_agrees(self, distance=0.003, angle=0.01)

    def test_3_the_base_still_drives(self):
        root = self.arm.model.root
        start_pose = self.arm.world_pose(root)[0]
        cmd = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
        wait_for(lambda: cmd.get_num_connections() > 0, 10, "/cmd_vel subscribed")
        twist = Twist()
        twist.linear.x = 0.1

        def moved():
            cmd.publish(twist)
            return math.dist(start_pose[:2], self.arm.world_pose(root)[0][:2]) > 0.15
        try:
            wait_for(moved, 60, "the base to drive 0.15 m", poll=0.05)
        finally:
            cmd.publish(Twist())


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "manipulator_way", ManipulatorWay, sys.argv)
