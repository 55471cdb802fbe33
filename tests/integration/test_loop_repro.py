#!/usr/bin/env python3
"""loop_repro suite: in lockstep, the same scenario with the same seed gives the same
trajectory, whatever the wall time of the client's work and whatever else runs on the machine.

The client is written as Gazebo learning environments are (TurtleBot3's machine-learning chapter): ``step``
publishes cmd_vel, then ``rospy.wait_for_message('/scan')`` (a subscriber made and dropped every step), then
computes; ``reset`` calls /gazebo/reset_simulation, takes a first scan, and respawns a goal marker (a static
model with one visual and no collision: delete_model, spawn_sdf_model, busy-waiting on model_states each time).
Actions (linear, angular velocity) and goal positions come from numpy's ``default_rng(~seed)``; the work between
steps (CPU, and sometimes an idle sleep) lasts a random wall time from an *unseeded* generator, so two runs
differ in timing but not in what they ask. Before its first reset the client takes one scan: it is then in the
simulator's loop (held for) when sim time restarts, so everything from the first reset on is the scenario.

Recorded: the body's ground-truth pose (``/bullet_sim/ground_truth``, 100 Hz, stamped in sim time) at the stamp
of every scan the client got, per episode. Written to ``~trajectory_file`` (JSON, exact floats; default
``$ROS_HOME/loop_repro/trajectory_seed<seed>.json``) and summarised as ``METRIC`` lines for ``batch``
(final x, y, yaw with 12 digits; ``trajectory_digest``: the first 48 bits of a SHA-256 of the exact values, as
an integer). Checked here: every step is one scan period of sim time, the episodes restart at the same sim
time, and the run is not trivial (the body moved > 0.3 m and turned > 0.5 rad). The comparison of runs is
tests/system/test_repro_batch.py's.
"""
import hashlib
import json
import math
import os
import sys
import threading
import time
import unittest

import numpy as np
import rospkg
import rospy
import rostest
from gazebo_msgs.msg import ModelStates
from gazebo_msgs.srv import DeleteModel, SpawnModel
from geometry_msgs.msg import Point, Pose, Quaternion, Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from simtest import GOAL_MARKER_SDF, agent_work, figure, wait_for, yaw_of
from std_srvs.srv import Empty

SCAN_PERIOD_NS = 200_000_000  # laser_robot.urdf's 5 Hz laser
MIN_PATH = 0.3  # m the body must travel over the run for the comparison to mean something
MIN_TURN = 0.5  # rad of heading change, summed
MAX_WORK = 0.04  # s: the longest CPU work between two steps
MAX_IDLE = 0.02  # s: the longest idle pause (I/O) between two steps


class TruthLog:
    """Every ground-truth sample as (stamp in ns, x, y, yaw), split into epochs where sim time goes back
    (reset_simulation): samples of one stamp in one epoch are one physics state."""

    def __init__(self, topic="/bullet_sim/ground_truth"):
        self.lock = threading.Lock()
        self.epochs = [[]]
        self.sub = rospy.Subscriber(topic, Odometry, self._keep, queue_size=10000)

    def _keep(self, msg):
        p = msg.pose.pose.position
        sample = (msg.header.stamp.to_nsec(), p.x, p.y, yaw_of(msg.pose.pose.orientation))
        with self.lock:
            current = self.epochs[-1]
            if current and sample[0] <= current[-1][0]:
                current = []
                self.epochs.append(current)
            current.append(sample)

    def count(self):
        with self.lock:
            return sum(len(samples) for samples in self.epochs)

    def epoch(self):
        with self.lock:
            return len(self.epochs) - 1

    def newest(self, epoch):
        """The newest stamp [ns] received in ``epoch`` (0 when none)."""
        with self.lock:
            samples = self.epochs[epoch] if epoch < len(self.epochs) else []
            return samples[-1][0] if samples else 0

    def find(self, epoch, stamp_ns):
        """The sample stamped ``stamp_ns`` in ``epoch``, or None (not arrived yet)."""
        with self.lock:
            if epoch >= len(self.epochs):
                return None
            for sample in reversed(self.epochs[epoch]):
                if sample[0] == stamp_ns:
                    return sample
                if sample[0] < stamp_ns:
                    return None
        return None


