#!/usr/bin/env python3
"""A step-and-wait learning environment with the traits of TurtleBot3's (ROBOTIS-GIT/turtlebot3_machine_learning,
noetic branch: ``environment_stage_1.py``'s ``Env``, ``respawnGoal.py``'s ``Respawn``, the agent loop of
``turtlebot3_dqn.py``), written here (none of its code), for the suites that judge fast mode with such a client
(``loop_lockstep``: one short run; ``slow_dqn_env``: 20 runs, each a fresh process).

What it does as the original does:

- its own ``odom`` subscriber (made at start-up, before the first reset) keeps the robot's position and the
  goal's heading; until the first odometry arrives the position is a ``geometry_msgs/Pose``, so a state built
  before any odometry fails as the original's did (``'Pose' object has no attribute 'x'``);
- ``reset``: ``/gazebo/reset_simulation`` through a fresh service proxy, then ``rospy.wait_for_message('scan')``;
  on the first reset the goal model is spawned (after a 0.5 s wall-clock sleep, busy-waiting on
  ``/gazebo/model_states``), and the goal distance is taken from the odometry;
- ``step``: publish ``cmd_vel`` (0.15 m/s, one of five turn rates), ``rospy.wait_for_message('scan')`` (a
  subscriber made and dropped each step), the state and reward; a collision stops the robot and ends the
  episode; a goal reached deletes and respawns the goal model (busy-waiting on model_states, 0.5 s sleep);
- the agent computes between steps (CPU, as a network's forward pass and training would).

Each action's span is the sim time between the scans that bracket it (the scan the action was chosen on, the
scan ``step`` returns): at real time one scan period (0.2 s for a 5 Hz laser), and so it must be in fast mode.
The command must also take effect at the first of those scans: every episode runs the same actions from the
same reset, so the odometry poses at the scans must be the same in every episode (and every run) whose first
scan came at the same sim time, bit for bit (:func:`same_starts`).

Run as a node: ``tb3_env.py EPISODES STEPS [SEED]`` prints one JSON line: every span, the episodes' ends, the
wall time, or the exception that ended the run.
"""
import json
import math
import random
import sys
import time
import traceback

import rospy
from gazebo_msgs.msg import ModelStates
from gazebo_msgs.srv import DeleteModel, SpawnModel
from geometry_msgs.msg import Pose, Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from simtest import GOAL_MARKER_SDF, agent_work
from std_srvs.srv import Empty

ACTIONS = 5
MAX_ANGULAR = 1.5  # rad/s: the turn rate is ((ACTIONS - 1) / 2 - action) x MAX_ANGULAR x 0.5, as the original's
LINEAR = 0.15  # m/s
COLLISION_RANGE = 0.13  # m
GOAL_RANGE = 0.2  # m
SCAN_TIMEOUT = 5.0  # s (wall): the original retries for ever; here each retry is counted


def wait_scan(counts):
    """``rospy.wait_for_message('scan')`` retried on timeout, as the original's loop (retries counted)."""
    while True:
        try:
            return rospy.wait_for_message("scan", LaserScan, timeout=SCAN_TIMEOUT)
        except rospy.ROSException:
            counts["scan_retries"] += 1


class Respawn:
    """The goal model: spawned and deleted through fresh service proxies, each call preceded by a busy wait on
    /gazebo/model_states (the original spins on a flag its callback sets)."""

    def __init__(self, rng):
        self.rng = rng
        self.goal = Pose()
        self.goal.position.x, self.goal.position.y = 0.6, 0.0
        self.last = (0.6, 0.0)
        self.listed = False
        self.sub = rospy.Subscriber("gazebo/model_states", ModelStates, self._states)

    def _states(self, msg):
        self.listed = "goal" in msg.name

    def spawn(self):
        while self.listed:  # busy, as the original
            pass
        rospy.wait_for_service("gazebo/spawn_sdf_model")
        rospy.ServiceProxy("gazebo/spawn_sdf_model", SpawnModel)("goal", GOAL_MARKER_SDF, "robotos_name_space",
                                                                 self.goal, "world")

    def delete(self):
        while not self.listed:  # busy, as the original
            pass
        rospy.wait_for_service("gazebo/delete_model")
        rospy.ServiceProxy("gazebo/delete_model", DeleteModel)("goal")

    def position(self, pick=False, delete=False):
        if delete:
            self.delete()
        while pick:  # stage 1's choice: away from the last goal
            x, y = self.rng.randrange(-12, 13) / 10.0, self.rng.randrange(-12, 13) / 10.0
            if abs(x - self.last[0]) >= 1 or abs(y - self.last[1]) >= 1:
                self.goal.position.x, self.goal.position.y = x, y
                break
        time.sleep(0.5)  # wall clock, as the original
        self.spawn()
        self.last = (self.goal.position.x, self.goal.position.y)
        return self.last


