#!/usr/bin/env python3
"""moveit_pick_place suite (`make test-moveit`): ``rosrun diffbot_sim pick_place --moveit`` run as a user runs it
beside diffbot_arm_moveit_config's demo_gazebo.launch (the simulator with move_group), judged by the box's ground
truth (/gazebo/get_link_state):

- the node exits 0 (every step succeeded: every MoveIt plan found and executed);
- the box was lifted clear of the table (more than 3 cm above its resting height at some point);
- the box ends on place_table within 2 cm of the place point, resting (its centre at the rest height within
  1 cm) and upright (tilted less than 0.1 rad).
"""
import math
import os
import re
import subprocess
import sys
import threading
import time
import unittest

import rospy
import rostest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from moveittest import wait_for_move_group
from traittest import settled

from diffbot_sim.control.pick_place import Scene
from diffbot_sim.transforms import roll_pitch_from_quaternion

BOX = "pick_box::link"
NODE_TIMEOUT = 600.0  # s wall


class MoveItPickPlace(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        from gazebo_msgs.srv import GetLinkState

        rospy.init_node("test_moveit_pick_place")
        wait_for_move_group()
        rospy.wait_for_service("/gazebo/get_link_state", 60)
        cls.link_state = rospy.ServiceProxy("/gazebo/get_link_state", GetLinkState)
        cls.start = cls.box_pose()
        heights, stop = [], threading.Event()

        def watch():
            while not stop.is_set():
                try:
                    heights.append(cls.box_pose()[2])
                except rospy.ServiceException:
                    pass
                time.sleep(0.02)
        watcher = threading.Thread(target=watch, daemon=True)
        watcher.start()
        log = os.path.join(os.environ.get("ROS_LOG_DIR", "/tmp"), "pick_place_moveit_node.log")
        sim0, wall0 = rospy.get_time(), time.monotonic()
        try:
            with open(log, "w") as out:
                cls.process = subprocess.run(["rosrun", "diffbot_sim", "pick_place", "--moveit"], stdout=out,
                                             stderr=subprocess.STDOUT, timeout=NODE_TIMEOUT)
        finally:
            stop.set()
            watcher.join()
        cls.sim_seconds, cls.wall_seconds = rospy.get_time() - sim0, time.monotonic() - wall0
        with open(log) as text:
            cls.node_output = text.read()
        cls.highest = max(heights) if heights else None
        cls.end = settled(lambda: list(cls.box_pose()), 0.0005, what="the placed box")

    @classmethod
    def box_pose(cls):
        resp = cls.link_state(BOX, "")
        if not resp.success:
            raise AssertionError(f"get_link_state {BOX}: {resp.status_message}")
        p, q = resp.link_state.pose.position, resp.link_state.pose.orientation
        return (p.x, p.y, p.z, q.x, q.y, q.z, q.w)

    def test_1_node_succeeds(self):
        done = re.findall(r"pick_place: done: .*", self.node_output)
        print(f"FIGURE pick_place --moveit: {done[-1] if done else 'not done'}; {self.sim_seconds:.1f} s sim, "
              f"{self.wall_seconds:.1f} s wall (RTF {self.sim_seconds / self.wall_seconds:.2f})", flush=True)
        self.assertEqual(self.process.returncode, 0, f"pick_place --moveit exited {self.process.returncode}:\n"
                         f"{self.node_output[-3000:]}")

    def test_2_box_was_lifted(self):
        scene = Scene()
        self.assertIsNotNone(self.highest)
        self.assertGreater(self.highest, scene.pick[2] + 0.03, f"the box rose to z {self.highest:.3f} at most")

    def test_3_box_ends_on_the_place_table(self):
        scene = Scene()
        off = math.dist(self.end[:2], scene.place[:2])
        roll, pitch = roll_pitch_from_quaternion(*self.end[3:])
        print(f"FIGURE pick_place --moveit: the box ended {off * 100:.2f} cm from the place point, centre at z "
              f"{self.end[2]:.4f}, tilted {max(abs(roll), abs(pitch)):.3f} rad", flush=True)
        self.assertLess(off, 0.02, f"the box ended at {self.end[:3]}, {off * 100:.1f} cm from {scene.place}")
        self.assertAlmostEqual(self.end[2], scene.place[2], delta=0.01)
        self.assertLess(max(abs(roll), abs(pitch)), 0.1, "the box is not upright")


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "moveit_pick_place", MoveItPickPlace, sys.argv)
