#!/usr/bin/env python3
"""IMU, GPS and p3d through ROS on tests/data/robots/imu_robot.urdf (see its comment): at rest every IMU reads
+9.81 m/s^2 on z (REP 145) and no rate; in a turn at 0.5 rad/s the IMU sensor (frame yawed 90 deg) reads the
ground truth's yaw rate on z and its orientation follows the ground truth's yaw + 90 deg; the GPS moves east
while driving along +x, north along +y (referenceHeading 90: an ENU world) by the ground truth's distances;
p3d matches ~ground_truth. Callbacks only record; waits poll with deadlines; times are sim time.
"""
import math
import sys
import threading
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist, Vector3Stamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu, NavSatFix

from diffbot_sim.transforms import yaw_from_quaternion
from diffbot_sim.plugins.gps import radii

SIM = "/bullet_sim"
G = 9.81


def wrap(a):
    return math.atan2(math.sin(a), math.cos(a))


def yaw_of(q):
    return yaw_from_quaternion(q.x, q.y, q.z, q.w)


class Record:
    """Every message (with its arrival's sim time), thread-safe."""

    def __init__(self):
        self.lock = threading.Lock()
        self.msgs = []

    def __call__(self, msg):
        with self.lock:
            self.msgs.append(msg)

    def latest(self):
        with self.lock:
            return self.msgs[-1] if self.msgs else None

    def since(self, stamp):
        with self.lock:
            return [m for m in self.msgs if m.header.stamp.to_sec() >= stamp]


class SensorImuTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_sensor_imu")
        cls.topics = {"imu": Imu, "imu_model": Imu, "imu_hector": Imu, "fix": NavSatFix,
                      "fix_velocity": Vector3Stamped, "ground_truth/p3d": Odometry, SIM + "/ground_truth": Odometry}
        cls.rec = {name: Record() for name in cls.topics}
        cls.subs = [rospy.Subscriber(name, kind, cls.rec[name], queue_size=50) for name, kind in cls.topics.items()]
        cls.pub = rospy.Publisher("/cmd_vel", Twist, queue_size=1)

    def wait(self, predicate, timeout, what):
        deadline = time.monotonic() + timeout
        while not predicate():
            if time.monotonic() > deadline or rospy.is_shutdown():
                self.fail(f"timed out after {timeout} s waiting for {what}")
            time.sleep(0.005)

    def command(self, linear, angular, seconds):
        msg = Twist()
        msg.linear.x, msg.angular.z = linear, angular
        end = rospy.get_time() + seconds
        while rospy.get_time() < end:
            self.pub.publish(msg)
            rospy.sleep(0.05)

    def stop(self, seconds=1.5):
        self.command(0.0, 0.0, seconds)

    def truth(self):
        return self.rec[SIM + "/ground_truth"].latest()

    def enu(self, fix, origin):
        """(east, north) [m] of a fix from an origin fix (the reference latitude's WGS84 radii)."""
        r_north, r_east = radii(49.9)
        return (math.radians(fix.longitude - origin.longitude) * r_east,
                math.radians(fix.latitude - origin.latitude) * r_north)

    def check_rest(self, name, since):
        msgs = self.rec[name].since(since)
        self.assertGreater(len(msgs), 10, f"{name}: too few messages at rest")
        n = len(msgs)
        acc = [sum(getattr(m.linear_acceleration, a) for m in msgs) / n for a in "xyz"]
        rate = [max(abs(getattr(m.angular_velocity, a)) for m in msgs) for a in "xyz"]
        rospy.loginfo(f"FIGURE rest[{name}]: accel {acc[0]:+.4f} {acc[1]:+.4f} {acc[2]:+.4f} m/s^2, "
                      f"max |rate| {max(rate):.5f} rad/s over {n} messages")
        self.assertAlmostEqual(acc[2], G, delta=0.05, msg=f"{name}: z at rest (REP 145: +g)")
        self.assertLess(abs(acc[0]), 0.05, name)
        self.assertLess(abs(acc[1]), 0.05, name)
        self.assertLess(max(rate), 0.01, name)
        return msgs

    def test_imu_gps_p3d(self):
        for name in self.topics:
            self.wait(lambda n=name: self.rec[n].latest() is not None, 60.0, name)
        self.wait(lambda: self.pub.get_num_connections() > 0, 30.0, "a subscriber on /cmd_vel")
        self.stop(1.0)  # settle after the drop onto the ground
        t0 = rospy.get_time()
        self.stop(1.0)
        msgs = self.check_rest("imu", t0)
        rate = (len(msgs) - 1) / (msgs[-1].header.stamp - msgs[0].header.stamp).to_sec()
        rospy.loginfo(f"FIGURE imu rate: {rate:.1f} Hz")
        self.assertAlmostEqual(rate, 100.0, delta=3.0)
        self.assertEqual(msgs[-1].header.frame_id, "imu_link")
        self.assertEqual(list(msgs[-1].linear_acceleration_covariance), [0.0] * 9)
        self.check_rest("imu_model", t0)  # corrected: the original reads no gravity
        self.check_rest("imu_hector", t0)
        truth = self.truth()
        imu_yaw = yaw_of(self.rec["imu"].latest().orientation)
        self.assertLess(abs(wrap(imu_yaw - yaw_of(truth.pose.pose.orientation) - math.pi / 2)), 0.02)

        # p3d ~ ground truth (both in world, at rest)
        p3d = self.rec["ground_truth/p3d"].latest()
        a, b = p3d.pose.pose.position, truth.pose.pose.position
        self.assertLess(math.hypot(a.x - b.x, a.y - b.y), 0.005)
        self.assertEqual((p3d.header.frame_id, p3d.child_frame_id), ("world", "base_link"))

        # drive along +x: the GPS moves east
        fix0, truth0 = self.rec["fix"].latest(), self.truth()
        t1 = rospy.get_time()
        self.command(0.2, 0.0, 3.0)
        velocities = self.rec["fix_velocity"].since(t1 + 1.0)
        self.stop()
        fix1, truth1 = self.rec["fix"].latest(), self.truth()
        east, north = self.enu(fix1, fix0)
        p, q = truth0.pose.pose.position, truth1.pose.pose.position
        rospy.loginfo(f"FIGURE gps +x: east {east:.3f} m, north {north:.3f} m; truth dx {q.x - p.x:.3f}, "
                      f"dy {q.y - p.y:.3f} m")
        self.assertGreater(east, 0.4)
        self.assertAlmostEqual(east, q.x - p.x, delta=0.01)
        self.assertAlmostEqual(north, q.y - p.y, delta=0.01)
        v = velocities[len(velocities) // 2].vector  # hector: (north, west, up)
        self.assertAlmostEqual(v.y, -0.2, delta=0.03)
        self.assertLess(abs(v.x), 0.03)
        p3d = self.rec["ground_truth/p3d"].latest()
        a, b = p3d.pose.pose.position, truth1.pose.pose.position
        self.assertLess(math.hypot(a.x - b.x, a.y - b.y), 0.005)
        self.assertLess(abs(wrap(yaw_of(p3d.pose.pose.orientation) - yaw_of(truth1.pose.pose.orientation))), 0.005)

        # turn in place at 0.5 rad/s for ~90 deg: the IMU reads the yaw rate on its z
        t2 = rospy.get_time()
        self.command(0.0, 0.5, math.pi)
        t3 = rospy.get_time()
        imu = self.rec["imu"].since(t2 + 1.0)
        truths = self.rec[SIM + "/ground_truth"].since(t2 + 1.0)
        self.stop()
        imu = [m for m in imu if m.header.stamp.to_sec() < t3 - 0.2]
        truths = [m for m in truths if m.header.stamp.to_sec() < t3 - 0.2]
        wz = sum(m.angular_velocity.z for m in imu) / len(imu)
        tz = sum(m.twist.twist.angular.z for m in truths) / len(truths)
        wxy = max(max(abs(m.angular_velocity.x), abs(m.angular_velocity.y)) for m in imu)
        rospy.loginfo(f"FIGURE turn: imu z {wz:.4f} rad/s, truth {tz:.4f} rad/s (command 0.5), max |x|,|y| {wxy:.4f}")
        self.assertAlmostEqual(wz, tz, delta=0.01)
        self.assertAlmostEqual(wz, 0.5, delta=0.1)
        self.assertLess(wxy, 0.05)
        truth2 = self.truth()
        imu_yaw = yaw_of(self.rec["imu"].latest().orientation)
        truth_yaw = yaw_of(truth2.pose.pose.orientation)
        rospy.loginfo(f"FIGURE turn: imu yaw {imu_yaw:.4f}, truth yaw + 90 deg {wrap(truth_yaw + math.pi / 2):.4f}")
        self.assertLess(abs(wrap(imu_yaw - truth_yaw - math.pi / 2)), 0.02)
        self.assertGreater(truth_yaw, 1.0)

        # drive forward again (now roughly along +y): the GPS moves north
        fix2 = self.rec["fix"].latest()
        self.command(0.2, 0.0, 3.0)
        self.stop()
        fix3, truth3 = self.rec["fix"].latest(), self.truth()
        east, north = self.enu(fix3, fix2)
        p, q = truth2.pose.pose.position, truth3.pose.pose.position
        rospy.loginfo(f"FIGURE gps +y: east {east:.3f} m, north {north:.3f} m; truth dx {q.x - p.x:.3f}, "
                      f"dy {q.y - p.y:.3f} m")
        self.assertGreater(north, 0.3)
        self.assertAlmostEqual(east, q.x - p.x, delta=0.01)
        self.assertAlmostEqual(north, q.y - p.y, delta=0.01)
        self.assertAlmostEqual(fix3.altitude, q.z + 0.033, delta=0.01)  # base_link is 0.033 m above base_footprint


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_sensor_imu", SensorImuTest, sys.argv)
