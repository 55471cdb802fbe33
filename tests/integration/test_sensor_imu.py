#!/usr/bin/env python3
"""IMU, GPS and p3d through ROS on tests/data/robots/imu_robot.urdf (see its comment): at rest every IMU reads
+9.81 m/s^2 on z (REP 145) and no rate; in a turn at 0.5 rad/s the IMU sensor (frame yawed 90 deg) reads the
ground truth's yaw rate on z and its orientation follows the ground truth's yaw + 90 deg; the GPS moves east
while driving along +x, north along +y (referenceHeading 90: an ENU world) by the ground truth's distances;
p3d matches ~ground_truth. Callbacks only record; waits poll with deadlines; times are sim time. Each motion is
commanded until the body (ground truth) has done it, and each "at rest" is the body still, not a time waited.
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
from simtest import wait_for

from diffbot_sim.check.stillness import pose_still
from diffbot_sim.plugins.gps import radii
from diffbot_sim.transforms import yaw_from_quaternion

SIM = "/bullet_sim"
G = 9.81
MOTION_TIMEOUT = 60.0  # s wall: a motion of a few sim seconds (at 3x real time), on a 4x slower machine
REST_BAND, REST_WINDOW = 0.001, 0.3  # m and rad, s of sim time: the body held within this band this long is at rest
DRIVE = 0.6  # m of each straight drive (0.2 m/s for 3 s)
TURN = math.pi / 2  # rad of the turn in place (0.5 rad/s for pi s)


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
        return wait_for(predicate, timeout, what, 0.005)

    def command(self, linear, angular, seconds):
        """Publish (linear, angular) at 20 Hz for ``seconds`` of sim time (a window to collect samples in)."""
        msg = Twist()
        msg.linear.x, msg.angular.z = linear, angular
        end = rospy.get_time() + seconds
        while rospy.get_time() < end:
            self.pub.publish(msg)
            rospy.sleep(0.05)

    def stop(self, seconds=1.5):
        self.command(0.0, 0.0, seconds)

    def command_until(self, linear, angular, done, what):
        """Publish (linear, angular) at 20 Hz (wall) until ``done()`` gives something true (returned): a motion
        is judged by what the body did (ground truth), not by how long it was told to, since on a loaded
        machine a command reaches the simulator late and a fixed time moves the body less."""
        msg = Twist()
        msg.linear.x, msg.angular.z = linear, angular
        deadline = time.monotonic() + MOTION_TIMEOUT
        while not rospy.is_shutdown() and time.monotonic() < deadline:
            self.pub.publish(msg)
            value = done()
            if value:
                return value
            time.sleep(0.05)
        self.fail(f"timed out after {MOTION_TIMEOUT} s waiting for {what}")

    def still(self):
        """The newest ground truth once the body has held still over the last REST_WINDOW s of its stamps (its
        position within REST_BAND m and its orientation within REST_BAND rad: stillness.pose_still), else None.
        One message with a low twist is an instant, which a body bouncing or rocking to rest also passes."""
        with self.rec[SIM + "/ground_truth"].lock:
            truth = self.rec[SIM + "/ground_truth"].msgs[-200:]
        return pose_still(truth, REST_BAND, REST_WINDOW)

    def at_rest(self, what):
        """Stop, and wait until the body is still (ground truth) and a GPS fix taken since has come: returns
        (that still ground truth, the fix) — both of the body at rest, wherever this node's queues are."""
        rest = self.command_until(0.0, 0.0, self.still, f"the body at rest {what} (ground truth)")
        t = rest.header.stamp.to_sec()
        self.wait(lambda: self.rec["fix"].since(t), MOTION_TIMEOUT, f"a GPS fix after the body came to rest {what}")
        return rest, self.rec["fix"].since(t)[0]

    def first_at(self, name, since, reached, what):
        """The stamp of the first ``name`` message from ``since`` on for which ``reached(msg)`` holds."""
        stamp = next((m.header.stamp.to_sec() for m in self.rec[name].since(since) if reached(m)), None)
        self.assertIsNotNone(stamp, f"{name}: {what} never seen after sim time {since:.2f}")
        return stamp

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
        rest, _ = self.at_rest("after the drop onto the ground")
        t0 = rest.header.stamp.to_sec()
        self.stop(1.0)  # a sim second of samples at rest
        msgs = self.check_rest("imu", t0)
        # The sensor's rate: messages published (header.seq counts them) per sim second, so that one lost on
        # the way here (this node's queue of 50 on a loaded machine) does not count against the sensor.
        rate = (msgs[-1].header.seq - msgs[0].header.seq) / (msgs[-1].header.stamp - msgs[0].header.stamp).to_sec()
        rospy.loginfo(f"FIGURE imu rate: {rate:.1f} Hz ({len(msgs)} of {msgs[-1].header.seq - msgs[0].header.seq + 1} "
                      "received)")
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
        truth0, fix0 = self.at_rest("before driving along +x")
        p = truth0.pose.pose.position
        end = self.command_until(0.2, 0.0, lambda: (t := self.truth()) and math.hypot(
            t.pose.pose.position.x - p.x, t.pose.pose.position.y - p.y) >= DRIVE and t,
            f"the body to drive {DRIVE} m (ground truth)")
        cruising = self.first_at(SIM + "/ground_truth", truth0.header.stamp.to_sec(),
                                 lambda m: m.twist.twist.linear.x > 0.18, "the body at 0.18 m/s")
        velocities = [m for m in self.rec["fix_velocity"].since(cruising) if m.header.stamp <= end.header.stamp]
        truth1, fix1 = self.at_rest("after driving along +x")
        east, north = self.enu(fix1, fix0)
        q = truth1.pose.pose.position
        rospy.loginfo(f"FIGURE gps +x: east {east:.3f} m, north {north:.3f} m; truth dx {q.x - p.x:.3f}, "
                      f"dy {q.y - p.y:.3f} m")
        self.assertGreater(east, 0.4)
        self.assertAlmostEqual(east, q.x - p.x, delta=0.01)
        self.assertAlmostEqual(north, q.y - p.y, delta=0.01)
        self.assertTrue(velocities, "no fix_velocity while the body drove at speed")
        v = velocities[len(velocities) // 2].vector  # hector: (north, west, up)
        self.assertAlmostEqual(v.y, -0.2, delta=0.03)
        self.assertLess(abs(v.x), 0.03)
        self.wait(lambda: self.rec["ground_truth/p3d"].since(truth1.header.stamp.to_sec()), MOTION_TIMEOUT,
                  "p3d after the body came to rest")
        p3d = self.rec["ground_truth/p3d"].since(truth1.header.stamp.to_sec())[0]
        a, b = p3d.pose.pose.position, truth1.pose.pose.position
        self.assertLess(math.hypot(a.x - b.x, a.y - b.y), 0.005)
        self.assertLess(abs(wrap(yaw_of(p3d.pose.pose.orientation) - yaw_of(truth1.pose.pose.orientation))), 0.005)

        # turn in place at 0.5 rad/s for ~90 deg: the IMU reads the yaw rate on its z
        yaw1 = yaw_of(truth1.pose.pose.orientation)
        end = self.command_until(0.0, 0.5, lambda: (t := self.truth()) and wrap(
            yaw_of(t.pose.pose.orientation) - yaw1) >= TURN and t, f"the body to turn {TURN:.2f} rad (ground truth)")
        # The steady part of the turn: from the body turning at 0.45 rad/s (plus a fifth of a second) to the end.
        turning = self.first_at(SIM + "/ground_truth", truth1.header.stamp.to_sec(),
                                lambda m: m.twist.twist.angular.z > 0.45, "the body turning at 0.45 rad/s") + 0.2
        t3 = end.header.stamp.to_sec()
        imu = [m for m in self.rec["imu"].since(turning) if m.header.stamp.to_sec() < t3 - 0.2]
        truths = [m for m in self.rec[SIM + "/ground_truth"].since(turning) if m.header.stamp.to_sec() < t3 - 0.2]
        self.assertTrue(imu and truths, f"no IMU or ground truth in the steady turn ({turning:.2f}..{t3 - 0.2:.2f})")
        wz = sum(m.angular_velocity.z for m in imu) / len(imu)
        tz = sum(m.twist.twist.angular.z for m in truths) / len(truths)
        wxy = max(max(abs(m.angular_velocity.x), abs(m.angular_velocity.y)) for m in imu)
        rospy.loginfo(f"FIGURE turn: imu z {wz:.4f} rad/s, truth {tz:.4f} rad/s (command 0.5), max |x|,|y| {wxy:.4f}")
        self.assertAlmostEqual(wz, tz, delta=0.01)
        self.assertAlmostEqual(wz, 0.5, delta=0.1)
        self.assertLess(wxy, 0.05)
        truth2, fix2 = self.at_rest("after the turn")
        self.wait(lambda: self.rec["imu"].since(truth2.header.stamp.to_sec()), MOTION_TIMEOUT,
                  "an IMU message after the body came to rest")
        imu_yaw = yaw_of(self.rec["imu"].since(truth2.header.stamp.to_sec())[0].orientation)
        truth_yaw = yaw_of(truth2.pose.pose.orientation)
        rospy.loginfo(f"FIGURE turn: imu yaw {imu_yaw:.4f}, truth yaw + 90 deg {wrap(truth_yaw + math.pi / 2):.4f}")
        self.assertLess(abs(wrap(imu_yaw - truth_yaw - math.pi / 2)), 0.02)
        self.assertGreater(truth_yaw, 1.0)

        # drive forward again (now roughly along +y): the GPS moves north
        p = truth2.pose.pose.position
        self.command_until(0.2, 0.0, lambda: (t := self.truth()) and math.hypot(
            t.pose.pose.position.x - p.x, t.pose.pose.position.y - p.y) >= DRIVE and t,
            f"the body to drive {DRIVE} m again (ground truth)")
        truth3, fix3 = self.at_rest("after driving along +y")
        east, north = self.enu(fix3, fix2)
        q = truth3.pose.pose.position
        rospy.loginfo(f"FIGURE gps +y: east {east:.3f} m, north {north:.3f} m; truth dx {q.x - p.x:.3f}, "
                      f"dy {q.y - p.y:.3f} m")
        self.assertGreater(north, 0.3)
        self.assertAlmostEqual(east, q.x - p.x, delta=0.01)
        self.assertAlmostEqual(north, q.y - p.y, delta=0.01)
        self.assertAlmostEqual(fix3.altitude, q.z + 0.033, delta=0.01)  # base_link is 0.033 m above base_footprint


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_sensor_imu", SensorImuTest, sys.argv)
