#!/usr/bin/env python3
"""The link attacher world plugin: /link_attacher_node/attach joins box_b to box_a where they are (a push on box_a
then carries box_b along at the same distance, by ground truth), detach releases it (the next push moves box_a
alone), unknown models and links answer ok false, detaching a pair never attached answers false."""
import math
import sys
import unittest

import rospy
import rostest
from gazebo_msgs.srv import ApplyBodyWrench, GetModelState
from gazebo_ros_link_attacher.srv import Attach
from geometry_msgs.msg import Wrench
from simtest import figure, wait_for
from std_srvs.srv import Empty


class LinkAttacherTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_link_attacher")
        for name in ("/link_attacher_node/attach", "/link_attacher_node/detach", "/gazebo/apply_body_wrench"):
            rospy.wait_for_service(name, 60.0)
        cls.attach = rospy.ServiceProxy("/link_attacher_node/attach", Attach)
        cls.detach = rospy.ServiceProxy("/link_attacher_node/detach", Attach)
        cls.push_srv = rospy.ServiceProxy("/gazebo/apply_body_wrench", ApplyBodyWrench)
        cls.state = rospy.ServiceProxy("/gazebo/get_model_state", GetModelState)

    def xy(self, model):
        p = self.state(model, "world").pose.position
        return p.x, p.y

    def both(self):
        """(box_a, box_b) positions at one instant: the boxes slide on (mu 0), so read them paused."""
        rospy.ServiceProxy("/gazebo/pause_physics", Empty)()
        try:
            return self.xy("box_a"), self.xy("box_b")
        finally:
            rospy.ServiceProxy("/gazebo/unpause_physics", Empty)()

    def push(self, force_x, seconds=0.5):
        wrench = Wrench()
        wrench.force.x = force_x
        before = self.xy("box_a")
        self.assertTrue(self.push_srv("box_a::link", "world", None, wrench, rospy.Time(0),
                                      rospy.Duration(seconds)).success)
        wait_for(lambda: abs(self.xy("box_a")[0] - before[0]) > 0.1, 30.0, "box_a moved by the push")
        rospy.sleep(1.0)

    def test_attach_carries_and_detach_releases(self):
        self.assertFalse(self.attach("nope", "link", "box_b", "link").ok)
        self.assertFalse(self.attach("box_a", "nope", "box_b", "link").ok)
        self.assertFalse(self.detach("box_a", "link", "box_b", "link").ok, "detach of a pair never attached")
        a0, b0 = self.both()
        gap0 = math.dist(a0, b0)
        self.assertTrue(self.attach("box_a", "link", "box_b", "link").ok)
        self.assertTrue(self.attach("box_a", "link", "box_b", "link").ok, "attaching again reuses the joint")
        self.push(4.0)
        a1, b1 = self.both()
        figure(f"attached: box_a moved {a1[0] - a0[0]:.3f} m, box_b {b1[0] - b0[0]:.3f} m, gap {gap0:.4f} -> "
               f"{math.dist(a1, b1):.4f} m")
        self.assertGreater(b1[0] - b0[0], 0.1, "box_b carried along")
        self.assertAlmostEqual(math.dist(a1, b1), gap0, delta=0.002)
        self.assertTrue(self.detach("box_a", "link", "box_b", "link").ok)
        self.push(-4.0)
        a2, b2 = self.both()
        figure(f"detached: box_a moved {a2[0] - a1[0]:.3f} m, box_b {b2[0] - b1[0]:.3f} m")
        self.assertLess(a2[0] - a1[0], -0.1)
        self.assertGreater(math.dist(a2, b2), gap0 + 0.1, "box_b stayed behind")


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_link_attacher", LinkAttacherTest, sys.argv)
