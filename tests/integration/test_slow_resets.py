#!/usr/bin/env python3
"""Resets and spawns without leaks (slow_resets.test): what a Gazebo learning environment does
over thousands of episodes (TurtleBot3's machine-learning chapter: /gazebo/reset_simulation, then the goal marker
deleted and spawned again), made 10,000 times against the simulator in fast mode, each call through a plain
``rospy.ServiceProxy`` as such code makes it (a master lookup and a new connection per call).

Per iteration: reset_simulation, spawn_sdf_model of the goal (a static model with one visual and no collision:
no physics body), delete_model of it; every BOX_EVERY-th iteration also a box with a collision (a physics body)
spawned and deleted. At CHECKPOINTS evenly spaced checkpoints the simulator process (its pid from its own
XML-RPC getPid) is sampled: resident memory (/proc/PID/status VmRSS), open file descriptors (/proc/PID/fd),
threads (/proc/PID/task), the TF listeners at the master (subscribers of /tf and /tf_static), the simulator's own
registrations there (topics published and subscribed, services) and its connections (its getBusInfo).

Judged after a warm-up of the first 10 % of iterations (caches filled, allocator pools grown): memory grows by
less than MAX_RSS_GROWTH_KIB over the rest; every count is exactly what it was at the end of the warm-up (fds and
threads read once the last call's connection has closed: until they hold still); every call succeeded; and the
services stay fast: for each call the quick end of its wall times (the 10th percentile) over the last 10 % of
iterations is at most MAX_SLOWDOWN times that over the second 10 %. The quick end, not the median: a slowdown the
simulator causes (something growing with each call) moves every call, the quickest too, while a machine that got
busier between the two windows moves the median (measured: medians 5.0 -> 7.5 ms with a chroot installing packages
beside it, the simulator's loop waiting for a CPU 17-24 % of the time). FIGURE lines give the calls per second and
every checkpoint.
"""
import os
import statistics
import sys
import time
import unittest
import xmlrpc.client
from dataclasses import dataclass

import rosgraph
import rospy
import rostest
from gazebo_msgs.srv import DeleteModel, SpawnModel
from geometry_msgs.msg import Point, Pose, Quaternion
from simtest import GOAL_MARKER_SDF, SIM, figure, node_pid, rss_kib, run_delay
from std_srvs.srv import Empty

CALLER = "/test_slow_resets"
CHECKPOINTS = 10
BOX_EVERY = 100  # iterations between two spawns of the box with a collision
#: KiB. Measured over 9,000 iterations after the warm-up (this machine, 2 cores): see the module's report; a
#: leak of one small object per call (~100 B x 30,000 calls) would reach ~3 MB, of one model's parsed SDF or
#: its bodies per spawn (~kB each) tens of MB.
MAX_RSS_GROWTH_KIB = 20 * 1024
MAX_SLOWDOWN = 1.5
SETTLE_TIMEOUT = 10.0  # wall s for fds and threads to hold still after the last call
BOX = ('<?xml version="1.0"?><sdf version="1.6"><model name="box"><link name="link"><inertial><mass>0.5</mass>'
       '</inertial><collision name="c"><geometry><box><size>0.2 0.2 0.2</size></box></geometry></collision>'
       '<visual name="v"><geometry><box><size>0.2 0.2 0.2</size></box></geometry></visual></link></model></sdf>')


@dataclass
class Checkpoint:
    done: int  # iterations done
    wall: float  # s since the first call
    rss_kib: int
    fds: int
    threads: int
    tf_listeners: int  # subscribers of /tf and /tf_static at the master
    registrations: int  # the simulator's publications, subscriptions and services at the master
    connections: int  # the simulator's topic connections (its getBusInfo)
    cpu_wait: float  # s its main thread has waited for a CPU so far (schedstat)

    COUNTS = ("fds", "threads", "tf_listeners", "registrations", "connections")


def quick_end(times):
    """The 10th percentile of ``times``: how fast a call is when the machine lets it be."""
    return statistics.quantiles(times, n=10)[0]


def pose(x, y, z):
    return Pose(Point(x, y, z), Quaternion(0.0, 0.0, 0.0, 1.0))


class Process:
    """The simulator's process and node as seen from outside."""

    def __init__(self):
        self.pid = node_pid(SIM, CALLER)
        self.master = rosgraph.Master(CALLER)
        self.node = xmlrpc.client.ServerProxy(self.master.lookupNode(SIM))

    def fds(self):
        return len(os.listdir(f"/proc/{self.pid}/fd"))

    def threads(self):
        return len(os.listdir(f"/proc/{self.pid}/task"))

    def settled(self):
        """(fds, threads) once three readings 50 ms apart agree (a call's connection and thread take a moment to
        go), or the last reading after SETTLE_TIMEOUT."""
        deadline = time.monotonic() + SETTLE_TIMEOUT
        readings = []
        while True:
            readings.append((self.fds(), self.threads()))
            if len(readings) >= 3 and len(set(readings[-3:])) == 1 or time.monotonic() > deadline:
                return readings[-1]
            time.sleep(0.05)

    def sample(self, done, wall):
        fds, threads = self.settled()
        pubs, subs, services = self.master.getSystemState()
        tf = sum(len(nodes) for topic, nodes in subs if topic in ("/tf", "/tf_static"))
        own = sum(SIM in nodes for _, nodes in pubs + subs + services)
        code, _, bus = self.node.getBusInfo(CALLER)
        if code != 1:
            raise AssertionError(f"getBusInfo of {SIM} failed")
        return Checkpoint(done, wall, rss_kib(self.pid), fds, threads, tf, own, len(bus), run_delay(self.pid) or 0.0)


