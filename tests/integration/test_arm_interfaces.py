#!/usr/bin/env python3
"""arm_interfaces suite: one JointTrajectoryController goal on each way DefaultRobotHWSim drives a joint
(position with pid_gains, position without gains, effort, velocity), judged by the body: the goal SUCCEEDS,
every link is where joint_states + the URDF put it (ground truth), and the arm holds that pose under gravity,
stretched out sideways (the worst load for the shoulder)."""
import math
import os
import sys
import unittest

import rospy
import rostest
from actionlib_msgs.msg import GoalStatus
from control_msgs.msg import FollowJointTrajectoryResult as Result

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from armtest import Arm, close, trajectory
from traittest import sim_sleep

JOINTS = ["joint_1", "joint_2", "joint_3"]
TARGET = [0.8, 1.0, 0.6]  # joint_2 tilts the arm 1 rad, joint_3 bends it further: a long lever against gravity


class ArmInterfaces(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_arm_interfaces")

    def check(self, name):
        arm = Arm(f"/{name}/arm_controller", name, description=f"/{name}/robot_description",
                  joint_states=f"/{name}/joint_states")
        state, result = arm.run(trajectory(JOINTS, (1.0, [0.4, 0.5, 0.3]), (2.5, TARGET)))
        self.assertEqual((state, result.error_code), (GoalStatus.SUCCEEDED, Result.SUCCESSFUL),
                         f"{name}: {result.error_string}")
        reached = arm.states.fresh(JOINTS)  # from a message stamped after the goal's result
        self.assertTrue(close(reached, TARGET, 0.03), f"{name}: joints at {reached}, goal {TARGET}")
        arm.assert_body_agrees(self, distance=0.003, angle=0.01)
        tool = arm.world_pose("link_3")[0]
        sim_sleep(3.0, timeout=60)  # holds for 3 s of the simulator's sim time
        later = arm.world_pose("link_3")[0]
        self.assertLess(math.dist(tool, later), 0.005,
                        f"{name}: the stretched arm sagged {math.dist(tool, later):.4f} m")
        return arm

    def test_position_with_pid_gains(self):
        self.check("pid")

    def test_position_without_gains(self):
        self.check("nogains")

    def test_effort_trajectory_controller(self):
        self.check("effort")

    def test_velocity_trajectory_controller(self):
        self.check("velocity")


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "arm_interfaces", ArmInterfaces, sys.argv)
