#!/usr/bin/env python3
"""view_multi suite: ``view_multi.launch`` (multi.launch's robot1 at (0, 0) and robot2 at (0, 1) plus rviz)
under Xvfb, judged as view_rviz judges one robot (test_view_rviz.py's helpers): every display (one RobotModel
and one Odometry per robot, prefixed frames) drawn Ok-blue, rviz subscribed to and receiving each robot's
odometry, nothing logged; and robot2's pixels (a frame with its RobotModel display against one without)
where its spawn pose puts them in the fixed frame robot1/odom, away from robot1.
"""
import math
import os
import sys
import tempfile

import rospy
import rostest
import viewtest
from test_view_rviz import ViewRviz

ROBOT2 = (0.0, 1.0)  # m, multi.launch's spawn pose of robot2; robot1 (the fixed frame's) is at the origin


class ViewMulti(ViewRviz):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_view_multi")
        if not cls.start_view("view_multi", viewtest.View([f"world:={viewtest.WORLD}"], "view_multi_launch",
                                                          launch="view_multi.launch"), ready=cls.rviz_up):
            return
        cls.tmp = tempfile.mkdtemp(prefix="view_multi_")
        cls.config = viewtest.generated_config()  # written by view_rviz before it started rviz
        current = cls.config["Visualization Manager"]["Views"]["Current"]
        cls.center, cls.scale = (current["X"], current["Y"]), current["Scale"]
        cls.full = viewtest.config_variant(cls.config, os.path.join(cls.tmp, "full.rviz"))
        cls.no_robot2 = viewtest.config_variant(cls.config, os.path.join(cls.tmp, "no_robot2.rviz"),
                                                **{"robot2 RobotModel": False})

    def test_1_displays_ok_and_fed(self):
        self.settled("every display Ok")
        topics = ("/robot1/odom", "/robot2/odom", "/world_markers", "/tf")
        subs = self.view.subscriptions("/rviz")
        for topic in topics:
            self.assertIn(topic, subs, f"rviz does not subscribe {topic}; it subscribes {subs}")
        self.view.wait(lambda: all(self.view.received("/rviz").get(t, 0) > 0 for t in topics), 20.0,
                       "rviz to receive messages on every robot's odometry")
        self.assertEqual(self.view.errors_from("/rviz"), [], "rviz logged warnings or errors")

    def test_2_robot_and_scan_where_they_are(self):
        """robot2's RobotModel display adds pixels at robot2's pose only."""
        self.view.load_config(self.full)
        both, view = self.settled("rviz settled with both robots")
        self.view.load_config(self.no_robot2)
        one, view2 = self.settled("rviz settled without robot2's model")
        self.assertEqual(view.box(), view2.box(), "the 3-D view moved between the two frames")
        count, centre, stray = self.robot_patch(both, one, view)
        self.assertGreater(count, 0.01 * self.scale ** 2, f"robot2's model changes only {count} pixels")
        self.assertLess(stray, 0.2 * count, f"{stray} changed pixels away from robot2's patch")
        want = self.expected_pixel(view, *ROBOT2)
        miss = math.hypot(centre[0] - want[0], centre[1] - want[1]) / self.scale
        self.assertLess(miss, 0.05, f"robot2 drawn at pixel {centre}, its pose says {want}: {miss:.3f} m off")
        robot1 = self.expected_pixel(view, 0.0, 0.0)
        self.assertGreater(math.hypot(centre[0] - robot1[0], centre[1] - robot1[1]) / self.scale, 0.5)
        self.view.alive()


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "view_multi", ViewMulti, sys.argv)
