#!/usr/bin/env python3
"""Driving behaviour: straight, turn in place, arc, reverse, 1 Hz commands, joint_states, /clock.

Every motion is judged on the body (the ground truth: it moves and turns as commanded, staying upright at its
rest height, base_footprint on the ground) and, separately, on the robot's odometry."""
import math
import statistics
import sys
import unittest

import rospy
import rostest
from simtest import Recorder, Truth, finite_odom, reset_robot, yaw_of

RADIUS = 0.032
SEPARATION = 0.2


def median_twist(msgs):
    """Median (linear.x, angular.z) over a segment: one instantaneous physics velocity can carry contact
    jitter, the median of a steady segment cannot."""
    return (statistics.median(m.twist.twist.linear.x for m in msgs),
            statistics.median(m.twist.twist.angular.z for m in msgs))


class DriveTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_drive")
        cls.rec = Recorder()
        cls.truth = Truth()
        cls.rec.wait_connected()

    def setUp(self):
        reset_robot(self.rec)

    def _segment(self, linear, angular, settle=1.0, duration=4.0):
        """Command, let it settle, then return odom messages over ``duration`` sim seconds; the body must stay
        upright on the ground meanwhile (its ground truth samples are in ``self.body``)."""
        rec = self.rec
        rec.send_until_seen(linear, angular)
        t0 = rec.sim_time() + settle
        first = rec.odom_after(t0)
        last = rec.odom_after(first.header.stamp.to_sec() + duration)
        msgs = [m for m in rec.snapshot(rec.odom)
                if first.header.stamp <= m.header.stamp <= last.header.stamp]
        start, end = first.header.stamp.to_sec(), last.header.stamp.to_sec()
        rec.wait(lambda: self.truth.between(end, end + 1.0), 30.0, "the ground truth of the segment's end")
        self.body = self.truth.ride(start, end, height=0.0)
        return first, last, msgs

    def body_moved(self):
        """(distance [m], turned [rad], summed) of the body over the last segment, by ground truth."""
        body = self.body
        turned = sum(math.atan2(math.sin(b.yaw - a.yaw), math.cos(b.yaw - a.yaw)) for a, b in zip(body, body[1:]))
        return math.hypot(body[-1].x - body[0].x, body[-1].y - body[0].y), turned

    def test_straight(self):
        v = 0.5
        first, last, msgs = self._segment(v, 0.0)
        dt = (last.header.stamp - first.header.stamp).to_sec()
        p0, p1 = first.pose.pose.position, last.pose.pose.position
        distance = math.hypot(p1.x - p0.x, p1.y - p0.y)
        self.assertAlmostEqual(distance, v * dt, delta=0.05 * v * dt, msg=f"distance {distance} in {dt} s")
        self.assertGreater(p1.x - p0.x, 0.0, "forward is +x (REP 103)")
        dyaw = abs(yaw_of(last.pose.pose.orientation) - yaw_of(first.pose.pose.orientation))
        self.assertLess(dyaw, 0.05)
        self.assertAlmostEqual(median_twist(msgs)[0], v, delta=0.05 * v)
        self.assertTrue(all(finite_odom(m) for m in msgs))
        moved, turned = self.body_moved()
        self.assertAlmostEqual(moved, v * dt, delta=0.05 * v * dt, msg=f"the body moved {moved} m in {dt} s")
        self.assertLess(abs(turned), 0.05, "the body kept its heading")

    def test_reverse_twist_is_negative(self):
        first, last, msgs = self._segment(-0.3, 0.0)
        self.assertLess(last.pose.pose.position.x, first.pose.pose.position.x)
        self.assertLess(self.body[-1].x, self.body[0].x - 0.5, "the body backed up")
        self.assertAlmostEqual(median_twist(msgs)[0], -0.3, delta=0.03)

    def test_turn_in_place(self):
        w = 1.0
        first, last, msgs = self._segment(0.0, w)
        dt = (last.header.stamp - first.header.stamp).to_sec()
        turned, prev = 0.0, yaw_of(first.pose.pose.orientation)
        for m in msgs[1:]:
            y = yaw_of(m.pose.pose.orientation)
            turned += math.atan2(math.sin(y - prev), math.cos(y - prev))
            prev = y
        self.assertGreater(turned, 0.0, "positive angular.z turns left (REP 103)")
        self.assertAlmostEqual(turned, w * dt, delta=0.05 + 0.05 * w * dt)
        p0, p1 = first.pose.pose.position, last.pose.pose.position
        self.assertLess(math.hypot(p1.x - p0.x, p1.y - p0.y), 0.05)
        self.assertAlmostEqual(median_twist(msgs)[1], w, delta=0.05 * w)
        moved, body_turned = self.body_moved()
        self.assertAlmostEqual(body_turned, w * dt, delta=0.05 + 0.05 * w * dt, msg="the body turned as told")
        self.assertLess(moved, 0.05, "the body turned in place")

    def test_arc(self):
        v, w = 0.3, 0.5
        first, last, msgs = self._segment(v, w, duration=2.0)
        linear, angular = median_twist(msgs)
        self.assertAlmostEqual(linear, v, delta=0.05 * v)
        self.assertAlmostEqual(angular, w, delta=0.05 * w)
        # The heading advances at w over the segment (the pose, not only the reported twist).
        y0 = yaw_of(first.pose.pose.orientation)
        turned = math.atan2(math.sin(yaw_of(last.pose.pose.orientation) - y0),
                            math.cos(yaw_of(last.pose.pose.orientation) - y0))
        self.assertAlmostEqual(turned, w * (last.header.stamp - first.header.stamp).to_sec(), delta=0.1)
        self.assertGreater(last.pose.pose.position.x, 0.0)
        self.assertGreater(last.pose.pose.orientation.z, 0.0)
        _, body_turned = self.body_moved()
        self.assertAlmostEqual(body_turned, w * (last.header.stamp - first.header.stamp).to_sec(), delta=0.1)

    def test_one_hertz_commands_keep_it_moving(self):
        """Like `rostopic pub -r 1`: a command each sim second; the robot never stops in between."""
        rec = self.rec
        rec.send_until_seen(0.4, 0.0)
        start = rec.sim_time()
        for k in range(1, 4):
            rec.wait(lambda: rec.sim_time() >= start + k, 30.0, "one sim second")
            rec.send(0.4, 0.0)
        speeds = [m.twist.twist.linear.x for m in rec.snapshot(rec.odom) if m.header.stamp.to_sec() > start + 0.5]
        self.assertGreater(len(speeds), 100)
        self.assertGreater(min(speeds), 0.35)

    def test_joint_states(self):
        v = 0.4
        rec = self.rec
        rec.send_until_seen(v, 0.0)
        t = rec.sim_time() + 1.0
        msgs = rec.wait(lambda: [m for m in rec.snapshot(rec.joints) if m.header.stamp.to_sec() > t][:10]
                        if len([m for m in rec.snapshot(rec.joints) if m.header.stamp.to_sec() > t]) >= 10
                        else None, 30.0, "10 joint_states messages")
        for msg in msgs:
            self.assertEqual(list(msg.name), ["left_wheel_joint", "right_wheel_joint", "front_caster_joint",
                                              "back_caster_joint"])
            self.assertEqual(len(msg.position), 4)
            self.assertEqual(len(msg.velocity), 4)
            self.assertEqual(len(msg.effort), 4)
            for i in (0, 1):
                self.assertAlmostEqual(msg.velocity[i], v / RADIUS, delta=0.05 * v / RADIUS)
        # Wheel angle advances consistently with the distance: delta(angle) * r ~= delta(x).
        a, b = msgs[0], msgs[-1]
        oa, ob = rec.odom_after(a.header.stamp.to_sec()), rec.odom_after(b.header.stamp.to_sec())
        rolled = (b.position[0] - a.position[0]) * RADIUS
        moved = ob.pose.pose.position.x - oa.pose.pose.position.x
        self.assertAlmostEqual(rolled, moved, delta=0.05 * abs(moved) + 0.002)

    def test_clock_monotonic_and_stamps_sim_time(self):
        rec = self.rec
        rec.wait_sim(1.0)
        # In fast mode a test node stalled for longer than ~send_timeout (CPU shared with another suite) may have its
        # /clock connection dropped by the simulator's send timeout; rospy reconnects, so wait for the count.
        rec.wait(lambda: len(rec.snapshot(rec.clock)) > 50, 30.0, "more than 50 /clock messages")
        stamps = [m.clock.to_sec() for m in rec.snapshot(rec.clock)]
        self.assertTrue(all(b > a for a, b in zip(stamps, stamps[1:])), "/clock must strictly increase")
        odom = rec.last(rec.odom)
        self.assertLess(abs(odom.header.stamp.to_sec() - rec.sim_time()), 1.0, "odom stamped in sim time")


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_drive", DriveTest, sys.argv)
