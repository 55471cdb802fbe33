#!/usr/bin/env python3
"""Per-robot SLAM and navigation of several robots in one world (the published multi-robot launch with a
``tf_prefix`` per namespace, as Noetic users set it), judged by ground truth.

``slam`` (the test's argument): gmapping runs in each robot's namespace on its prefixed frames (tb3like_slam's
multi_tb3like_slam.launch) while each robot drives its own tour (diffbot_sim's ``tour`` node in the namespace,
steering by TF ``tb3_N/map -> tb3_N/base_footprint``). Once every tour is through, each robot's ``/tb3_N/map`` is
judged against the world's true geometry (diffbot_sim.check.map_check) in world coordinates: with odometrySource
world a robot's odom frame is the world's, and gmapping's map frame starts on it. A robot maps only its part of
the house: of the obstacles, those it saw must be mapped, on half their seen outline or on ENOUGH_MAPPED cells;
no free cell more than HOLE_DEPTH inside a solid;
NEAR_SHARE of its occupied cells on true surfaces (the other robots are in its map, not in the world file).

``goals``: amcl and move_base run in each robot's namespace on the shared ``/map`` (tb3like_navigation's
multi_tb3like_navigation.launch); every robot gets its goal at the same moment (paths that cross), and each must
end SUCCEEDED with its body (ground truth, /gazebo/model_states) within ~xy_tolerance m of the goal.

Either way: no two robots touch (each body's outline from above, ~body_outline: convex corners [x, y] in the
robot's base frame, tb3like's box and wheels by default; two robots' outlines must never meet, judged on each
/gazebo/model_states the test receives: the newest one whenever it falls behind),
and TF holds each robot's chain under its prefix, each edge from one node: ``tb3_N/odom -> tb3_N/base_footprint``
from the simulator and ``tb3_N/map -> tb3_N/odom`` from that robot's gmapping, or ``map -> tb3_N/odom`` from its
amcl.

Argument: slam or goals. Parameters: ~robots ([{name, goal: [x, y, yaw]}]; a goal only for goals), ~world and
~laser_height (slam), ~xy_tolerance (0.25), ~goal_timeout (sim s, 240), ~body_outline, ~timeout (wall s, 900).
FIGURE lines: maps, goals, clearances, sim/wall time, RTF.
"""
import math
import sys
import threading
import time
import unittest

import actionlib
import numpy as np
import rospy
import rostest
from actionlib_msgs.msg import GoalStatus
from gazebo_msgs.msg import ModelStates
from gazebo_msgs.srv import GetModelState
from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal
from nav_msgs.msg import OccupancyGrid
from simtest import Latest, TfEdges, action_done, figure, sim_now, wait_for, yaw_of

from diffbot_sim.check import map_check
from diffbot_sim.world.loading import load_world

#: tb3like's footprint as seen from above (its collision shapes: the 0.138 m box about (-0.032, 0) and the two
#: wheels, r 0.033 m and 0.018 m wide at y +-0.080), as the convex outline [x, y] in base_footprint.
TB3LIKE_OUTLINE = [[-0.101, -0.069], [-0.033, -0.089], [0.033, -0.089], [0.037, -0.069], [0.037, 0.069],
                   [0.033, 0.089], [-0.033, 0.089], [-0.101, 0.069]]


def _edges(outline):
    """The closed outline's edges as map_check segments: (N, 4) [x1, y1, x2, y2]."""
    return np.hstack([outline, np.roll(outline, -1, axis=0)])


def outline_gap(a, b):
    """The distance [m] between two convex outlines ((N, 2) corners in order); 0 when they touch or overlap."""
    edges_a, edges_b = _edges(a), _edges(b)
    if map_check.inside(a, edges_b).any() or map_check.inside(b, edges_a).any():
        return 0.0
    for p, q in zip(a, np.roll(a, -1, axis=0)):  # crossing edges (no corner inside the other)
        for r, t in zip(b, np.roll(b, -1, axis=0)):
            d1 = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
            d2 = (q[0] - p[0]) * (t[1] - p[1]) - (q[1] - p[1]) * (t[0] - p[0])
            d3 = (t[0] - r[0]) * (p[1] - r[1]) - (t[1] - r[1]) * (p[0] - r[0])
            d4 = (t[0] - r[0]) * (q[1] - r[1]) - (t[1] - r[1]) * (q[0] - r[0])
            if d1 * d2 < 0 and d3 * d4 < 0:
                return 0.0
    return float(min(map_check.distances(a, edges_b).min(), map_check.distances(b, edges_a).min()))