def trajectory_digest(rows):
    """The first 48 bits of a SHA-256 of the rows' exact values (stamps, float reprs), as an integer (exact in a
    float64, so a batch METRIC keeps it)."""
    text = "\n".join(f"{r['episode']} {r['stamp_ns']} {r['x']!r} {r['y']!r} {r['yaw']!r}" for r in rows)
    return int(hashlib.sha256(text.encode()).hexdigest()[:12], 16)


def path_and_turn(rows):
    """Metres travelled and radians turned (absolute heading changes summed), episode by episode."""
    path = turn = 0.0
    for a, b in zip(rows, rows[1:]):
        if a["episode"] == b["episode"]:
            path += math.hypot(b["x"] - a["x"], b["y"] - a["y"])
            turn += abs(math.atan2(math.sin(b["yaw"] - a["yaw"]), math.cos(b["yaw"] - a["yaw"])))
    return path, turn


class Repro(unittest.TestCase):
    def test_seeded_scenario_in_lockstep(self):
        rospy.init_node("test_loop_repro")
        seed = int(rospy.get_param("~seed", 1))
        steps = int(rospy.get_param("~steps", 40))
        path = rospy.get_param("~trajectory_file", "") or os.path.join(
            rospkg.get_ros_home(), "loop_repro", f"trajectory_seed{seed}.json")
        self.assertFalse(rospy.get_param("/bullet_sim/real_time"), "the scenario runs in fast mode")
        self.rng = np.random.default_rng(seed)  # what the agent does: the scenario
        self.jitter = np.random.default_rng()  # how long it takes: differs run to run, on purpose
        self.cmd = rospy.Publisher("/cmd_vel", Twist, queue_size=5)
        self.truth = TruthLog()
        self.states_lock = threading.Lock()
        self.names = None
        rospy.Subscriber("/gazebo/model_states", ModelStates, self._keep_names, queue_size=1)
        for name in ("reset_simulation", "spawn_sdf_model", "delete_model"):
            rospy.wait_for_service(f"/gazebo/{name}", 30)
        self.reset_sim = rospy.ServiceProxy("/gazebo/reset_simulation", Empty)
        self.spawn = rospy.ServiceProxy("/gazebo/spawn_sdf_model", SpawnModel)
        self.delete = rospy.ServiceProxy("/gazebo/delete_model", DeleteModel)
        wait_for(lambda: self.cmd.get_num_connections() > 0, 30, "bullet_sim subscribed to /cmd_vel")
        wait_for(self.truth.count, 30, "ground truth")

        rospy.wait_for_message("/scan", LaserScan, timeout=30)  # in the loop before sim time restarts
        rows, started = [], time.monotonic()
        half = steps // 2
        for k in range(steps):
            if k in (0, half):
                rows.append(self.reset_episode(rows[-1]["episode"] + 1 if rows else 1))
            linear, angular = self.rng.uniform(0.05, 0.25), self.rng.uniform(-1.0, 1.0)
            rows.append(self.step(rows[-1], float(linear), float(angular)))
        wall = time.monotonic() - started

        self.write(path, seed, rows)
        moved, turned = path_and_turn(rows)
        last = rows[-1]
        sim = sum(max(r["stamp_ns"] for r in rows if r["episode"] == e) for e in (1, 2)) / 1e9
        figure(f"loop_repro seed {seed}: {steps} steps, 2 episodes in {wall:.2f} s wall ({steps / wall:.1f} steps/s, "
               f"~{sim / wall:.1f}x real time); path {moved:.3f} m, turned {turned:.3f} rad; trajectory {path}")
        for name, value in (("final_x", last["x"]), ("final_y", last["y"]), ("final_yaw", last["yaw"])):
            print(f"METRIC {name}={value:.12f}", flush=True)
        print(f"METRIC path_m={moved:.12f}", flush=True)
        print(f"METRIC turned_rad={turned:.12f}", flush=True)
        print(f"METRIC samples={len(rows)}", flush=True)
        print(f"METRIC trajectory_digest={trajectory_digest(rows)}", flush=True)

        ahead = [(r["episode"], r["step"], r["stamp_ns"], r["seen_ns"]) for r in rows
                 if r.get("seen_ns", 0) > r["stamp_ns"]]
        self.assertFalse(ahead, "sim time went on while the client was between its scan and its next command "
                                "(episode, step, scan stamp ns, ground truth seen ns): not held for it")
        for episode in (1, 2):
            stamps = [r["stamp_ns"] for r in rows if r["episode"] == episode]
            gaps = set(np.diff(stamps[1:]).tolist())  # stamps[0]: the first scan after the reset
            self.assertEqual(gaps, {SCAN_PERIOD_NS}, f"episode {episode}: sim time between the scans of two steps "
                                                     f"{sorted(gaps)} ns (each should be one scan period)")
        first = {r["episode"]: r["stamp_ns"] for r in reversed(rows)}
        self.assertEqual(first[1], first[2], f"the episodes' first scans came at different sim times {first}")
        self.assertGreater(moved, MIN_PATH, f"the body travelled only {moved:.3f} m: nothing to compare")
        self.assertGreater(turned, MIN_TURN, f"the body turned only {turned:.3f} rad: nothing to compare")

    # -- the environment, as a Gazebo user writes it ----------------------------------------------------------
    def _keep_names(self, msg):
        with self.states_lock:
            self.names = list(msg.name)

    def _listed(self, name):
        with self.states_lock:
            return self.names is not None and name in self.names

    def reset_episode(self, episode):
        """reset_simulation, the first observation, then the goal marker respawned where the seed says."""
        self.reset_sim()
        scan = rospy.wait_for_message("/scan", LaserScan, timeout=30)
        if self._listed("goal"):
            self.assertTrue(self.delete("goal").success)
            deadline = time.monotonic() + 20
            while self._listed("goal"):  # busy, as the original
                self.assertLess(time.monotonic(), deadline, "the goal never left model_states")
        x, y = self.rng.uniform(-1.0, 1.5), self.rng.uniform(-1.2, 1.8)
        pose = Pose(Point(float(x), float(y), 0.0), Quaternion(0.0, 0.0, 0.0, 1.0))
        self.assertTrue(self.spawn("goal", GOAL_MARKER_SDF, "", pose, "world").success)
        deadline = time.monotonic() + 20
        while not self._listed("goal"):
            self.assertLess(time.monotonic(), deadline, "the goal never appeared in model_states")
        return self.record(episode, 0, scan)

    def step(self, previous, linear, angular):
        twist = Twist()
        twist.linear.x, twist.angular.z = linear, angular
        self.cmd.publish(twist)
        scan = rospy.wait_for_message("/scan", LaserScan, timeout=30)
        row = self.record(previous["episode"], previous["step"] + 1, scan, linear, angular)
        agent_work(self.jitter.uniform(0.0, MAX_WORK))
        if self.jitter.random() < 0.3:
            time.sleep(self.jitter.uniform(0.0, MAX_IDLE))  # idle, not subscribed: still held
        # Held for us, sim time is still the scan's when we act: ground truth stamped later is proof it was not
        # (a lower bound: messages may still be on their way).
        row["seen_ns"] = self.truth.newest(row["episode"])
        return row

    def record(self, episode, step, scan, linear=0.0, angular=0.0):
        """The body's ground-truth pose at ``scan``'s stamp (episode e: the truth log's epoch e)."""
        stamp = scan.header.stamp.to_nsec()
        sample = wait_for(lambda: self.truth.find(episode, stamp), 10,
                          f"the ground truth at the scan stamp {stamp} ns of episode {episode}")
        return {"episode": episode, "step": step, "stamp_ns": stamp, "x": sample[1], "y": sample[2],
                "yaw": sample[3], "linear": linear, "angular": angular}

    @staticmethod
    def write(path, seed, rows):
        os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
        tmp = path + ".part"
        with open(tmp, "w") as f:
            json.dump({"seed": seed, "rows": rows}, f, indent=0)  # json writes floats by repr: exact
        os.replace(tmp, path)


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "loop_repro", Repro, sys.argv)
