#!/usr/bin/env python3
"""A fixture robot loaded unchanged drives as in Gazebo, judged by its body (the physics ground truth): spawned
(paused, at ~spawn_z) it gains no height and lands and settles within 1 s of sim time, upright at the height its
geometry rests at (~rest_height, computed by hand in the fixture's comment); then straight at 0.2 m/s for 4 s
(0.8 m, heading kept) and in place at 0.5 rad/s for 4 s, staying at that height and upright while it drives.
Its own odometry topic is a second, separate claim, judged against the command too.

Private parameters: ~cmd_topic, ~odom_topic (the robot's own), ~urdf_mass (kg, the URDF's sum), ~rest_height (m,
the root link's height when standing on flat ground; default 0), ~spawn_z (m, where the launch file puts it;
default 0), ~skid (bool, default false): a four-wheel robot driven as a diff drive turns its body slower than its
wheels say (its wheels slide sideways; real YAMLs carry a wheel_separation_multiplier for it), so in the turn
its ground truth need only turn the right way by a quarter of the command, while its own odometry must still
read the commanded turn; ~wheel_centre ([x, y] in the root link's frame, m; default the origin): the middle of
the drive wheels, which is what turns in place; ~footprint ([half length, half width] of a skid-steered wheel
set, m): its body may turn about any point inside it (drive_check.skid_turn_drift), else its origin must stay
within 0.1 m; ~odom_is_truth (bool, default false): the drive's odometry is the world pose
(gazebo_ros_skid_steer_drive), so in the turn it is held to the ground truth's bounds; ~holonomic (bool, default
false): also 0.2 m/s sideways (linear.y) for 4 s: 0.8 m to the robot's left, heading kept;
~imu_topic (optional): the base IMU a drive plugin publishes reads +9.81 m/s^2 on z and no yaw rate at rest
(REP 145). The launch file starts bullet_sim paused; this node unpauses it once it listens.
Callbacks only record; waits poll with deadlines; times are sim time. The motions and the body are judged by
diffbot_sim.check.drive_check, shared with `robot_check`.
"""
import sys
import threading
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu
from simtest import sim_now, wait_for
from std_srvs.srv import Empty

from diffbot_sim.check import drive_check
from diffbot_sim.check.drive_check import SECONDS, SPEED, TURN, wrap

SIM = "/bullet_sim"
RAMP = 1.0  # s of sim time a command is on before its measured run starts (acceleration limits, late commands)


def yaw_of(msg):
    q = msg.pose.pose.orientation
    return drive_check.yaw_from_quaternion(q.x, q.y, q.z, q.w)


def pose_of(msg):
    """``(x, y, yaw)`` of an Odometry message, as drive_check takes poses."""
    p = msg.pose.pose.position
    return p.x, p.y, yaw_of(msg)


class Latest:
    """The newest message, how many came, and (``keep``) every message as a drive_check.BodySample."""

    def __init__(self, keep=False):
        self.lock = threading.Lock()
        self.msg = None
        self.count = 0
        self.samples = [] if keep else None
        self.msgs = [] if keep else None

    def __call__(self, msg):
        with self.lock:
            self.msg, self.count = msg, self.count + 1
            if self.samples is not None:
                self.msgs.append(msg)
                p, q = msg.pose.pose.position, msg.pose.pose.orientation
                self.samples.append(drive_check.body_sample(msg.header.stamp.to_sec(), (p.x, p.y, p.z),
                                                            (q.x, q.y, q.z, q.w)))

    def get(self):
        with self.lock:
            return self.msg

    def first_after(self, stamp):
        """The first message kept that is stamped at or after ``stamp`` (sim time), else None."""
        with self.lock:
            return next((m for m in self.msgs if m.header.stamp.to_sec() >= stamp), None)

    def between(self, start, end):
        """The body samples stamped in [start, end] (sim time)."""
        with self.lock:
            return [s for s in self.samples if start <= s.t <= end]


class RealRobotTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_real_robot")
        cls.cmd_topic = rospy.get_param("~cmd_topic")
        cls.odom = Latest(keep=True)
        cls.truth = Latest(keep=True)
        # every message kept, however late this node reads them: a run's ends are found by their stamps
        cls.truth_sub = rospy.Subscriber(SIM + "/ground_truth", Odometry, cls.truth, queue_size=1000)
        cls.subs = [rospy.Subscriber(rospy.get_param("~odom_topic"), Odometry, cls.odom, queue_size=1000),
                    cls.truth_sub]
        cls.pub = rospy.Publisher(cls.cmd_topic, Twist, queue_size=1)
        cls.imu = Latest()
        if rospy.has_param("~imu_topic"):
            cls.subs.append(rospy.Subscriber(rospy.get_param("~imu_topic"), Imu, cls.imu, queue_size=1))

    def wait(self, predicate, timeout, what, poll=0.005):
        return wait_for(predicate, timeout, what, poll)

    def drive(self, linear, angular, seconds, lateral=0.0):
        """Command (linear, angular) at 20 Hz of sim time; returns (odom, truth) at the start and the end of a
        run of ``seconds`` of sim time, and the body samples in between. The run starts once the command has been
        on for RAMP s of sim time (faster than real time, a busy machine delays this node's first command by wall
        time, which would cost the run sim seconds the robot never had its command for), and its two ends are
        the first messages stamped at or after them: the newest message this node holds at a moment of its
        clock can be half a second of sim time old on a busy machine, and more at one end than the other."""
        msg = Twist()
        msg.linear.x, msg.linear.y, msg.angular.z = linear, lateral, angular
        begin = sim_now() + RAMP
        end_at = begin + seconds

        def run_done():
            self.pub.publish(msg)
            return self.odom.first_after(end_at) is not None and self.truth.first_after(end_at) is not None
        self.wait(run_done, 60.0 + 10.0 * (RAMP + seconds), f"a run of {seconds} s of sim time from {begin:.3f}",
                  poll=0.01)  # wall: a command at least every 0.03 s of sim time at 3x real time
        start = (self.odom.first_after(begin), self.truth.first_after(begin))
        end = (self.odom.first_after(end_at), self.truth.first_after(end_at))
        self.pub.publish(Twist())
        return start, end, self.truth.between(start[1].header.stamp.to_sec(), end[1].header.stamp.to_sec())

    def assert_legal_parameter_names(self):
        """Every parameter bullet_sim writes (its start-up summary) is a legal ROS name: a plugin's summary
        key once carried a space ('~imu /imu'), which rospy warns about and rosparam cannot address."""
        import rosgraph.names

        names = [n for n in rosgraph.Master("/test_real_robot").getParamNames() if n.startswith(SIM + "/")]
        self.assertGreater(len(names), 5)
        self.assertEqual([n for n in names if not rosgraph.names.is_legal_name(n)], [])

    def assert_ride(self, body, height, what):
        ride = drive_check.ride(body, height, what)
        rospy.loginfo(f"FIGURE body while {what}: height {ride.low:.4f}..{ride.high:.4f} m, tilt {ride.tilt:.4f} rad")
        self.assertTrue(ride.passed, "; ".join(ride.failures))

    def spawn_and_settle(self):
        """Unpause the world the launch file started paused; the body must gain no height and be at rest,
        upright at its geometry's height, from 1 s of sim time on (Gazebo lands a robot placed in the air)."""
        self.wait(lambda: self.truth_sub.get_num_connections() > 0, 30.0, "the ground truth publisher")
        rospy.wait_for_service(SIM + "/unpause_physics", timeout=30.0)
        rospy.ServiceProxy(SIM + "/unpause_physics", Empty)()
        self.wait(lambda: self.truth.between(2.0, 1e9), 60.0, "2 s of sim time of ground truth")
        rest_height = rospy.get_param("~rest_height", 0.0)
        spawn_z = rospy.get_param("~spawn_z", 0.0)
        landing = self.truth.between(0.0, 2.0)
        highest = max(s.z for s in landing)
        rospy.loginfo(f"FIGURE spawn at z {spawn_z}: highest {highest:.4f} m")
        self.assertLess(highest, max(spawn_z, rest_height) + drive_check.HEIGHT_TOLERANCE,
                        f"the body rose to {highest:.3f} m after a spawn at z {spawn_z} (rest height {rest_height})")
        rest = drive_check.rest(self.truth.between(1.0, 2.0), rest_height)
        rospy.loginfo(f"FIGURE at rest from 1 s: height {rest.height:.4f} m (geometry {rest_height} m), "
                      f"tilt {rest.tilt:.4f} rad, varied {rest.spread:.4f} m")
        self.assertTrue(rest.passed, "; ".join(rest.failures))
        return rest.height

    def stop(self, seconds=1.5):
        end_time = rospy.get_time() + seconds
        while rospy.get_time() < end_time:
            self.pub.publish(Twist())
            rospy.sleep(0.05)

    def test_drives_straight_and_turns_in_place(self):
        height = self.spawn_and_settle()
        self.wait(lambda: self.odom.get() is not None and self.truth.get() is not None, 60.0,
                  "the robot's odometry and the ground truth")
        self.wait(lambda: self.pub.get_num_connections() > 0, 30.0, f"a subscriber on {self.cmd_topic}")
        self.assert_legal_parameter_names()
        urdf_mass = rospy.get_param("~urdf_mass")
        self.assertAlmostEqual(rospy.get_param(SIM + "/urdf_mass"), urdf_mass, delta=1e-6)
        self.assertAlmostEqual(rospy.get_param(SIM + "/loaded_mass"), urdf_mass, delta=1e-3,
                               msg="loaded mass differs from the URDF's")
        if rospy.has_param("~imu_topic"):
            self.wait(lambda: self.imu.count >= 3, 30.0, "the IMU")
            self.stop(0.5)
            imu = self.imu.get()
            a, w = imu.linear_acceleration, imu.angular_velocity
            rospy.loginfo(f"FIGURE imu at rest: accel ({a.x:.3f}, {a.y:.3f}, {a.z:.3f}), yaw rate {w.z:.4f}")
            self.assertAlmostEqual(a.z, 9.81, delta=0.1, msg="an IMU at rest reads +g on z (REP 145)")
            self.assertLess(abs(a.x) + abs(a.y), 0.1)
            self.assertLess(abs(w.z), 0.01)

        (o0, t0), (o1, t1), body = self.drive(SPEED, 0.0, SECONDS)
        self.stop()
        self.assert_ride(body, height, "driving straight")
        tolerance = rospy.get_param("~tolerance", drive_check.DISTANCE_TOLERANCE)  # 0.05: holonomic suites
        straight = drive_check.straight(pose_of(o0), pose_of(o1), pose_of(t0), pose_of(t1), tolerance=tolerance)
        for name, distance, heading in (("odometry", straight.odom_distance, straight.odom_heading),
                                        ("ground truth", straight.truth_distance, straight.truth_heading)):
            rospy.loginfo(f"FIGURE straight[{name}]: {distance:.3f} m, heading change {heading:.3f} rad")
        self.assertTrue(straight.passed, "; ".join(straight.failures))

        if rospy.get_param("~holonomic", False):
            (o0, t0), (o1, t1), body = self.drive(0.0, 0.0, SECONDS, lateral=SPEED)
            self.stop()
            self.assert_ride(body, height, "driving sideways")
            strafe = drive_check.strafe(pose_of(o0), pose_of(o1), pose_of(t0), pose_of(t1), tolerance=tolerance)
            rospy.loginfo(f"FIGURE sideways: odometry {strafe.odom_left:.3f} m, truth {strafe.truth_left:.3f} m to the "
                          "left")
            self.assertTrue(strafe.passed, "; ".join(strafe.failures))

        (o0, t0), (o1, t1), body = self.drive(0.0, TURN, SECONDS)
        self.stop()
        self.assert_ride(body, height, "turning")
        skid = rospy.get_param("~skid", False)
        turn_tolerance = rospy.get_param("~tolerance", drive_check.TURN_TOLERANCE)
        low = 0.25 if skid and rospy.get_param("~odom_is_truth", False) else 1.0 - turn_tolerance
        footprint = rospy.get_param("~footprint", None)  # [half length, half width] of a skid-steered wheel set
        turned = wrap(yaw_of(t1) - yaw_of(t0))
        drift = drive_check.skid_turn_drift(*footprint, turned) if footprint else drive_check.MAX_TURN_DRIFT
        truth_fraction = drive_check.SKID_TURN_FRACTION if skid else drive_check.TRUTH_TURN_FRACTION
        if rospy.has_param("~tolerance"):
            truth_fraction = 1.0 - turn_tolerance
        turn = drive_check.turn(pose_of(o0), pose_of(o1), pose_of(t0), pose_of(t1), odom_fraction=low,
                                truth_fraction=truth_fraction, max_moved=drift,
                                centre=rospy.get_param("~wheel_centre", [0.0, 0.0]), tolerance=turn_tolerance)
        rospy.loginfo(f"FIGURE turn: odometry {turn.odom_yaw:.3f} rad, truth {turn.truth_yaw:.3f} rad, "
                      f"moved {turn.moved:.3f} m")
        self.assertTrue(turn.passed, "; ".join(turn.failures))


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_real_robot", RealRobotTest, sys.argv)