#: Boundary cells (half a metre of outline) that make an obstacle mapped in a robot's partial map, whatever share
#: of its seen boundary they are: a fleet robot sees some faces only at grazing angles from afar (the sofa's end
#: from the living room's middle: 12 of 37 seen cells mapped in one run, 13 of 26 in the next).
ENOUGH_MAPPED = 10
#: How deep inside a solid a free cell of one robot's map is a hole: the accuracy asked of its occupied cells
#: (map_check.NEAR, 0.15 m) rather than the single-robot suites' 0.10 m. Three gmappings share two cores; in fast
#: mode one robot's map twice had cells 0.12-0.13 m into the kitchen counter's west end (1, then 3 cells, in 18
#: maps), while 272,000 rays cast about that kitchen at the laser's height, 200,000 of them at the counter from
#: where the robot turns, crossed no solid: gmapping's registration, not the sensor.
HOLE_DEPTH = map_check.NEAR
#: Of one robot's occupied cells, the share that must lie on a true surface: the other robots are in its scans
#: and its map (their laser housings, and the trail gmapping leaves of a robot that moved) but not in the world
#: file; 91.9-97.9 % measured in 18 maps (the single-robot suites ask 90 % and see 99-100 %).
NEAR_SHARE = 0.85


class Fleet:
    """What the robots do, by ground truth and TF (callbacks only store): each robot's latest pose, the
    smallest gap between any two robots' outlines and when, and which node published each TF edge."""

    def __init__(self, names):
        self.names = list(names)
        self.lock = threading.Lock()
        self.poses = {}  # name -> (x, y, yaw, sim t)
        self.gap, self.gap_moment = math.inf, ""
        self.outline = np.array(rospy.get_param("~body_outline", TB3LIKE_OUTLINE), dtype=float)
        rospy.Subscriber("/gazebo/model_states", ModelStates, self._models, queue_size=1)
        self.tf = TfEdges(static=True)  # robot_state_publisher's fixed joints are on /tf_static

    def _models(self, msg):
        now = rospy.get_time()
        outlines = {}
        for name in self.names:
            if name not in msg.name:
                continue
            pose = msg.pose[msg.name.index(name)]
            yaw = yaw_of(pose.orientation)
            c, s = math.cos(yaw), math.sin(yaw)
            outlines[name] = self.outline @ np.array([[c, s], [-s, c]]) + [pose.position.x, pose.position.y]
            with self.lock:
                self.poses[name] = (pose.position.x, pose.position.y, yaw, now)
        names = sorted(outlines)
        with self.lock:
            for i, a in enumerate(names):
                for b in names[i + 1:]:
                    gap = outline_gap(outlines[a], outlines[b])
                    if gap < self.gap:
                        self.gap = gap
                        pa, pb = self.poses[a], self.poses[b]
                        self.gap_moment = (f"{a} at ({pa[0]:.2f}, {pa[1]:.2f}, {pa[2]:.2f} rad) and {b} at "
                                           f"({pb[0]:.2f}, {pb[1]:.2f}, {pb[2]:.2f} rad), sim t {now:.1f} s")

    def pose(self, name):
        with self.lock:
            return self.poses.get(name)

    def smallest_gap(self):
        with self.lock:
            return self.gap, self.gap_moment


class MultiNavTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_multi_nav")
        cls.robots = rospy.get_param("~robots")
        cls.names = [r["name"] for r in cls.robots]
        cls.fleet = Fleet(cls.names)
        cls.timeout = float(rospy.get_param("~timeout", 900.0))

    def check_tf(self, map_parent):
        """Each robot's chain under its prefix, each edge from one node (``map_parent(name)``: the frame amcl or
        gmapping hangs the robot's odom frame on)."""
        edges = self.fleet.tf.edges()
        twice = {edge: who for edge, who in edges.items() if len(who) > 1}
        self.assertEqual(twice, {}, "TF edges published by more than one node")
        for name in self.names:
            for parent, child in ((f"{name}/odom", f"{name}/base_footprint"), (map_parent(name), f"{name}/odom"),
                                  (f"{name}/base_footprint", f"{name}/base_link"),
                                  (f"{name}/base_link", f"{name}/base_scan")):
                self.assertIn((parent, child), edges, f"no TF edge {parent} -> {child} (edges: {sorted(edges)})")
        self.assertFalse(any(child == "odom" for _, child in edges), "an unprefixed odom frame in TF")

    def check_no_contact(self):
        gap, moment = self.fleet.smallest_gap()
        figure(f"robots' outlines: {gap * 100:.1f} cm apart at the closest ({moment})")
        self.assertTrue(math.isfinite(gap), "the robots were never seen in /gazebo/model_states")
        self.assertGreater(gap, 0.0, f"two robots touched: {moment}")


