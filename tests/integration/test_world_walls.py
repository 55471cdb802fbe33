#!/usr/bin/env python3
"""Robots driven at a world's obstacles stop where the geometry says (through ROS: cmd_vel in, ground truth
out). Each lane is one named robot of ``~robots``, driven at 0.3 m/s for 7 s of sim time from x = 0.

Private parameter ~lanes: a list of {robot: NAME, stop: X} (the robot ends within 2 cm of x = X: an
obstacle's face minus the robot's 0.1 m front), {robot: NAME, beyond: X} (it pushed something past X), or
{robot: NAME, z: Z} (not driven: it was spawned onto a surface at height Z and rests there within 2 cm).
~reset_world (bool): afterwards, /bullet_sim/reset_world puts every robot back at its start while sim time
goes on.
"""
import sys
import threading
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from simtest import sim_now, wait_for

from diffbot_sim.check.stillness import held_still

SIM = "/bullet_sim"
SPEED, SECONDS, TOLERANCE = 0.3, 7.0, 0.02
REST_BAND, REST_WINDOW = 0.001, 0.3  # m, s of sim time: a body whose position stays within this band is at rest


class WorldWallsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_world_walls")
        cls.lanes = rospy.get_param("~lanes")
        cls.lock = threading.Lock()
        cls.truth = {}
        cls.history = {}  # name -> [(stamp, [x, y, z])], the last 2 s or so of ground truth
        cls.subs, cls.pubs = [], {}
        for lane in cls.lanes:
            name = lane["robot"]
            cls.subs.append(rospy.Subscriber(f"{SIM}/{name}/ground_truth", Odometry, cls._keep,
                                             callback_args=name, queue_size=100))
            cls.pubs[name] = rospy.Publisher(f"/{name}/cmd_vel", Twist, queue_size=1)

    @classmethod
    def _keep(cls, msg, name):
        p = msg.pose.pose.position
        with cls.lock:
            cls.truth[name] = p
            kept = cls.history.setdefault(name, [])
            kept.append((msg.header.stamp.to_sec(), [p.x, p.y, p.z]))
            del kept[:-500]

    def at_rest(self, names, since):
        """{name: position} once every robot's ground truth, stamped at or after ``since``, has held within
        REST_BAND over the last REST_WINDOW s of its stamps (stillness.held_still); else None."""
        with self.lock:
            history = {n: [s for s in self.history.get(n, []) if s[0] >= since] for n in names}
            if all(held_still(history[n], REST_BAND, REST_WINDOW)[0] for n in names):
                return {n: self.truth[n] for n in names}
        return None

    def wait(self, predicate, timeout, what):
        return wait_for(predicate, timeout, what, 0.01)

    def test_robots_stop_where_the_geometry_says(self):
        every = [lane["robot"] for lane in self.lanes]
        names = [lane["robot"] for lane in self.lanes if "z" not in lane]
        self.wait(lambda: all(n in self.truth for n in every), 60.0, "every robot's ground truth")
        self.wait(lambda: all(self.pubs[n].get_num_connections() > 0 for n in names), 30.0, "the cmd_vel subscribers")
        # every robot at rest (one dropped from a height has landed), judged by its ground truth's stamps
        rest = self.wait(lambda: self.at_rest(every, -1.0), 60.0, "every robot at rest before the drive")
        start = {n: rest[n].x for n in every}
        for name in every:
            self.assertAlmostEqual(start[name], 0.0, delta=0.02, msg=f"{name} did not start at x = 0")
        msg = Twist()
        msg.linear.x = SPEED
        end = rospy.get_time() + SECONDS
        while rospy.get_time() < end:
            for name in names:
                self.pubs[name].publish(msg)
            rospy.sleep(0.05)
        for name in names:
            self.pubs[name].publish(Twist())
        # where each robot ended: ground truth stamped after the stop (the newest this node holds may be older)
        stopped = sim_now()
        self.wait(lambda: all(self.history.get(n) and self.history[n][-1][0] >= stopped for n in every), 30.0,
                  "ground truth stamped after the stop")
        with self.lock:
            final = {n: self.truth[n].x for n in every}
            heights = {n: self.truth[n].z for n in every}
        for lane in self.lanes:
            name, x = lane["robot"], final[lane["robot"]]
            if "z" in lane:
                rospy.loginfo(f"FIGURE {name}: rests at z = {heights[name]:.3f}")
                self.assertAlmostEqual(heights[name], lane["z"], delta=TOLERANCE, msg=f"{name} rests at z = "
                                       f"{heights[name]:.3f}, the surface under it is at {lane['z']}")
                continue
            rospy.loginfo(f"FIGURE {name}: ended at x = {x:.3f}")
            if "stop" in lane:
                self.assertAlmostEqual(x, lane["stop"], delta=TOLERANCE,
                                       msg=f"{name} ended at x = {x:.3f}, the geometry says {lane['stop']}")
            else:
                self.assertGreater(x, lane["beyond"], f"{name} ended at x = {x:.3f}: nothing was pushed")


    def test_zz_reset_world_puts_robots_back_and_keeps_time(self):
        """After the drive (methods run in name order): ~reset_world, as Gazebo's reset_world."""
        if not rospy.get_param("~reset_world", False):
            self.skipTest("~reset_world not asked for")
        from std_srvs.srv import Empty
        names = [lane["robot"] for lane in self.lanes]
        self.wait(lambda: all(n in self.truth for n in names), 60.0, "every robot's ground truth")
        before = rospy.get_time()
        rospy.wait_for_service(SIM + "/reset_world", 10.0)
        rospy.ServiceProxy(SIM + "/reset_world", Empty)()
        self.wait(lambda: all(abs(self.truth[n].x) < 0.02 for n in names), 20.0, "every robot back at x = 0")
        self.assertGreater(rospy.get_time(), before, "sim time went back on reset_world")


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_world_walls", WorldWallsTest, sys.argv)
