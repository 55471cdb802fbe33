#!/usr/bin/env python3
"""arm_way_omx suite: an OpenMANIPULATOR-X-like arm bolted to the world through a mounting offset, from its own
Gazebo launch unchanged (tests/data/arm_way/omx_gazebo: PID gains under /gazebo_ros_control/pid_gains, so the
position JointTrajectoryController's joints run as POSITION_PID; controlPeriod 0.001; Gazebo paused while
spawn_model puts the arm at a pose with -J for every joint, then -unpause; joint states at 1 kHz), judged by
the body as fixedarm.FixedArmCase judges it: link1 held at the spawn pose composed with the world joint's
origin (20 mm up, turned 0.4 rad), the arm starting where -J put it, a goal SUCCEEDED within the controller's
own tolerances with its tracking error inside the path tolerance, joint speeds within what Gazebo lets them
reach, the body where joint_states + the URDF put it, set_model_state and reset_world leaving the base."""
import os
import sys

import rospy
import rostest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fixedarm import FixedArmCase

JOINTS = ["joint1", "joint2", "joint3", "joint4"]
SPAWNED = [0.0, -1.0, 0.3, 0.7]  # omx_gazebo.launch's -J
VIA = [0.4, -0.5, 0.1, 0.4]
TARGET = [0.8, 0.0, -0.2, 0.2]


class ArmWayOmx(FixedArmCase):
    LABEL = "omx"

    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_arm_way_omx")
        cls.start_arm("", "open_manipulator", JOINTS, controller="arm_controller",
                      running=("joint_state_controller", "arm_controller", "gripper_controller"),
                      spawn=((0.3, -0.2, 0.0), (0.0, 0.0, 0.5)))  # -x 0.3 -y -0.2 -z 0.0 -Y 0.5

    def test_1_the_base_is_where_it_was_spawned_and_the_arm_where_j_put_it(self):
        self.check_base_at_rest()
        rest = self.arm.states.settled(JOINTS, band=0.002)
        off = max(abs(r - s) for r, s in zip(rest, SPAWNED))
        self.say(f"at rest after the spawn {off:.4f} rad from the -J configuration")
        self.assertLess(off, 0.02, f"the arm rests at {rest}, not at spawn_model's -J {SPAWNED}")

    def test_2_a_goal_is_reached_and_held_within_the_controllers_tolerances(self):
        self.run_to(SPAWNED)  # where the arm starts in Gazebo (test_1)
        self.check_goal((1.0, VIA), (2.0, TARGET), hold_link="link5")

    def test_3_set_model_state_leaves_the_base_where_it_was_spawned(self):
        self.check_set_model_state()

    def test_4_reset_world_puts_the_arm_back_with_the_base_unmoved(self):
        self.check_reset_world()


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "arm_way_omx", ArmWayOmx, sys.argv)
