#!/usr/bin/env python3
"""arm_way_wxarm_position suite: the small arm of arm_way_wxarm from the same Interbotix-style launch file,
unchanged, with use_position_controllers:=true: one effort_controllers/JointPositionController per joint (P-only
on the arm), commanded through their `command` topics. Judged by the body as fixedarm.FixedArmCase judges it:
the base where it was spawned; after a step command on every arm joint, each joint at rest within what a P loop
leaves against gravity and the joint's friction (Gazebo's static error: (|gravity torque| + friction) / p, from
the URDF), no joint faster than Gazebo lets it (a step drives each joint at its effort limit, so this is where
the velocity limits bite), the base unmoved, the body where joint_states + the URDF put it, the arm holding;
set_model_state and reset_world leaving the base."""
import os
import sys

import rospy
import rostest
from std_msgs.msg import Float64

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fixedarm import FixedArmCase
from simtest import wait_for
from traittest import sim_now

JOINTS = ["waist", "shoulder", "elbow", "wrist_angle", "wrist_rotate"]
TARGET = [-0.5, 0.5, -0.3, 0.4, -0.6]
FRICTION = 0.1  # N·m, the joints' URDF <dynamics friction>
MARGIN = 0.01  # rad beyond the static error: the settling band and the last of the joints' creep


class ArmWayWxarmPosition(FixedArmCase):
    LABEL = "wxarm position"

    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_arm_way_wxarm_position")
        controllers = [f"{j}_controller" for j in JOINTS + ["left_finger", "right_finger"]]
        cls.start_arm("/wxarm", "wxarm", JOINTS, unpause=True, running=["joint_state_controller"] + controllers)
        cls.commands = {j: rospy.Publisher(f"/wxarm/{j}_controller/command", Float64, queue_size=1) for j in JOINTS}

    def test_1_the_base_is_where_it_was_spawned_under_gazebos_name(self):
        self.check_base_at_rest()

    def test_2_step_commands_are_reached_and_held(self):
        wait_for(lambda: all(p.get_num_connections() for p in self.commands.values()), 20,
                 "the controllers subscribed to their command topics")
        self.arm.states.settled(self.joints, band=0.002)
        self.base.worst = 0.0
        start = sim_now()
        for joint, value in zip(JOINTS, TARGET):
            self.commands[joint].publish(Float64(value))
        gravity = self.dynamics.gravity(dict(zip(JOINTS, TARGET)))
        tolerances = {j: (abs(gravity[j]) + FRICTION) / rospy.get_param(f"/wxarm/{j}_controller/pid/p") + MARGIN
                      for j in JOINTS}
        self.check_rest(TARGET, start, None, "wxarm/gripper_link", tolerances)

    def test_3_set_model_state_leaves_the_base_where_it_was_spawned(self):
        self.check_set_model_state()

    def test_4_reset_world_puts_the_arm_back_with_the_base_unmoved(self):
        self.check_reset_world()


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "arm_way_wxarm_position", ArmWayWxarmPosition, sys.argv)
