#!/usr/bin/env python3
"""~pause_physics freezes sim time, ~unpause_physics resumes it; ~reset_world restores the pose and sim time
goes on; ~reset_simulation also sends sim time back to 0 (Gazebo's World::Reset)."""
import math
import sys
import time
import unittest

import rospy
import rostest
from simtest import SIM, Recorder, call


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
        frozen_clock = rec.last(rec.clock).clock
        frozen_odom = rec.last(rec.odom)
        deadline = time.monotonic() + 1.0
        while time.monotonic() < deadline:  # observe for 1 wall second: nothing may advance
            time.sleep(0.05)
            self.assertLessEqual(rec.last(rec.clock).clock, frozen_clock + rospy.Duration(0.05))
        self.assertLess(rec.last(rec.odom).header.stamp - frozen_odom.header.stamp, rospy.Duration(0.05))
        x_paused = rec.last(rec.odom).pose.pose.position.x
        call(SIM + "/unpause_physics")
        rec.wait(lambda: rec.last(rec.odom).pose.pose.position.x > x_paused + 0.05, 20.0, "motion after unpause")
        self.assertGreater(rec.last(rec.odom).pose.pose.position.x, 0.3)
        # reset_world: the robot goes back to its spawn pose; sim time keeps increasing.
        before = rec.sim_time()
        rec.send(0.0, 0.0)
        call(SIM + "/reset_world")
        msg = rec.odom_after(before + 0.2)
        p = msg.pose.pose.position
        self.assertLess(math.hypot(p.x, p.y), 0.01)
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