class MultiSlamTest(MultiNavTest):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.maps = {name: Latest(f"/{name}/map", OccupancyGrid) for name in cls.names}

    def test_each_robot_maps_its_part_of_the_world(self):
        wall0 = time.monotonic()
        wait_for(lambda: rospy.get_time() > 0, 60.0, "sim time")
        sim0 = rospy.get_time()
        for name in self.names:
            wait_for(lambda: rospy.get_param(f"/{name}/tour/done", False), self.timeout, f"{name}'s tour to end")
        done_at, wall = rospy.get_time(), time.monotonic() - wall0
        figure(f"tours: {done_at - sim0:.1f} s of sim time in {wall:.1f} s of wall time: RTF "
               f"{(done_at - sim0) / wall:.2f}")
        world = load_world(rospy.get_param("~world"), 1.0)
        sections = map_check.world_section(world, float(rospy.get_param("~laser_height")))
        failures = []
        # maps stamped after the simulator's time now, when every tour is known to be over (this node's clock can
        # lag it: a map stamped after that could still miss a tour's last part)
        ended = sim_now()
        for name in self.names:
            msg = wait_for(lambda: (m := self.maps[name].get()) is not None and m.header.stamp.to_sec() > ended
                           and m, 120.0, f"a /{name}/map published after the tours")
            # gmapping stamps its /map with tf_.resolve(map_frame): the tf_prefix it finds from its namespace is
            # put before the already prefixed frame once more (its TF is tb3_N/map -> tb3_N/odom all the same).
            self.assertIn(msg.header.frame_id.lstrip("/"), (f"{name}/map", f"{name}/{name}/map"))
            grid = map_check.Grid.from_message(msg)
            report = map_check.judge(grid, sections, deep=HOLE_DEPTH, min_near_fraction=NEAR_SHARE,
                                     every_obstacle=False, enough_mapped=ENOUGH_MAPPED)
            seen = [o for o in report.obstacles if o.seen]
            figure(f"{name}'s map: {report.occupied} occupied cells, {report.near_fraction:.1%} within "
                   f"{map_check.NEAR} m of a true surface, median error {report.median_error * 100:.1f} cm, "
                   f"{report.free_inside} free cells deep inside solids, {len(seen)} obstacles seen, mapped "
                   + ", ".join(f"{o.mapped}/{o.seen}" for o in seen))
            failures += [f"{name}: {why}" for why in report.failures]
            if len(seen) < 3:
                failures.append(f"{name}: only {len(seen)} obstacles seen (a wall and furniture at least)")
        self.assertEqual(failures, [], "; ".join(failures))
        self.check_no_contact()
        self.check_tf(lambda name: f"{name}/map")


class MultiGoalsTest(MultiNavTest):
    def test_every_robot_reaches_its_goal(self):
        xy_tol = float(rospy.get_param("~xy_tolerance", 0.25))
        timeout = float(rospy.get_param("~goal_timeout", 240.0))
        clients = {}
        for name in self.names:
            clients[name] = actionlib.SimpleActionClient(f"/{name}/move_base", MoveBaseAction)
            wait_for(lambda: clients[name].wait_for_server(rospy.Duration(0.05)), 120.0, f"{name}'s move_base")
        wait_for(lambda: all(self.fleet.pose(n) for n in self.names), 60.0, "every robot's ground truth")
        wall0, sim0 = time.monotonic(), rospy.get_time()
        for robot in self.robots:
            x, y, yaw = robot["goal"]
            goal = MoveBaseGoal()
            goal.target_pose.header.frame_id = "map"
            goal.target_pose.header.stamp = rospy.Time.now()
            goal.target_pose.pose.position.x, goal.target_pose.pose.position.y = x, y
            goal.target_pose.pose.orientation.z = math.sin(yaw / 2)
            goal.target_pose.pose.orientation.w = math.cos(yaw / 2)
            clients[robot["name"]].send_goal(goal)
        ended = {}

        def all_ended():
            for name, client in clients.items():
                if name not in ended and action_done(client):
                    ended[name] = rospy.get_time() - sim0
            return len(ended) == len(clients) or rospy.get_time() - sim0 > timeout
        wait_for(all_ended, timeout * 3 + 60, "every robot's goal to end")
        sim_time, wall = rospy.get_time() - sim0, time.monotonic() - wall0
        failures = []
        # each body after every goal ended, read from the simulator now (the newest /gazebo/model_states this node
        # holds, stamped by its own lagging clock, can be from before the last goal ended)
        rospy.wait_for_service("/gazebo/get_model_state", 30.0)
        model_state = rospy.ServiceProxy("/gazebo/get_model_state", GetModelState)
        for robot in self.robots:
            name, (x, y, _) = robot["name"], robot["goal"]
            state = clients[name].get_state()
            body = model_state(name, "world")
            self.assertTrue(body.success, f"get_model_state {name}: {body.status_message}")
            error = math.hypot(body.pose.position.x - x, body.pose.position.y - y)
            figure(f"{name}: goal ({x}, {y}) state {state} after {ended.get(name, math.nan):.1f} s sim, body "
                   f"{error * 100:.1f} cm from it")
            if state != GoalStatus.SUCCEEDED:
                failures.append(f"{name}'s goal ({x}, {y}) ended in state {state}")
            if error >= xy_tol:
                failures.append(f"{name}'s body is {error:.3f} m from its goal ({x}, {y})")
        figure(f"navigation: {len(self.robots)} robots' goals in {sim_time:.1f} s of sim time, {wall:.1f} s of "
               f"wall time: RTF {sim_time / wall:.2f}")
        self.assertEqual(failures, [], "; ".join(failures))
        self.check_no_contact()
        self.check_tf(lambda name: "map")


if __name__ == "__main__":
    # The kind is the test's argument (args="slam" or "goals" in the .test file): it picks the test class
    # before the node exists to read a parameter.
    rostest.rosrun("diffbot_sim", "test_multi_nav", MultiSlamTest if "slam" in sys.argv[1:] else MultiGoalsTest,
                   sys.argv)
