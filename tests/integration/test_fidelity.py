#!/usr/bin/env python3
"""Fidelity against the physics ground truth (~ground_truth): encoder odometry on a 2 m straight and a
360 degree turn in place (encoder mode), or world odometry equal to the physics pose (world mode)."""
import math
import sys
import unittest

import rospy
import rostest
from simtest import SIM, Recorder, reset_robot, yaw_of


def unwrap(msgs):
    total, prev = 0.0, yaw_of(msgs[0].pose.pose.orientation)
    for m in msgs[1:]:
        y = yaw_of(m.pose.pose.orientation)
        total += math.atan2(math.sin(y - prev), math.cos(y - prev))
        prev = y
    return total


class FidelityTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_fidelity")
        cls.rec = Recorder(extra_odom=SIM + "/ground_truth")
        cls.rec.wait_connected()
        cls.source = rospy.get_param(SIM + "/odometry_source")

    def setUp(self):
        reset_robot(self.rec)

    def _pair(self, stamp):
        """Odom and ground truth with the same stamp."""
        rec = self.rec
        odom = rec.odom_after(stamp)
        truth = rec.odom_after(odom.header.stamp.to_sec(), store=rec.extra)
        self.assertEqual(odom.header.stamp, truth.header.stamp)
        return odom, truth

    def test_straight_2m(self):
        rec = self.rec
        rec.send(0.2, 0.0)
        rec.wait(lambda: rec.last(rec.odom).pose.pose.position.x >= 2.0, 120.0, "2 m travelled")
        rec.send(0.0, 0.0)
        odom, truth = self._pair(rec.sim_time() + 1.0)
        po, pt = odom.pose.pose.position, truth.pose.pose.position
        error = math.hypot(po.x - pt.x, po.y - pt.y)
        rospy.loginfo(f"FIGURE straight_2m[{self.source}]: travelled {pt.x:.4f} m, error {error * 1000:.2f} mm "
                      f"({100 * error / pt.x:.3f} %)")
        self.assertGreater(pt.x, 1.95)
        limit = 0.001 if self.source == "world" else 0.01 * pt.x
        self.assertLessEqual(error, limit)

    def test_turn_360(self):
        rec = self.rec
        t0 = rec.sim_time()
        rec.send(0.0, 1.0)
        rec.wait(lambda: unwrap([m for m in rec.snapshot(rec.odom) if m.header.stamp.to_sec() >= t0]) >= 2 * math.pi,
                 120.0, "a full turn")
        rec.send(0.0, 0.0)
        odom, truth = self._pair(rec.sim_time() + 1.0)
        end = odom.header.stamp.to_sec()
        yaw_o = unwrap([m for m in rec.snapshot(rec.odom) if t0 <= m.header.stamp.to_sec() <= end])
        yaw_t = unwrap([m for m in rec.snapshot(rec.extra) if t0 <= m.header.stamp.to_sec() <= end])
        rospy.loginfo(f"FIGURE turn_360[{self.source}]: turned {yaw_t:.4f} rad, error {abs(yaw_o - yaw_t):.4f} rad")
        self.assertGreater(yaw_t, 2 * math.pi - 0.2)
        self.assertLessEqual(abs(yaw_o - yaw_t), 0.001 if self.source == "world" else 0.05)

    def test_mass(self):
        loaded = rospy.get_param(SIM + "/loaded_mass")
        urdf = rospy.get_param(SIM + "/urdf_mass")
        self.assertAlmostEqual(loaded, urdf, delta=1e-5)


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_fidelity", FidelityTest, sys.argv)
