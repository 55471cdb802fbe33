#!/usr/bin/env python3
"""arm_way_wxarm suite: a small 5-joint arm with two fingers bolted to the world, from its own Interbotix-style
Gazebo launch unchanged (tests/data/arm_way/wxarm_gazebo, use_trajectory_controllers:=true: a world file with a
blank line before its XML declaration, Gazebo left paused for the user to press play, everything in the
robot's namespace, links named wxarm/<link>, an effort JointTrajectoryController with P-only gains (an `i`
without `i_clamp`, no `d`) and goal_time 0.2, a shoulder limited to 0.84 rad/s), judged by the body as
fixedarm.FixedArmCase judges it: the base where it was spawned, a goal SUCCEEDED within the controller's own
tolerances with its tracking error inside the path tolerance, joint speeds within what Gazebo lets them
reach, the body where joint_states + the URDF put it, set_model_state and reset_world leaving the base."""
import os
import sys

import rospy
import rostest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fixedarm import FixedArmCase

JOINTS = ["waist", "shoulder", "elbow", "wrist_angle", "wrist_rotate"]
VIA = [0.3, 0.35, -0.2, 0.3, 0.4]
TARGET = [0.6, 0.7, -0.4, 0.6, 0.8]  # the shoulder at 0.5 rad/s of its 0.84


class ArmWayWxarm(FixedArmCase):
    LABEL = "wxarm trajectory"

    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_arm_way_wxarm")
        cls.start_arm("/wxarm", "wxarm", JOINTS, controller="arm_controller", unpause=True,
                      running=("arm_controller", "gripper_controller", "joint_state_controller"))

    def test_1_the_base_is_where_it_was_spawned_under_gazebos_name(self):
        self.check_base_at_rest()

    def test_2_a_goal_is_reached_and_held_within_the_controllers_tolerances(self):
        self.check_goal((0.7, VIA), (1.4, TARGET), hold_link="wxarm/gripper_link")

    def test_3_set_model_state_leaves_the_base_where_it_was_spawned(self):
        self.check_set_model_state()

    def test_4_reset_world_puts_the_arm_back_with_the_base_unmoved(self):
        self.check_reset_world()


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "arm_way_wxarm", ArmWayWxarm, sys.argv)
