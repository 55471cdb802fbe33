#!/usr/bin/env python3
"""Hostile commands: NaN/Inf in every Twist field, absurd magnitudes; and the command timeout."""
import math
import sys
import unittest

import rospy
import rostest
from simtest import Recorder, finite_odom, reset_robot

FIELDS = ("linear_x", "linear_y", "linear_z", "angular_x", "angular_y", "angular_z")


def finite_joint_state(msg):
    return all(math.isfinite(x) for x in list(msg.position) + list(msg.velocity) + list(msg.effort))


def finite_tf(msg):
    return all(math.isfinite(x) for t in msg.transforms for x in (
        t.transform.translation.x, t.transform.translation.y, t.transform.translation.z,
        t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, t.transform.rotation.w))


class _Base(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_safety")
        cls.rec = Recorder()
        cls.rec.wait_connected()

    def setUp(self):
        reset_robot(self.rec)


class SafetyTest(_Base):
    """Runs with the default ~cmd_vel_timeout 0 (safety.test)."""

    def _all_finite_since(self, t):
        rec = self.rec
        odom = [m for m in rec.snapshot(rec.odom) if m.header.stamp.to_sec() >= t]
        joints = [m for m in rec.snapshot(rec.joints) if m.header.stamp.to_sec() >= t]
        tfs = [m for m in rec.snapshot(rec.tf) if m.transforms and m.transforms[0].header.stamp.to_sec() >= t]
        self.assertTrue(odom and joints and tfs, "messages were recorded")
        self.assertTrue(all(finite_odom(m) for m in odom), "odom stayed finite")
        self.assertTrue(all(finite_joint_state(m) for m in joints), "joint_states stayed finite")
        self.assertTrue(all(finite_tf(m) for m in tfs), "tf stayed finite")
        return odom

    def test_non_finite_commands_are_ignored(self):
        rec = self.rec
        t = rec.sim_time()
        for field in FIELDS:
            for value in (float("nan"), float("inf"), float("-inf")):
                for _ in range(10):
                    rec.send(0.0, 0.0, **{field: value})
        rec.wait_sim(1.0)
        odom = self._all_finite_since(t)
        p = odom[-1].pose.pose.position
        self.assertLess(math.hypot(p.x, p.y), 0.001, "the robot stayed put")
        # A normal command afterwards drives as usual.
        rec.send_until_seen(0.3, 0.0)
        start = rec.odom_after(rec.sim_time() + 0.5)
        end = rec.odom_after(start.header.stamp.to_sec() + 1.0)
        self.assertAlmostEqual(end.pose.pose.position.x - start.pose.pose.position.x, 0.3, delta=0.03)

    def test_nan_after_valid_command_keeps_last_valid(self):
        rec = self.rec
        rec.send_until_seen(0.3, 0.0)
        for _ in range(10):
            rec.send(float("nan"), 0.0)
        t = rec.sim_time()
        after = rec.odom_after(t + 1.0)
        self.assertAlmostEqual(after.twist.twist.linear.x, 0.3, delta=0.03)

    def test_extreme_commands_are_clamped(self):
        rec = self.rec
        max_wheel = rospy.get_param("/bullet_sim/effective_max_wheel_velocity")
        radius = rospy.get_param("/bullet_sim/wheel_radius")
        for value in (1e6, 1e308):
            reset_robot(rec)
            t = rec.sim_time()
            rec.send(value, value)
            rec.wait_sim(10.0)
            odom = self._all_finite_since(t)
            for m in odom:
                p, q = m.pose.pose.position, m.pose.pose.orientation
                roll = math.atan2(2 * (q.w * q.x + q.y * q.z), 1 - 2 * (q.x * q.x + q.y * q.y))
                pitch = math.asin(max(-1.0, min(1.0, 2 * (q.w * q.y - q.z * q.x))))
                self.assertLess(abs(p.z), 0.05, "base stays on the ground")
                self.assertLess(max(abs(roll), abs(pitch)), 0.3, "no tipping or blow-up")
            joints = [m for m in rec.snapshot(rec.joints) if m.header.stamp.to_sec() >= t]
            peak = max(abs(v) for m in joints for v in m.velocity[:2])
            self.assertLessEqual(peak, max_wheel * 1.05, f"wheel speed capped at {max_wheel} rad/s")
            self.assertLessEqual(max(abs(m.twist.twist.linear.x) for m in odom), max_wheel * radius * 1.05)



class TimeoutTest(_Base):
    """Runs with ~cmd_vel_timeout 0.5 (timeout.test)."""

    def test_timeout_brakes(self):
        self.assertEqual(rospy.get_param("/bullet_sim/cmd_vel_timeout"), 0.5)
        rec = self.rec
        t = rec.sim_time()
        rec.send(1.0, 0.0)
        rec.wait_sim(3.0)
        odom = [m for m in rec.snapshot(rec.odom) if m.header.stamp.to_sec() >= t]
        self.assertGreater(max(m.pose.pose.position.x for m in odom), 0.01, "the command did move the robot")
        self.assertLess(odom[-1].pose.pose.position.x, 0.6)
        self.assertLess(abs(odom[-1].twist.twist.linear.x), 0.01, "stopped")


if __name__ == "__main__":
    CASE = TimeoutTest if "--timeout" in sys.argv else SafetyTest
    rostest.rosrun("diffbot_sim", "test_safety", CASE, [a for a in sys.argv if a != "--timeout"])
