#!/usr/bin/env python3
"""arm_cell_namespace suite: controllers in a robot namespace, as published fixed-arm launch files load them
(arm_cell_namespace.test). The controller manager serves /my_arm/controller_manager/*, the spawners' controllers
run there (one loaded stopped), joint_state_controller publishes /my_arm/joint_states (nothing on
/joint_states), the trajectory controller's action is /my_arm/arm_controller/follow_joint_trajectory, and the
TF that the group's robot_state_publisher draws from /my_arm/joint_states puts the links where the physics has
them."""
import math
import os
import sys
import unittest

import rospy
import rosservice
import rostest
import tf2_ros
from actionlib_msgs.msg import GoalStatus
from control_msgs.msg import FollowJointTrajectoryResult as Result
from controller_manager_msgs.srv import ListControllers
from sensor_msgs.msg import JointState

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from armtest import Arm, close, trajectory
from simtest import Latest, wait_for

NS = "/my_arm"  # arm_cell.launch's robot_name: its <group ns>, spawn_model -model and -robot_namespace
ARM = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]
RUNNING = {"joint_state_controller", "arm_controller", "gripper_controller"}


class ArmCellNamespace(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_arm_cell_namespace")
        rospy.wait_for_service(f"{NS}/controller_manager/list_controllers", 90)
        cls.listing = rospy.ServiceProxy(f"{NS}/controller_manager/list_controllers", ListControllers)
        wait_for(lambda: {c.name for c in cls.listing().controller if c.state == "running"} >= RUNNING, 90,
                 f"the spawners to start {', '.join(sorted(RUNNING))} under {NS}")
        cls.tf = tf2_ros.Buffer()
        cls.tf_listener = tf2_ros.TransformListener(cls.tf)

    def test_1_controllers_and_joint_states_are_the_namespaces(self):
        states = {c.name: c.state for c in self.listing().controller}
        self.assertEqual(states, {"joint_state_controller": "running", "arm_controller": "running",
                                  "gripper_controller": "running", "joint_group_effort_controller": "stopped"})
        services = set(rosservice.get_service_list())
        self.assertIn(f"{NS}/controller_manager/switch_controller", services)
        outside = {name for name in services if name.startswith("/controller_manager/")}
        self.assertFalse(outside, "a controller manager outside the namespace")
        joints = Latest(f"{NS}/joint_states", JointState)
        msg = wait_for(joints.get, 20, f"{NS}/joint_states")
        self.assertTrue(set(ARM) | {"finger_joint"} <= set(msg.name), msg.name)
        topics = {name for name, _ in rospy.get_published_topics()}
        self.assertNotIn("/joint_states", topics, "joint_state_controller published outside the namespace")
        self.assertIn(f"{NS}/arm_controller/follow_joint_trajectory/status", topics)  # the action server

    def test_2_a_goal_in_the_namespace_and_tf_from_its_robot_state_publisher(self):
        arm = Arm(f"{NS}/arm_controller", "my_arm", description=f"{NS}/robot_description",
                  joint_states=f"{NS}/joint_states")
        target = [0.6, -0.5, 1.0, 0.3, 0.4, -0.5]
        state, result = arm.run(trajectory(ARM, (3.0, target)), timeout=60)
        self.assertEqual((state, result.error_code), (GoalStatus.SUCCEEDED, Result.SUCCESSFUL), result.error_string)
        self.assertTrue(close(arm.states.settled(ARM), target, 0.1))
        for link in ("forearm_link", "wrist_3_link"):
            truth = arm.world_pose(link)[0]

            def drawn(link=link, truth=truth):
                """TF drawn from a joint_states message after the arm settled: within 2 mm of the body."""
                t = self.tf.lookup_transform("world", link, rospy.Time(0), rospy.Duration(1)).transform.translation
                return math.dist((t.x, t.y, t.z), truth) < 0.002
            wait_for(drawn, 20, f"TF of {link} (the group's robot_state_publisher) within 2 mm of the body")


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "arm_cell_namespace", ArmCellNamespace, sys.argv)
