#!/usr/bin/env python3
"""A fixture robot loaded unchanged drives as in Gazebo: straight at 0.2 m/s for 4 s (0.8 m, heading kept)
and in place at 0.5 rad/s for 4 s, judged on its own odometry topic and on the physics ground truth.

Private parameters: ~cmd_topic, ~odom_topic (the robot's own), ~urdf_mass (kg, the URDF's sum, computed by
hand in the fixture's comment), ~skid (bool, default false): a four-wheel robot driven as a diff drive
turns its body slower than its wheels say (its wheels slide sideways; real YAMLs carry a
wheel_separation_multiplier for it), so in the turn its ground truth need only turn the right way by a
quarter of the command and stay within 0.2 m, while its own odometry must still read the commanded turn;
~odom_is_truth (bool, default false): the drive's odometry is the world pose (gazebo_ros_skid_steer_drive),
so in the turn it is held to the ground truth's bounds; ~holonomic (bool, default false): also 0.2 m/s
sideways (linear.y) for 4 s: 0.8 m to the robot's left, heading kept; ~imu_topic (optional): the base IMU
a drive plugin publishes reads +9.81 m/s^2 on z and no yaw rate at rest (REP 145). Callbacks only record; waits poll with deadlines; times are sim time.
The straight run and the turn are measured and judged by diffbot_sim.drive_check, shared with `robot_check`.
"""
import math
import sys
import threading
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu

from diffbot_sim import drive_check
from diffbot_sim.drive_check import SECONDS, SPEED, TURN, wrap

SIM = "/bullet_sim"


def yaw_of(msg):
    q = msg.pose.pose.orientation
    return drive_check.yaw_from_quaternion(q.x, q.y, q.z, q.w)


def pose_of(msg):
    """``(x, y, yaw)`` of an Odometry message, as drive_check takes poses."""
    p = msg.pose.pose.position
    return p.x, p.y, yaw_of(msg)


class Latest:
    def __init__(self):
        self.lock = threading.Lock()
        self.msg = None
        self.count = 0

    def __call__(self, msg):
        with self.lock:
            self.msg, self.count = msg, self.count + 1

    def get(self):
        with self.lock:
            return self.msg


class RealRobotTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_real_robot")
        cls.cmd_topic = rospy.get_param("~cmd_topic")
        cls.odom = Latest()
        cls.truth = Latest()
        cls.subs = [rospy.Subscriber(rospy.get_param("~odom_topic"), Odometry, cls.odom, queue_size=1),
                    rospy.Subscriber(SIM + "/ground_truth", Odometry, cls.truth, queue_size=1)]
        cls.pub = rospy.Publisher(cls.cmd_topic, Twist, queue_size=1)
        cls.imu = Latest()
        if rospy.has_param("~imu_topic"):
            cls.subs.append(rospy.Subscriber(rospy.get_param("~imu_topic"), Imu, cls.imu, queue_size=1))

    def wait(self, predicate, timeout, what):
        deadline = time.monotonic() + timeout
        while not predicate():
            if time.monotonic() > deadline or rospy.is_shutdown():
                self.fail(f"timed out after {timeout} s waiting for {what}")
            time.sleep(0.005)

    def drive(self, linear, angular, seconds, lateral=0.0):
        """Command (linear, angular) at 20 Hz of sim time for ``seconds``; returns (odom, truth) at start and end."""
        start = (self.odom.get(), self.truth.get())
        end_time = rospy.get_time() + seconds
        msg = Twist()
        msg.linear.x, msg.linear.y, msg.angular.z = linear, lateral, angular
        while rospy.get_time() < end_time:
            self.pub.publish(msg)
            rospy.sleep(0.05)
        end = (self.odom.get(), self.truth.get())
        self.pub.publish(Twist())
        return start, end

    def stop(self, seconds=1.5):
        end_time = rospy.get_time() + seconds
        while rospy.get_time() < end_time:
            self.pub.publish(Twist())
            rospy.sleep(0.05)

    def test_drives_straight_and_turns_in_place(self):
        self.wait(lambda: self.odom.get() is not None and self.truth.get() is not None, 60.0,
                  "the robot's odometry and the ground truth")
        self.wait(lambda: self.pub.get_num_connections() > 0, 30.0, f"a subscriber on {self.cmd_topic}")
        urdf_mass = rospy.get_param("~urdf_mass")
        self.assertAlmostEqual(rospy.get_param(SIM + "/urdf_mass"), urdf_mass, delta=1e-6)
        self.assertAlmostEqual(rospy.get_param(SIM + "/loaded_mass"), urdf_mass, delta=1e-3,
                               msg="loaded mass differs from the URDF's")
        self.stop(1.0)  # settle after the drop onto the ground
        if rospy.has_param("~imu_topic"):
            self.wait(lambda: self.imu.count >= 3, 30.0, "the IMU")
            self.stop(0.5)
            imu = self.imu.get()
            a, w = imu.linear_acceleration, imu.angular_velocity
            rospy.loginfo(f"FIGURE imu at rest: accel ({a.x:.3f}, {a.y:.3f}, {a.z:.3f}), yaw rate {w.z:.4f}")
            self.assertAlmostEqual(a.z, 9.81, delta=0.1, msg="an IMU at rest reads +g on z (REP 145)")
            self.assertLess(abs(a.x) + abs(a.y), 0.1)
            self.assertLess(abs(w.z), 0.01)

        (o0, t0), (o1, t1) = self.drive(SPEED, 0.0, SECONDS)
        self.stop()
        straight = drive_check.straight(pose_of(o0), pose_of(o1), pose_of(t0), pose_of(t1))
        for name, distance, heading in (("odometry", straight.odom_distance, straight.odom_heading),
                                        ("ground truth", straight.truth_distance, straight.truth_heading)):
            rospy.loginfo(f"FIGURE straight[{name}]: {distance:.3f} m, heading change {heading:.3f} rad")
        self.assertTrue(straight.passed, "; ".join(straight.failures))

        if rospy.get_param("~holonomic", False):
            (o0, t0), (o1, t1) = self.drive(0.0, 0.0, SECONDS, lateral=SPEED)
            self.stop()
            for name, a, b in (("odometry", o0, o1), ("ground truth", t0, t1)):
                p0, p1, yaw = a.pose.pose.position, b.pose.pose.position, yaw_of(a)
                dx, dy = p1.x - p0.x, p1.y - p0.y
                left = -math.sin(yaw) * dx + math.cos(yaw) * dy  # along the robot's +y (REP 103: left)
                rospy.loginfo(f"FIGURE sideways[{name}]: {left:.3f} m to the left")
                self.assertGreater(left, 0.85 * SPEED * SECONDS, f"{name}: moved {left:.3f} m left")
                self.assertLess(left, 1.15 * SPEED * SECONDS, f"{name}: moved {left:.3f} m left")
                self.assertLess(abs(wrap(yaw_of(b) - yaw)), 0.1, f"{name}: heading changed")

        (o0, t0), (o1, t1) = self.drive(0.0, TURN, SECONDS)
        self.stop()
        skid = rospy.get_param("~skid", False)
        low = 0.25 if skid and rospy.get_param("~odom_is_truth", False) else 1.0 - drive_check.TURN_TOLERANCE
        turn = drive_check.turn(pose_of(o0), pose_of(o1), pose_of(t0), pose_of(t1), odom_fraction=low,
                                truth_fraction=0.25 if skid else 0.5, max_moved=0.2 if skid else 0.1)
        rospy.loginfo(f"FIGURE turn: odometry {turn.odom_yaw:.3f} rad, truth {turn.truth_yaw:.3f} rad, "
                      f"moved {turn.moved:.3f} m")
        self.assertTrue(turn.passed, "; ".join(turn.failures))


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_real_robot", RealRobotTest, sys.argv)
