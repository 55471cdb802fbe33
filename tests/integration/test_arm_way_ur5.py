#!/usr/bin/env python3
"""arm_way_ur5 suite (and arm_way_ur5_fast): a UR5-like arm bolted to the world, run from its own ur_gazebo-style
bringup launch unchanged (tests/data/arm_way/ur5like_gazebo: `world` link and world_joint, a 4 kg base that a
free base could not hold up, EffortJointInterface transmissions, gazebo_ros_control with no robotNamespace and
no controlPeriod, UR5's effort trajectory gains and constraints, `spawn_model -z 0.1`, Gazebo's empty world at
its 1 ms step; started paused, as `paused:=true` does, and unpaused once the controllers are loaded, so that the
arm does not fall limp onto the floor before they hold it), judged by the body (fixedarm.FixedArmCase):

- base_link is where spawn_model put it (ground truth within 1 mm), answers as ``robot::base_link``, and no
  link is called ``robot::world``;
- a FollowJointTrajectory goal SUCCEEDS within the controller's own tolerances, the controller's tracking
  error along the way stays inside its path tolerance, no joint passes its URDF velocity limit by more than
  Gazebo lets it within a step, the base does not move while the arm swings, the arm holds its goal and every
  link is where joint_states + the URDF put it;
- ``/gazebo/set_model_state`` on the arm leaves the base where it was spawned;
- ``/gazebo/reset_world`` puts every joint back at zero with the base unmoved.
"""
import os
import sys

import rospy
import rostest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fixedarm import FixedArmCase

JOINTS = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]
VIA = [0.3, -0.6, 0.5, -0.3, 0.2, 0.4]
TARGET = [0.6, -1.2, 1.0, -0.6, 0.4, 0.8]


class ArmWayUr5(FixedArmCase):
    LABEL = "ur5like"

    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_arm_way_ur5")
        cls.start_arm("", "robot", JOINTS, controller="eff_joint_traj_controller",  # gazebo_model_name: robot
                      running=("joint_state_controller", "eff_joint_traj_controller"), unpause=True,
                      stopped=("joint_group_eff_controller",), spawn=((0.0, 0.0, 0.1), (0.0, 0.0, 0.0)))

    def test_1_the_base_is_where_it_was_spawned_under_gazebos_name(self):
        self.check_base_at_rest()

    def test_2_a_goal_is_reached_and_held_within_the_controllers_tolerances(self):
        self.check_goal((1.5, VIA), (3.0, TARGET), hold_link="wrist_3_link")

    def test_3_set_model_state_leaves_the_base_where_it_was_spawned(self):
        self.check_set_model_state()

    def test_4_reset_world_puts_the_arm_back_with_the_base_unmoved(self):
        self.check_reset_world()


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "arm_way_ur5", ArmWayUr5, sys.argv)
