#!/usr/bin/env python3
"""Two robots in one simulator: namespaced topics, prefixed frames, independent motion."""
import math
import sys
import unittest

import rosgraph
import rospy
import rostest
import tf2_ros
from geometry_msgs.msg import Twist
from simtest import Recorder, Truth, finite_odom, yaw_of

SIM = "/bullet_sim"


class MultiRobotTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_multi")
        cls.rec = Recorder(odom="/robot1/odom", joint_states="/robot1/joint_states", extra_odom="/robot2/odom")
        cls.truth = {name: Truth(f"{SIM}/{name}/ground_truth") for name in ("robot1", "robot2")}
        cls.cmd = {name: rospy.Publisher(f"/{name}/cmd_vel", Twist, queue_size=10) for name in ("robot1", "robot2")}
        cls.rec.wait(lambda: all(p.get_num_connections() > 0 for p in cls.cls_pubs()), 20.0,
                     "the simulator to subscribe both cmd_vel topics")
        cls.rec.wait(lambda: cls.rec.last(cls.rec.odom) and cls.rec.last(cls.rec.extra), 20.0,
                     "odom from both robots")
        cls.tf_buffer = tf2_ros.Buffer()
        cls.tf_listener = tf2_ros.TransformListener(cls.tf_buffer)

    @classmethod
    def cls_pubs(cls):
        return list(cls.cmd.values())

    def send(self, name, linear, angular):
        msg = Twist()
        msg.linear.x, msg.angular.z = linear, angular
        self.cmd[name].publish(msg)

    def test_1_spawned_where_asked_with_prefixed_frames(self):
        one, two = self.rec.last(self.rec.odom), self.rec.last(self.rec.extra)
        self.assertEqual((one.header.frame_id, one.child_frame_id), ("robot1/odom", "robot1/base_footprint"))
        self.assertEqual((two.header.frame_id, two.child_frame_id), ("robot2/odom", "robot2/base_footprint"))
        self.assertAlmostEqual(one.pose.pose.position.y, 0.0, delta=0.01)
        self.assertAlmostEqual(two.pose.pose.position.y, 1.0, delta=0.01)
        joints = self.rec.wait(lambda: self.rec.last(self.rec.joints), 10.0, "/robot1/joint_states")
        self.assertIn("left_wheel_joint", joints.name)
        self.assertAlmostEqual(rospy.get_param(SIM + "/robot1/loaded_mass"), rospy.get_param(SIM + "/robot1/urdf_mass"),
                               delta=1e-3)
        self.assertEqual(rospy.get_param(SIM + "/robot2/y"), 1.0)

    def test_1_nothing_listens_on_the_unprefixed_topics(self):
        _, subscribers, _ = rosgraph.Master("/test_multi").getSystemState()
        topics = {topic for topic, _ in subscribers}
        self.assertNotIn("/cmd_vel", topics)
        self.assertIn("/robot1/cmd_vel", topics)
        self.assertIn("/robot2/cmd_vel", topics)

    def test_1_the_simulator_does_not_follow_its_own_clock(self):
        """It owns sim time; under use_sim_time rospy would subscribe it to the /clock it publishes."""
        self.assertTrue(rospy.get_param("/use_sim_time"))
        _, subscribers, _ = rosgraph.Master("/test_multi").getSystemState()
        clock_subscribers = dict(subscribers).get("/clock", [])
        self.assertIn("/robot1/robot_state_publisher", clock_subscribers)  # the check can see a subscriber
        self.assertNotIn(SIM, clock_subscribers)

    def test_2_each_robot_follows_its_own_commands(self):
        rec = self.rec
        self.send("robot1", 0.4, 0.0)
        self.send("robot2", 0.0, 1.0)
        # Measured from when both bodies answer their commands, not from the newest odom seen before sending:
        # in fast mode a loaded machine delivers a command sim seconds after that (this node's odom queues up
        # behind a starved thread), and 3 s "from then" would partly be time before the command.
        def both():
            one, two = self.responding(rec.odom, 0.4, 0.0), self.responding(rec.extra, 0.0, 1.0)
            return (one, two) if one and two else None
        a0, b0 = rec.wait(both, 30.0, "robot1 to drive at 0.4 m/s and robot2 to turn at 1 rad/s (/robot1/odom, "
                          "/robot2/odom)")
        start = max(a0.header.stamp.to_sec(), b0.header.stamp.to_sec())
        a0, b0 = rec.odom_after(start), rec.odom_after(start, store=rec.extra)
        a1 = rec.odom_after(start + 3.0)
        b1 = rec.odom_after(start + 3.0, store=rec.extra)
        self.send("robot1", 0.0, 0.0)
        self.send("robot2", 0.0, 0.0)
        # robot1 drove straight ahead, robot2 turned in place at its own spawn point.
        self.assertGreater(a1.pose.pose.position.x - a0.pose.pose.position.x, 0.6)
        self.assertLess(abs(yaw_of(a1.pose.pose.orientation) - yaw_of(a0.pose.pose.orientation)), 0.05)
        self.assertGreater(abs(yaw_of(b1.pose.pose.orientation) - yaw_of(b0.pose.pose.orientation)), 0.5)
        self.assertLess(math.hypot(b1.pose.pose.position.x - b0.pose.pose.position.x,
                                   b1.pose.pose.position.y - b0.pose.pose.position.y), 0.05)
        self.assertTrue(all(finite_odom(m) for m in rec.snapshot(rec.odom) + rec.snapshot(rec.extra)))
        # The bodies (ground truth), not only their odometry: upright on the ground, each doing as told.
        end = a1.header.stamp.to_sec()
        rec.wait(lambda: all(t.between(end, end + 1.0) for t in self.truth.values()), 30.0, "both ground truths")
        one = self.truth["robot1"].ride(start, end)
        two = self.truth["robot2"].ride(start, end, what="turning")
        self.assertGreater(one[-1].x - one[0].x, 0.6, "robot1's body drove ahead")
        self.assertLess(abs(one[-1].yaw - one[0].yaw), 0.05)
        self.assertGreater(abs(math.atan2(math.sin(two[-1].yaw - two[0].yaw), math.cos(two[-1].yaw - two[0].yaw))),
                           0.5, "robot2's body turned")
        self.assertLess(math.hypot(two[-1].x - two[0].x, two[-1].y - two[0].y), 0.05, "in place")

    def responding(self, store, linear, angular):
        """The first odom of ``store`` showing the robot moving as (linear, angular) says (a fifth of each), or
        None."""
        for msg in self.rec.snapshot(store):
            twist = msg.twist.twist
            if ((linear == 0 or twist.linear.x * linear > 0.2 * linear * linear) and
                    (angular == 0 or twist.angular.z * angular > 0.2 * angular * angular)):
                return msg
        return None

    def test_3_tf_tree_per_robot(self):
        """bullet_sim's odom -> base_footprint joins robot_state_publisher's tf_prefix'ed links."""
        for name in ("robot1", "robot2"):
            tf = self.rec.wait(lambda: self._lookup(f"{name}/odom", f"{name}/base_link"), 20.0,
                               f"TF {name}/odom -> {name}/base_link")
            self.assertTrue(math.isfinite(tf.transform.translation.x))

    def _lookup(self, parent, child):
        try:
            return self.tf_buffer.lookup_transform(parent, child, rospy.Time(0))
        except (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException):
            return None


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "multi", MultiRobotTest, sys.argv)
