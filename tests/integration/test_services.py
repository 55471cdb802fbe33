#!/usr/bin/env python3
"""~pause_physics freezes sim time, ~unpause_physics resumes it; ~reset_world restores the pose and sim time
goes on; ~reset_simulation also sends sim time back to 0 (Gazebo's World::Reset)."""
import math
import sys
import time
import unittest

import rospy
import rostest
from simtest import SIM, Recorder, call, sim_now


class ServicesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_services")
        cls.rec = Recorder()
        cls.rec.wait_connected()

    def test_pause_unpause_reset(self):
        rec = self.rec
        rec.send_until_seen(0.5, 0.0)
        rec.wait_sim(1.0)
        call(SIM + "/pause_physics")
        # The simulator's own time at the pause: the newest /clock or odom this node has received may be
        # older (on a loaded machine they queue up), and the ones still queued are not an advance.
        paused_at = sim_now()
        frozen = rospy.Duration.from_sec(paused_at)
        deadline = time.monotonic() + 1.0
        while time.monotonic() < deadline:  # observe for 1 wall second: nothing may advance
            time.sleep(0.05)
            self.assertLessEqual(rec.last(rec.clock).clock, rospy.Time() + frozen + rospy.Duration(0.05),
                                 "/clock advanced while paused")
        self.assertLess(rec.last(rec.odom).header.stamp - rospy.Time() - frozen, rospy.Duration(0.05),
                        "odom advanced while paused")
        self.assertEqual(sim_now(), paused_at, "sim time advanced while paused")
        x_paused = rec.last(rec.odom).pose.pose.position.x
        call(SIM + "/unpause_physics")

        def moved_after_unpause():
            msg = rec.last(rec.odom)
            return msg.header.stamp.to_sec() > paused_at and msg.pose.pose.position.x > x_paused + 0.05
        rec.wait(moved_after_unpause, 20.0, "motion after unpause (odom stamped after the pause, 5 cm on)")
        self.assertGreater(rec.last(rec.odom).pose.pose.position.x, 0.3)
        # reset_world: the robot goes back to its spawn pose; sim time keeps increasing.
        rec.send(0.0, 0.0)
        before = sim_now()
        call(SIM + "/reset_world")
        after = sim_now()  # anything stamped later follows the reset, whatever this node has received so far
        self.assertGreaterEqual(after, before, "sim time does not jump back on reset_world")
        msg = rec.odom_after(after + 1e-6)
        p = msg.pose.pose.position
        self.assertLess(math.hypot(p.x, p.y), 0.01, "the robot back at its spawn pose after reset_world")
        self.assertGreater(msg.header.stamp.to_sec(), before, "sim time does not jump back on reset_world")
        # reset_simulation: sim time starts again from 0 (the clock jumps back), the robot at its spawn pose.
        rec.send_until_seen(0.5, 0.0)
        rec.wait(lambda: rec.last(rec.odom).pose.pose.position.x > 0.2, 20.0, "motion before reset_simulation")
        before = rec.sim_time()
        rec.send(0.0, 0.0)
        seen_clock, seen_odom = len(rec.snapshot(rec.clock)), len(rec.snapshot(rec.odom))
        call(SIM + "/reset_simulation")
        msg = rec.wait(lambda: next((m for m in rec.snapshot(rec.clock)[seen_clock:]
                                     if m.clock.to_sec() < 0.5 * before), None),
                       10.0, "/clock back near 0 after reset_simulation")
        self.assertLess(msg.clock.to_sec(), 0.5 * before)
        msg = rec.wait(lambda: next((m for m in rec.snapshot(rec.odom)[seen_odom:]
                                     if m.header.stamp.to_sec() < 0.5 * before), None), 10.0, "odom after the reset")
        self.assertLess(math.hypot(msg.pose.pose.position.x, msg.pose.pose.position.y), 0.05)


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_services", ServicesTest, sys.argv)
