#!/usr/bin/env python3
"""Frames and TF switches: the odom header and TF follow ~odometry_frame; ~publish_odom_tf false removes it."""
import sys
import unittest

import rospy
import rostest
import tf2_ros
from simtest import Recorder


class FramesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_frames")
        cls.rec = Recorder()
        cls.rec.wait_connected()
        cls.frame = rospy.get_param("~expect_frame")
        cls.tf_on = rospy.get_param("~expect_tf")
        cls.buffer = tf2_ros.Buffer()
        cls.listener = tf2_ros.TransformListener(cls.buffer)

    def test_odom_header(self):
        msg = self.rec.last(self.rec.odom)
        self.assertEqual(msg.header.frame_id, self.frame)
        self.assertEqual(msg.child_frame_id, "base_footprint")

    def test_tf(self):
        rec = self.rec
        rec.wait_sim(2.0)
        parents = {t.header.frame_id for m in rec.snapshot(rec.tf) for t in m.transforms}
        if self.tf_on:
            self.assertIn(self.frame, parents)
            # The whole tree exists (robot_state_publisher adds base_link); wall-clock deadline, since a
            # sim-time timeout passes in milliseconds in fast mode.
            rec.wait(lambda: self.buffer.can_transform(self.frame, "left_wheel_link", rospy.Time(0)), 20.0,
                     f"TF {self.frame} -> left_wheel_link")
        else:
            self.assertNotIn(self.frame, parents)
            self.assertGreater(len(rec.snapshot(rec.odom)), 10, "odom still publishes without its TF")
        if self.frame != "odom":
            self.assertNotIn("odom", parents)


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_frames", FramesTest, sys.argv)
