#!/usr/bin/env python3
"""Joints with a transmission that no drive plugin names get gazebo_ros_control-style command topics:
<joint>_velocity_controller/command and <joint>_position_controller/command (std_msgs/Float64)."""
import math
import sys
import unittest

import rospy
import rostest
from simtest import Recorder, sim_now
from std_msgs.msg import Float64


class JointMotorsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_joint_motors")
        cls.rec = Recorder()
        cls.rec.wait_connected()
        cls.velocity = rospy.Publisher("/mast_joint_velocity_controller/command", Float64, queue_size=10)
        cls.position = rospy.Publisher("/flap_joint_position_controller/command", Float64, queue_size=10)
        for pub in (cls.velocity, cls.position):
            cls.rec.wait(lambda: pub.get_num_connections() > 0, 20.0, f"a subscriber on {pub.name}")

    def _joint(self, name):
        msg = self.rec.last(self.rec.joints)
        i = list(msg.name).index(name)
        return msg.position[i], msg.velocity[i]

    def test_velocity_and_position_commands(self):
        rec = self.rec
        self.assertLess(abs(self._joint("mast_joint")[1]), 0.1, "the mast is still before any command")
        self.velocity.publish(2.0)
        self.position.publish(0.5)
        rec.wait(lambda: abs(self._joint("mast_joint")[1] - 2.0) < 0.1, 20.0, "mast at 2 rad/s")
        rec.wait(lambda: abs(self._joint("flap_joint")[0] - 0.5) < 0.05, 20.0, "flap at 0.5 rad")
        # A non-finite command is ignored: the mast keeps its speed, every state stays finite.
        self.velocity.publish(float("nan"))
        # joint_states stamped 0.5 s of sim time after the NaN went out (the newest this node holds may be older)
        msg = rec.odom_after(sim_now() + 0.5, store=rec.joints)
        self.assertAlmostEqual(dict(zip(msg.name, msg.velocity, strict=True))["mast_joint"], 2.0, delta=0.1)
        self.assertTrue(all(math.isfinite(v) for v in list(msg.position) + list(msg.velocity)))
        self.velocity.publish(0.0)
        rec.wait(lambda: abs(self._joint("mast_joint")[1]) < 0.1, 20.0, "mast stopped")


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_joint_motors", JointMotorsTest, sys.argv)
