#!/usr/bin/env python3
"""The published multi-robot launch pattern runs unchanged (tests/data/multi_way: turtlebot3_gazebo's
multi_turtlebot3.launch shape, three TurtleBot3-class robots in a furnished house made of meshes).

Each robot's plugins take the spawning node's namespace (``/tb3_N/``; spawn_model has no -robot_namespace)
and name their frames as Noetic's gazebo_ros does (its plugins' tf_prefix lookup since gazebo_ros_pkgs #1173):

* ``~prefixed`` false (multi_tb3like.launch, robot_state_publisher's tf_prefix private): the plugins find no
  tf_prefix, so odometry is ``odom -> base_footprint`` and scans are in ``base_scan`` for every robot, while
  robot_state_publisher (1.15.2+) publishes ``tb3_N/base_footprint -> tb3_N/...``: ``tb3_N/odom`` exists
  nowhere (turtlebot3_simulations #214).
* ``~prefixed`` true (multi_tb3like_prefixed.launch, a ``tf_prefix`` parameter in each namespace): every
  plugin frame is ``tb3_N/...`` and TF resolves ``tb3_N/odom -> tb3_N/base_scan``.
* Either way the IMU model plugin and joint names are never prefixed (the plugin reads no tf_prefix).

Each robot is judged by ground truth (/gazebo/get_model_state): its /tb3_N/cmd_vel drives it and no other;
its laser sees the other robots (the laser housing, a cylinder of HOUSING_RADIUS around base_scan, is the
only part of a robot at the beam's height) and the living room's south wall where the meshes put it.

Parameters: ~prefixed (bool); ~robots: [{name, x, y, yaw}] as the launch file spawns them.
The geometry helpers (ray_hits) are shared with test_fleet_small.py.
"""
import math
import sys
import threading
import unittest

import numpy as np
import rosgraph
import rospy
import rostest
import tf2_ros
from gazebo_msgs.srv import GetModelState, GetWorldProperties
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu, JointState, LaserScan
from simtest import Latest, assert_upright, sim_now, wait_for as wait, yaw_of
from tf2_msgs.msg import TFMessage

#: The robot (tb3like_description): base_scan 0.032 m behind base_footprint and 0.181 m above it.
SCAN_OFFSET = -0.032  # m along the robot's x
SCAN_HEIGHT = 0.181  # m
HOUSING_RADIUS = 0.050  # m: the laser housing's cylinder, all of a robot the beams can meet
NOISE = 0.01  # m, the laser's <noise><stddev>
RAY_TOLERANCE = 5 * NOISE  # m, one beam against its expected range
MEAN_TOLERANCE = 0.012  # m, the mean signed error of many beams (a wrong mount or geometry shows here)
CENTRAL = 0.7  # beams within this fraction of the radius from a housing's centre line are judged
#: house.world: the living room's south wall face, bare for x in this span at the beams' height
SOUTH_WALL_Y = -4.0
SOUTH_WALL_SPAN = (-3.2, 0.2)
WALL_FAN = math.radians(20.0)  # beams this close to straight south are judged against the wall
DRIVE = 0.15  # m each robot drives forward, judged on its body
SPEED = 0.15  # m/s
DRIVE_TIMEOUT = 60.0  # s wall: ~1 s of sim time on a machine 10x slower
STILL = 0.01  # m a robot not commanded may move while another drives


def scan_origin(x, y, yaw):
    """World (x, y) of base_scan for a robot's base_footprint at (x, y, yaw)."""
    return x + SCAN_OFFSET * math.cos(yaw), y + SCAN_OFFSET * math.sin(yaw)


def beam_angles(scan, yaw):
    """World angle of every reading of ``scan`` taken by a laser facing ``yaw`` (angles from the message)."""
    return yaw + scan.angle_min + scan.angle_increment * np.arange(len(scan.ranges))