class Env:
    """TurtleBot3's stage-1 environment's traits (see the module docstring)."""

    def __init__(self, rng, counts):
        self.counts = counts
        self.position = Pose()  # as the original: a Pose until the first odometry (its .x fails)
        self.heading = 0.0
        self.goal_x = self.goal_y = 0.0
        self.first_goal = True
        self.goal_distance = 0.0
        self.poses = {}  # odometry stamp -> (x, y, yaw) since the last reset (a measurement, not the original's)
        self.cmd = rospy.Publisher("cmd_vel", Twist, queue_size=5)
        self.sub = rospy.Subscriber("odom", Odometry, self._odometry)
        self.respawn = Respawn(rng)

    def _odometry(self, msg):
        self.position = msg.pose.pose.position
        q = msg.pose.pose.orientation
        yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
        heading = math.atan2(self.goal_y - self.position.y, self.goal_x - self.position.x) - yaw
        heading = (heading + math.pi) % (2.0 * math.pi) - math.pi
        self.heading = round(heading, 2)
        self.poses[round(msg.header.stamp.to_sec(), 6)] = (self.position.x, self.position.y, yaw)

    def poses_at(self, stamps, timeout=2.0):
        """The odometry pose at each of ``stamps`` (the drive publishes at the laser's stamps too), waiting up to
        ``timeout`` wall seconds for the last; None where there is none."""
        deadline = time.monotonic() + timeout
        while round(stamps[-1], 6) not in self.poses and time.monotonic() < deadline:
            time.sleep(0.01)
        return [self.poses.get(round(s, 6)) for s in stamps]

    def distance(self):
        return round(math.hypot(self.goal_x - self.position.x, self.goal_y - self.position.y), 2)

    def state(self, scan):
        ranges = [3.5 if r == float("inf") else 0.0 if math.isnan(r) else r for r in scan.ranges]
        done = COLLISION_RANGE > min(ranges) > 0
        distance = self.distance()
        return ranges + [self.heading, distance], done, distance < GOAL_RANGE

    def step(self, action):
        twist = Twist()
        twist.linear.x = LINEAR
        twist.angular.z = ((ACTIONS - 1) / 2 - action) * MAX_ANGULAR * 0.5
        self.cmd.publish(twist)
        scan = wait_scan(self.counts)
        state, done, goal = self.state(scan)
        if done:
            self.cmd.publish(Twist())
            self.counts["collisions"] += 1
        elif goal:
            self.cmd.publish(Twist())
            self.counts["goals"] += 1
            self.goal_x, self.goal_y = self.respawn.position(pick=True, delete=True)
            self.goal_distance = self.distance()
        return scan, state, done

    def reset(self):
        self.poses = {}
        rospy.wait_for_service("gazebo/reset_simulation")
        try:
            rospy.ServiceProxy("gazebo/reset_simulation", Empty)()
        except rospy.ServiceException:
            print("gazebo/reset_simulation service call failed", file=sys.stderr)
        scan = wait_scan(self.counts)
        if self.first_goal:
            self.goal_x, self.goal_y = self.respawn.position()
            self.first_goal = False
        self.goal_distance = self.distance()
        state, _, _ = self.state(scan)
        return scan, state


def run(episodes, steps, seed=0, work=(0.002, 0.03)):
    """``episodes`` episodes of at most ``steps`` steps, each episode the same random actions (from ``seed``), with
    ``work`` (min, max) wall seconds of agent computing between steps; returns the record: the spans, the
    odometry pose at each scan of each episode (held exactly, every episode moves the body the same, bit for
    bit: a command taken late shows), counts, wall time, and the error if one ended the run."""
    rng = random.Random(seed)
    counts = {"collisions": 0, "goals": 0, "scan_retries": 0, "steps": 0}
    record = {"spans": [], "episode_spans": [], "trajectories": [], "starts": [], "counts": counts, "error": None}
    started = time.monotonic()
    try:
        env = Env(rng, counts)
        for _ in range(episodes):
            actions = random.Random(seed)
            scan, state = env.reset()
            last = scan.header.stamp.to_sec()
            spans, stamps = [], [last]
            for _ in range(steps):
                agent_work(rng.uniform(*work))
                scan, state, done = env.step(actions.randrange(ACTIONS))
                stamp = scan.header.stamp.to_sec()
                spans.append(round(stamp - last, 6))
                stamps.append(stamp)
                last = stamp
                counts["steps"] += 1
                if done:
                    break
            record["spans"] += spans
            record["episode_spans"].append(spans)
            record["trajectories"].append(env.poses_at(stamps))
            record["starts"].append(stamps[0])
    except Exception as err:  # reported, as a crash of the original would end its run
        record["error"] = f"{type(err).__name__}: {err}\n{traceback.format_exc(limit=3)}"
    record["wall_s"] = time.monotonic() - started
    return record


def same_starts(record, start):
    """The trajectories of ``record``'s episodes whose first scan after the reset came at sim time ``start``: those
    started from the same state and must move the body the same, bit for bit. (A first scan can come a period
    or two later when the client's new subscription connects after sim time passed one period; the body rests
    that much longer after the reset, and moves a little differently.)"""
    return [t for t, s in zip(record.get("trajectories") or [], record.get("starts") or []) if abs(s - start) < 1e-6]


def main():
    episodes, steps = int(sys.argv[1]), int(sys.argv[2])
    seed = int(sys.argv[3]) if len(sys.argv) > 3 else 0
    rospy.init_node("tb3_env", anonymous=True, disable_signals=True)
    print(json.dumps(run(episodes, steps, seed)), flush=True)


if __name__ == "__main__":
    main()
