#!/usr/bin/env python3
"""A small fleet in one simulator (fleet_small.test: ten TurtleBot3-class robots of tests/data/multi_way, each
with its 360-beam laser at 5 Hz, spawned from bullet_sim's ~robots list, nine on a ring and one inside it).

Every robot's scan is subscribed, and every robot sees the others where ground truth
(/gazebo/get_model_state) puts them: each beam that ground truth says meets another robot's laser housing
(the only part of a robot at the beams' height; a robot behind another is hidden, as ray casting hides it)
reads the distance to it, and each beam that ground truth says passes clear of every robot reads no hit. Then
the ring robots drive 0.2 m along the ring and the inner one turns, and the scans are judged again against
the moved bodies. Geometry: test_multi_way.py (the robot's laser mount, ray_hits). With ``~ray_process`` (as
fleet_small.test sets it) the rays are cast in the simulator's helper process, which must be running.
"""
import math
import os
import sys
import unittest

import numpy as np
import rospy
import rostest
from gazebo_msgs.srv import GetModelState, GetWorldProperties
from geometry_msgs.msg import Twist
from sensor_msgs.msg import LaserScan
from simtest import Latest, sim_now, wait_for as wait, yaw_of
from test_multi_way import (
    CENTRAL,
    HOUSING_RADIUS,
    MEAN_TOLERANCE,
    RAY_TOLERANCE,
    beam_angles,
    fresh,
    ray_hits,
    scan_origin,
)
from traittest import settled

SIM = "/bullet_sim"
CLEAR = 0.02  # m: a beam passing a housing closer than this may go either way, and is not judged as a miss
RANGE_EDGE = 0.05  # m: a housing this close to the laser's range_max may be in range or not
MOVE = 0.2  # m each ring robot drives forward (along the ring)
TURN = 1.0  # rad the inner robot turns
SPEED, TURN_RATE = 0.2, 1.0  # m/s, rad/s
MOVE_TIMEOUT = 90.0  # s wall: ~1.5 s of sim time for ten robots on a loaded machine
REST_BAND, REST_WINDOW = 0.001, 0.3  # m and rad, s of sim time: a body held within this band this long is at rest


def clearance(origin, angles, circles):
    """For each beam, how far it passes outside the nearest circle ahead of it (m; inf with none ahead)."""
    d = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    out = np.full(len(angles), np.inf)
    for cx, cy, r in circles:
        rel = np.array([cx - origin[0], cy - origin[1]])
        along = d @ rel
        lateral = np.sqrt(np.maximum(rel @ rel - along * along, 0.0))
        out = np.where(along > -r, np.minimum(out, lateral - r), out)
    return out


class FleetSmallTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_fleet_small")
        cls.names = [r["name"] for r in rospy.get_param(SIM + "/robots")]
        rospy.wait_for_service("/gazebo/get_model_state", 60.0)
        cls.get_state = rospy.ServiceProxy("/gazebo/get_model_state", GetModelState)
        world = rospy.ServiceProxy("/gazebo/get_world_properties", GetWorldProperties)
        wait(lambda: all(n in world().model_names for n in cls.names), 60.0, "every robot in the world")
        cls.scan = {n: Latest(f"/{n}/scan", LaserScan) for n in cls.names}
        cls.cmd = {n: rospy.Publisher(f"/{n}/cmd_vel", Twist, queue_size=1) for n in cls.names}
        for n in cls.names:
            wait(cls.scan[n].get, 30.0, f"/{n}/scan")
            wait(lambda: cls.cmd[n].get_num_connections() > 0, 20.0, f"/{n}/cmd_vel subscriber")

    def test_0_the_ray_process_runs_when_asked(self):
        if not rospy.get_param(SIM + "/ray_process", False):
            self.skipTest("~ray_process is off: the rays are cast in the simulator's process")
        helpers = []
        for pid in filter(str.isdigit, os.listdir("/proc")):
            try:
                with open(f"/proc/{pid}/cmdline", "rb") as f:
                    command = f.read().split(b"\0")
            except OSError:
                continue
            if b"diffbot_sim.physics.ray_mirror" in command:
                helpers.append(pid)
        self.assertEqual(len(helpers), 1, "one ray process (python -m diffbot_sim.physics.ray_mirror) runs")

    def state(self, name):
        resp = self.get_state(name, "world")
        self.assertTrue(resp.success, resp.status_message)
        return resp

    def pose(self, name):
        """A robot's (x, y, yaw), ground truth."""
        p = self.state(name).pose
        return p.position.x, p.position.y, yaw_of(p.orientation)

    def poses(self):
        return {name: self.pose(name) for name in self.names}

    def judge_scans(self, poses, what):
        """Each robot's next scan against the housings of all the others at ``poses``; returns how many
        neighbours each robot saw."""
        taken = sim_now()
        errors, seen = [], {}
        for name in self.names:
            scan = fresh(self.scan[name], taken, f"a /{name}/scan after the poses were read ({what})")
            ranges = np.array(scan.ranges, dtype=float)
            origin = scan_origin(*poses[name])
            angles = beam_angles(scan, poses[name][2])
            others = [n for n in self.names if n != name]
            circles = [scan_origin(*poses[n]) + (HOUSING_RADIUS,) for n in others]
            expected, which, centrality = ray_hits(origin, angles, circles)
            in_range = expected < scan.range_max - RANGE_EDGE
            seen[name] = 0
            for k, other in enumerate(others):
                judged = (which == k) & (centrality < CENTRAL) & in_range
                if not judged.any():
                    continue  # hidden behind another robot, or out of range
                seen[name] += 1
                error = ranges[judged] - expected[judged]
                distance = math.dist(origin, circles[k][:2])
                self.assertLess(np.abs(error).max(), RAY_TOLERANCE,
                                f"{what}: {name} sees {other} at {ranges[judged]} m; ground truth: {distance:.3f} m to "
                                f"its laser's centre, so {expected[judged]} m to its housing")
                errors.extend(error)
            free = clearance(origin, angles, circles) > CLEAR
            phantom = free & np.isfinite(ranges) & (ranges < scan.range_max)
            self.assertFalse(phantom.any(), f"{what}: {name} reads {ranges[phantom]} m at beams "
                             f"{np.flatnonzero(phantom)}, where ground truth has no robot")
        self.assertLess(abs(np.mean(errors)), MEAN_TOLERANCE, f"{what}: robots seen at a bias")
        return seen

    def test_1_every_robot_sees_the_others_where_they_are(self):
        seen = self.judge_scans(self.poses(), "at the spawn poses")
        # in this layout no robot hides another entirely: each sees all nine
        self.assertEqual(seen, {n: len(self.names) - 1 for n in self.names})

    def test_2_and_after_they_moved(self):
        start = self.poses()
        inner = self.names[-1]
        done = set()

        def moved():
            for name in self.names:
                if name in done:
                    continue
                x, y, yaw = self.pose(name)
                x0, y0, yaw0 = start[name]
                far = (abs(math.remainder(yaw - yaw0, 2 * math.pi)) >= TURN if name == inner
                       else math.hypot(x - x0, y - y0) >= MOVE)
                cmd = Twist()
                if far:
                    done.add(name)
                elif name == inner:
                    cmd.angular.z = TURN_RATE
                else:
                    cmd.linear.x = SPEED
                self.cmd[name].publish(cmd)
            return len(done) == len(self.names)
        wait(moved, MOVE_TIMEOUT, "the ring robots to drive and the inner one to turn", poll=0.05)

        def poses():
            for name in self.names:  # the zero command, again while they come to rest
                self.cmd[name].publish(Twist())
            return [v for x, y, yaw in map(self.pose, self.names) for v in (x, y, math.cos(yaw), math.sin(yaw))]
        # every robot held within 1 mm and ~1 mrad (its heading's cosine and sine: no jump at +-pi) for 0.3 s of
        # sim time: one slow instant is not at rest
        settled(poses, REST_BAND, window=REST_WINDOW, timeout=20.0, what="every robot's pose")
        now = self.poses()
        for name in self.names[:-1]:
            self.assertGreater(math.dist(now[name][:2], start[name][:2]), MOVE * 0.9, f"{name} drove")
        self.assertGreater(abs(math.remainder(now[inner][2] - start[inner][2], 2 * math.pi)), TURN * 0.9)
        seen = self.judge_scans(now, "after the moves")
        self.assertTrue(all(count >= len(self.names) - 2 for count in seen.values()), seen)


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_fleet_small", FleetSmallTest, sys.argv)