def ray_hits(origin, angles, circles):
    """Where beams from ``origin`` at world ``angles`` first meet the ``circles`` [(cx, cy, r)].

    Returns (ranges, which, centrality): the distance to the nearest circle each beam enters (inf for none),
    that circle's index (-1), and the beam's distance from that circle's centre line as a fraction of its
    radius (1 at a grazing beam, where a millimetre decides between hit and miss)."""
    d = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    ranges = np.full(len(angles), np.inf)
    which = np.full(len(angles), -1)
    centrality = np.ones(len(angles))
    for k, (cx, cy, r) in enumerate(circles):
        rel = np.array([cx - origin[0], cy - origin[1]])
        along = d @ rel
        lateral2 = np.maximum(rel @ rel - along * along, 0.0)
        hit = (along > 0) & (lateral2 < r * r)
        dist = np.where(hit, along - np.sqrt(np.maximum(r * r - lateral2, 0.0)), np.inf)
        nearer = dist < ranges
        ranges = np.where(nearer, dist, ranges)
        which = np.where(nearer, k, which)
        centrality = np.where(nearer, np.sqrt(lateral2) / r, centrality)
    return ranges, which, centrality


def fresh(latest, after, what, timeout=20.0):
    """The newest message of ``latest`` stamped after sim time ``after``."""
    return wait(lambda: (m := latest.get()) is not None and m.header.stamp.to_sec() > after and m, timeout, what)


class TfPairs:
    """Every (parent, child) pair seen on /tf (the callback only stores)."""

    def __init__(self):
        self.lock, self.pairs = threading.Lock(), set()
        self.sub = rospy.Subscriber("/tf", TFMessage, self._keep, queue_size=100)

    def _keep(self, msg):
        with self.lock:
            self.pairs.update((t.header.frame_id, t.child_frame_id) for t in msg.transforms)

    def seen(self, pair):
        with self.lock:
            return pair in self.pairs


class MultiWayTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_multi_way")
        cls.prefixed = rospy.get_param("~prefixed", False)
        cls.robots = rospy.get_param("~robots")
        cls.names = [r["name"] for r in cls.robots]
        rospy.wait_for_service("/gazebo/get_model_state", 60.0)
        cls.get_state = rospy.ServiceProxy("/gazebo/get_model_state", GetModelState)
        world = rospy.ServiceProxy("/gazebo/get_world_properties", GetWorldProperties)
        wait(lambda: all(n in world().model_names for n in cls.names), 60.0, "every robot spawned")
        cls.odom = {n: Latest(f"/{n}/odom", Odometry) for n in cls.names}
        cls.scan = {n: Latest(f"/{n}/scan", LaserScan) for n in cls.names}
        cls.tf_buffer = tf2_ros.Buffer()
        cls.tf_listener = tf2_ros.TransformListener(cls.tf_buffer)
        cls.tf_pairs = TfPairs()
        for n in cls.names:
            wait(cls.odom[n].get, 30.0, f"/{n}/odom")

    def frame(self, name, frame):
        """A plugin frame as Noetic's gazebo_ros names it here."""
        return f"{name}/{frame}" if self.prefixed else frame

    def pose(self, name):
        """(x, y, yaw, Pose) of a robot's base_footprint in the world (ground truth)."""
        resp = self.get_state(name, "world")
        self.assertTrue(resp.success, resp.status_message)
        p = resp.pose
        return p.position.x, p.position.y, yaw_of(p.orientation), p

    def test_0_spawned_at_the_launch_files_poses(self):
        for robot in self.robots:
            x, y, yaw, pose = self.pose(robot["name"])
            self.assertAlmostEqual(x, robot["x"], delta=0.02)
            self.assertAlmostEqual(y, robot["y"], delta=0.02)
            self.assertAlmostEqual(yaw, robot["yaw"], delta=0.03)
            assert_upright(pose, 0.0, f"{robot['name']} at rest after the spawn")

    def test_1_topics_are_in_each_robots_namespace(self):
        state = rosgraph.Master("/test_multi_way").getSystemState()
        publishers, subscribers = dict(state[0]), dict(state[1])
        for name in self.names:
            for topic in ("odom", "scan", "imu", "joint_states"):
                self.assertIn("/gazebo", publishers.get(f"/{name}/{topic}", []), f"/gazebo publishes /{name}/{topic}")
            self.assertIn("/gazebo", subscribers.get(f"/{name}/cmd_vel", []), f"/gazebo subscribes /{name}/cmd_vel")
        for topic in ("/odom", "/scan", "/imu", "/joint_states", "/cmd_vel"):
            self.assertNotIn(topic, publishers, "nothing outside the robots' namespaces")
            self.assertNotIn(topic, subscribers, "nothing outside the robots' namespaces")

    def test_2_frames_as_noetic_gazebo_ros_names_them(self):
        wrong = []  # every frame named otherwise, for one message naming them all

        def expect(what, got, expected):
            if got != expected:
                wrong.append(f"{what} is {got!r}, expected {expected!r}")
        for name in self.names:
            odom = self.odom[name].get()
            expect(f"/{name}/odom frame_id", odom.header.frame_id, self.frame(name, "odom"))
            expect(f"/{name}/odom child_frame_id", odom.child_frame_id, self.frame(name, "base_footprint"))
            scan = wait(self.scan[name].get, 20.0, f"/{name}/scan")
            expect(f"/{name}/scan frame_id", scan.header.frame_id, self.frame(name, "base_scan"))
            imu = wait(Latest(f"/{name}/imu", Imu).get, 20.0, f"/{name}/imu")
            expect(f"/{name}/imu frame_id (gazebo_ros_imu reads no tf_prefix)", imu.header.frame_id, "imu_link")
            joints = wait(Latest(f"/{name}/joint_states", JointState).get, 20.0, f"/{name}/joint_states")
            expect(f"/{name}/joint_states names", sorted(joints.name), ["wheel_left_joint", "wheel_right_joint"])
            self.assertEqual(len(scan.ranges), 360)
            self.assertAlmostEqual(scan.range_max, 3.5, places=5)
            # odometrySource world: the odometry pose is the body's world pose
            x, y, yaw, _ = self.pose(name)
            p = odom.pose.pose
            self.assertAlmostEqual(p.position.x, x, delta=0.01)
            self.assertAlmostEqual(p.position.y, y, delta=0.01)
            self.assertAlmostEqual(yaw_of(p.orientation), yaw, delta=0.01)
            self.assertAlmostEqual(yaw_of(imu.orientation), yaw, delta=0.02)
        if wrong:
            self.fail("; ".join(wrong))
        for name in self.names:
            pair = (self.frame(name, "odom"), self.frame(name, "base_footprint"))
            wait(lambda: self.tf_pairs.seen(pair), 10.0, f"the odometry transform {pair} of {name} on /tf")

    def test_3_tf_tree_per_robot(self):
        """robot_state_publisher prefixes with its private tf_prefix either way; the odometry transform joins
        that tree only when the plugins found a tf_prefix too."""
        for name in self.names:
            wait(lambda: self.tf_buffer.can_transform(f"{name}/base_footprint", f"{name}/base_scan", rospy.Time()),
                 20.0, f"robot_state_publisher's {name}/base_footprint -> {name}/base_scan")
            if not self.prefixed:
                wait(lambda: self.tf_buffer.can_transform("odom", "base_footprint", rospy.Time()), 20.0,
                     "the plugins' unprefixed odom -> base_footprint in TF")
                self.assertFalse(self.tf_buffer._frameExists(f"{name}/odom"),
                                 f"no {name}/odom on Noetic without a tf_prefix the plugins find "
                                 "(turtlebot3_simulations #214)")
                continue
            t = wait(lambda: self.tf_buffer.can_transform(f"{name}/odom", f"{name}/base_scan", rospy.Time()) and
                     self.tf_buffer.lookup_transform(f"{name}/odom", f"{name}/base_scan", rospy.Time()),
                     20.0, f"TF {name}/odom -> {name}/base_scan").transform.translation
            x, y, yaw, _ = self.pose(name)  # odometrySource world: odom is the world frame
            sx, sy = scan_origin(x, y, yaw)
            self.assertAlmostEqual(t.x, sx, delta=0.01)
            self.assertAlmostEqual(t.y, sy, delta=0.01)
            self.assertAlmostEqual(t.z, SCAN_HEIGHT, delta=0.01)
        if self.prefixed:
            self.assertFalse(self.tf_buffer._frameExists("odom"), "no unprefixed odom once tf_prefix is found")

    def test_4_each_laser_sees_the_other_robots_and_the_wall(self):
        poses = {n: self.pose(n)[:3] for n in self.names}
        taken = sim_now()
        robot_errors, wall_errors = [], []
        for name in self.names:
            scan = fresh(self.scan[name], taken, f"a /{name}/scan after the poses were read")
            ranges = np.array(scan.ranges, dtype=float)
            x, y, yaw = poses[name]
            origin = scan_origin(x, y, yaw)
            angles = beam_angles(scan, yaw)
            others = [n for n in self.names if n != name]
            circles = [scan_origin(*poses[n]) + (HOUSING_RADIUS,) for n in others]
            expected, which, centrality = ray_hits(origin, angles, circles)
            for k, other in enumerate(others):
                judged = (which == k) & (centrality < CENTRAL)
                self.assertTrue(judged.any(), f"{name}'s laser has a beam on {other}")
                error = ranges[judged] - expected[judged]
                distance = math.dist(origin, circles[k][:2])
                self.assertLess(np.abs(error).max(), RAY_TOLERANCE,
                                f"{name} sees {other} at {ranges[judged]} m, ground truth {distance:.3f} m to its "
                                f"centre - {HOUSING_RADIUS} m")
                robot_errors.extend(error)
            # the living room's south wall: beams near straight south that meet its bare span before any robot
            south = np.abs(np.angle(np.exp(1j * (angles + math.pi / 2)))) < WALL_FAN
            reach = (origin[1] - SOUTH_WALL_Y) / np.maximum(-np.sin(angles), 1e-9)
            hit_x = origin[0] + reach * np.cos(angles)
            judged = south & (hit_x > SOUTH_WALL_SPAN[0]) & (hit_x < SOUTH_WALL_SPAN[1]) & (reach < expected)
            self.assertGreater(judged.sum(), 10, f"{name} has beams on the south wall")
            error = ranges[judged] - reach[judged]
            self.assertLess(np.abs(error).max(), RAY_TOLERANCE,
                            f"{name} sees the south wall at {ranges[judged]}, expected {reach[judged]}")
            wall_errors.extend(error)
        self.assertLess(abs(np.mean(robot_errors)), MEAN_TOLERANCE, f"robots seen at a bias: {robot_errors}")
        self.assertLess(abs(np.mean(wall_errors)), MEAN_TOLERANCE, "the wall seen at a bias")

    def test_5_each_cmd_vel_drives_only_its_robot(self):
        for name in self.names:
            others = {n: self.pose(n)[:2] for n in self.names if n != name}
            x0, y0, yaw0, _ = self.pose(name)
            pub = rospy.Publisher(f"/{name}/cmd_vel", Twist, queue_size=1)
            wait(lambda: pub.get_num_connections() > 0, 10.0, f"/{name}/cmd_vel subscriber")
            cmd = Twist()
            cmd.linear.x = SPEED

            def driven():
                """Commanded until the body has moved DRIVE (not for a time: a loaded machine is late)."""
                pub.publish(cmd)
                x, y = self.pose(name)[:2]
                return math.hypot(x - x0, y - y0) >= DRIVE
            wait(driven, DRIVE_TIMEOUT, f"{name} to drive {DRIVE} m on /{name}/cmd_vel", poll=0.05)

            def stopped():
                pub.publish(Twist())
                v = self.get_state(name, "world").twist.linear
                return math.hypot(v.x, v.y) < 0.01
            wait(stopped, 20.0, f"{name} at rest after the drive", poll=0.05)
            x1, y1, _, pose = self.pose(name)
            assert_upright(pose, 0.0, f"{name} after the drive")
            forward = (x1 - x0) * math.cos(yaw0) + (y1 - y0) * math.sin(yaw0)
            self.assertGreater(forward, DRIVE * 0.95, f"{name} drove forward along its heading")
            self.assertLess(abs(-(x1 - x0) * math.sin(yaw0) + (y1 - y0) * math.cos(yaw0)), 0.03, "and straight")
            for other, (ox, oy) in others.items():
                nx, ny = self.pose(other)[:2]
                self.assertLess(math.hypot(nx - ox, ny - oy), STILL, f"{other} stayed while {name} drove")
            pub.unregister()


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_multi_way", MultiWayTest, sys.argv)