class Resets(unittest.TestCase):
    def test_ten_thousand_resets_and_spawns(self):
        rospy.init_node(CALLER.lstrip("/"))
        iterations = int(rospy.get_param("~iterations", 10000))
        self.assertFalse(rospy.get_param(SIM + "/real_time"), "the leak check runs in fast mode")
        for name in ("reset_simulation", "spawn_sdf_model", "delete_model"):
            rospy.wait_for_service(f"/gazebo/{name}", 30)
        calls = {"reset_simulation": rospy.ServiceProxy("/gazebo/reset_simulation", Empty),
                 "spawn_sdf_model": rospy.ServiceProxy("/gazebo/spawn_sdf_model", SpawnModel),
                 "delete_model": rospy.ServiceProxy("/gazebo/delete_model", DeleteModel)}
        sim = Process()
        every = max(1, iterations // CHECKPOINTS)
        times = {name: [] for name in calls}
        failures = []
        checkpoints = [sim.sample(0, 0.0)]
        started = time.monotonic()
        for k in range(iterations):
            self.iteration(k, calls, times, failures)
            if (k + 1) % every == 0:
                point = sim.sample(k + 1, time.monotonic() - started)
                checkpoints.append(point)
                self.report(point, checkpoints[-2], times, every)
        wall = time.monotonic() - started
        total = sum(len(t) for t in times.values())
        figure(f"resets: {iterations} iterations, {total} calls in {wall:.0f} s ({total / wall:.0f} calls/s, "
               f"{iterations / wall:.1f} iterations/s); RSS by checkpoint (MB): "
               + " ".join(f"{c.rss_kib / 1024:.1f}" for c in checkpoints))
        self.judge(checkpoints, times, failures, every)

    @staticmethod
    def iteration(k, calls, times, failures):
        """One episode's calls: reset, goal spawned, goal deleted (and the box, every BOX_EVERY-th time)."""
        def timed(name, *args):
            begun = time.perf_counter()
            response = calls[name](*args)
            times[name].append(time.perf_counter() - begun)
            if response is not None and hasattr(response, "success") and not response.success:
                failures.append(f"iteration {k}: {name}{args[:1]}: {response.status_message}")
        timed("reset_simulation")
        timed("spawn_sdf_model", "goal", GOAL_MARKER_SDF, "", pose(1.0, 0.5, 0.0), "world")
        timed("delete_model", "goal")
        if k % BOX_EVERY == BOX_EVERY - 1:
            for name, args in (("spawn_sdf_model", ("box", BOX, "", pose(2.0, -1.0, 0.2), "world")),
                               ("delete_model", ("box",))):
                response = calls[name](*args)
                if not response.success:
                    failures.append(f"iteration {k}: {name}('box'): {response.status_message}")

    @staticmethod
    def report(point, previous, times, every):
        window = {name: (statistics.median(t[-every:]) * 1e3, quick_end(t[-every:]) * 1e3) for name, t in times.items()}
        span = point.wall - previous.wall
        waited = 100.0 * (point.cpu_wait - previous.cpu_wait) / span if span > 0 else 0.0
        figure(f"resets checkpoint {point.done}: RSS {point.rss_kib / 1024:.1f} MB, fds {point.fds}, threads "
               f"{point.threads}, TF listeners {point.tf_listeners}, registrations {point.registrations}, "
               f"connections {point.connections}; {3 * every / span:.0f} calls/s; median ms "
               + ", ".join(f"{name} {ms:.2f} (p10 {p10:.2f})" for name, (ms, p10) in window.items())
               + f"; the simulator's loop waited for a CPU {waited:.0f} % of the time")

    def judge(self, checkpoints, times, failures, every):
        self.assertEqual(failures[:5], [], f"{len(failures)} calls failed")
        warm = checkpoints[1]  # the end of the warm-up
        after = checkpoints[1:]
        growth = max(c.rss_kib for c in after) - warm.rss_kib
        self.assertLess(growth, MAX_RSS_GROWTH_KIB,
                        f"the simulator's memory grew {growth / 1024:.1f} MB after the warm-up: RSS (MB) "
                        + " ".join(f"{c.done}:{c.rss_kib / 1024:.1f}" for c in checkpoints))
        for count in Checkpoint.COUNTS:
            values = [getattr(c, count) for c in after]
            self.assertEqual(set(values), {getattr(warm, count)},
                             f"the simulator's {count} changed after the warm-up: "
                             + " ".join(f"{c.done}:{getattr(c, count)}" for c in checkpoints))
        for name, spent in times.items():
            second, last = quick_end(spent[every:2 * every]), quick_end(spent[-every:])
            self.assertLessEqual(last, MAX_SLOWDOWN * second,
                                 f"{name} slowed down: 10th percentile {1e3 * last:.2f} ms over the last {every} "
                                 f"calls, {1e3 * second:.2f} ms over the second {every}")


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "slow_resets", Resets, sys.argv)
