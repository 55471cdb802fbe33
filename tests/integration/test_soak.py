#!/usr/bin/env python3
"""Soak (slow_soak.test): one simulated hour in fast mode (``real_time:=false``) while the robot drives a
changing pattern and the world is reset (reset_world: sim time goes on) every 10 sim minutes.

Checked: bullet_sim's resident memory (VmRSS of the pid it reports over XML-RPC) grows by < 5 MB between the
end of a 60 s warm-up and the end of the hour; odom stamps strictly increase; /clock never goes back (strictly
increasing); every odom message is finite; the simulator's log file (its ``__log:=`` argument) gains at most
a few WARN/ERROR records, and none are published on /rosout either. Figures (wall time, RTF, RSS start/end,
message counts) are logged as FIGURE lines.
"""
import re
import sys
import threading
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock, Log
from simtest import SIM, alive, figure, finite_odom, node_pid, rss_kib
from std_srvs.srv import Empty

from diffbot_sim import waiting

SIM_SECONDS = 3600.0
WARM_UP = 60.0  # sim s before the memory baseline
RESET_EVERY = 600.0  # sim s
PHASE = 10.0  # sim s per command of the pattern
PATTERN = [(0.3, 0.5), (0.2, -0.4), (0.0, 1.0), (-0.2, 0.3), (0.5, 0.0), (-0.5, 0.0), (0.0, 0.0)]
MAX_RSS_GROWTH_KIB = 5 * 1024
MAX_WARNINGS = 3  # WARN/ERROR records the sim may log during the hour
WALL_LIMIT = 480.0  # s for the simulated hour (the runner kills a suite at 600 s)
LOG_RECORD = re.compile(r"^\[[^\]]*\]\[(WARN|WARNING|ERROR|FATAL|CRITICAL)\]")


class Monotonic:
    """Subscriber callback target: counts messages and stamps that fail to increase (checked as they arrive)."""

    def __init__(self, stamp_of, strict=True, check=None):
        self.lock = threading.Lock()
        self.stamp_of, self.strict, self.check = stamp_of, strict, check
        self.count = 0
        self.last = None
        self.bad = []  # (previous, this) of the first few violations
        self.bad_count = 0
        self.invalid = 0

    def __call__(self, msg):
        stamp = self.stamp_of(msg)
        with self.lock:
            self.count += 1
            if self.last is not None and (stamp <= self.last if self.strict else stamp < self.last):
                self.bad_count += 1
                if len(self.bad) < 5:
                    self.bad.append((self.last, stamp))
            self.last = stamp
            if self.check is not None and not self.check(msg):
                self.invalid += 1


class SoakTest(unittest.TestCase):
    def test_one_simulated_hour(self):
        rospy.init_node("test_soak")
        odom = Monotonic(lambda m: m.header.stamp.to_nsec(), check=finite_odom)
        clock = Monotonic(lambda m: m.clock.to_nsec())
        rosout = []
        rospy.Subscriber("/odom", Odometry, odom, queue_size=10000)
        rospy.Subscriber("/clock", Clock, clock, queue_size=10000)
        rospy.Subscriber("/rosout", Log, lambda m: rosout.append(m) if m.name == SIM and m.level >= Log.WARN
                         else None, queue_size=1000)
        cmd = rospy.Publisher("/cmd_vel", Twist, queue_size=10)
        rospy.wait_for_service(SIM + "/reset_world", timeout=30.0)
        reset = rospy.ServiceProxy(SIM + "/reset_world", Empty)
        self.assertFalse(rospy.get_param(SIM + "/real_time"), "the soak runs in fast mode")
        pid = node_pid(SIM)
        log_path = self.log_file(pid)

        def sim_now():
            with odom.lock:
                return odom.last / 1e9 if odom.last is not None else 0.0

        def wait(predicate, timeout, what):
            return waiting.wait_for(predicate, timeout, what, 0.05, error=self.failureException,
                                    give_up=lambda: not alive(pid) and "bullet_sim died")

        wait(lambda: cmd.get_num_connections() > 0 and odom.count > 0, 30.0, "the simulator")
        started = time.monotonic()
        phase = None
        next_reset = RESET_EVERY
        resets = 0
        rss_start = None
        rss_max = 0
        last_sample = 0.0
        warnings_at_start = None
        sim_start = sim_now()
        while True:
            now = sim_now()
            if now >= SIM_SECONDS:
                break
            self.assertTrue(alive(pid), f"bullet_sim died at sim time {now:.1f} s")
            self.assertLess(time.monotonic() - started, WALL_LIMIT,
                            f"the simulated hour did not finish within {WALL_LIMIT} s (reached {now:.0f} s)")
            index = int(now // PHASE) % len(PATTERN)
            if index != phase:
                phase = index
                msg = Twist()
                msg.linear.x, msg.angular.z = PATTERN[index]
                cmd.publish(msg)
            if now >= next_reset:
                reset()
                resets += 1
                next_reset += RESET_EVERY
            if rss_start is None and now >= WARM_UP:
                rss_start = rss_kib(pid)
                warnings_at_start = self.count_warnings(log_path)
            if rss_start is not None and time.monotonic() - last_sample >= 1.0:
                rss_max = max(rss_max, rss_kib(pid))
                last_sample = time.monotonic()
            time.sleep(0.02)
        wall = time.monotonic() - started
        rss_end = rss_kib(pid)
        rss_max = max(rss_max, rss_end)
        records = self.warning_records(log_path)
        growth = rss_end - rss_start
        figure(f"soak: {SIM_SECONDS:.0f} sim s in {wall:.0f} s wall (RTF {(sim_now() - sim_start) / wall:.1f}), "
               f"{resets} resets")
        figure(f"soak: bullet_sim VmRSS {rss_start / 1024:.1f} MiB after the {WARM_UP:.0f} s warm-up, "
               f"{rss_end / 1024:.1f} MiB at the end (growth {growth / 1024:+.2f} MiB, max {rss_max / 1024:.1f} MiB)")
        figure(f"soak: {odom.count} odom and {clock.count} /clock messages received; stamps going back: odom "
               f"{odom.bad_count}, clock {clock.bad_count}; non-finite odom {odom.invalid}")
        figure(f"soak: WARN/ERROR records in {log_path}: {len(records)} in all, "
               f"{len(records) - warnings_at_start} during the hour; on /rosout: {len(rosout)}")
        for line in records[:10]:
            print("  " + line)
        self.assertLess(growth, MAX_RSS_GROWTH_KIB, "bullet_sim memory grew")
        self.assertEqual(odom.bad_count, 0, f"odom stamps not strictly increasing: {odom.bad}")
        self.assertEqual(clock.bad_count, 0, f"/clock not strictly increasing: {clock.bad}")
        self.assertEqual(odom.invalid, 0)
        # The subscribers kept up with most of it (100 Hz each): the checks above saw the hour, not a sample.
        self.assertGreater(odom.count, 0.5 * 100 * SIM_SECONDS)
        self.assertGreater(clock.count, 0.5 * 100 * SIM_SECONDS)
        self.assertLessEqual(len(records) - warnings_at_start, MAX_WARNINGS, "\n".join(records[-10:]))
        self.assertLessEqual(len([m for m in rosout if m.header.stamp.to_sec() >= WARM_UP]), MAX_WARNINGS)
        self.assertEqual(node_pid(SIM), pid, "bullet_sim was restarted")

    @staticmethod
    def log_file(pid):
        """The node's own log file: the ``__log:=`` argument roslaunch gave it."""
        with open(f"/proc/{pid}/cmdline") as f:
            args = f.read().split("\0")
        for arg in args:
            if arg.startswith("__log:="):
                return arg[len("__log:="):]
        raise AssertionError(f"bullet_sim has no __log:= argument: {args}")

    @staticmethod
    def warning_records(path):
        with open(path, errors="replace") as f:
            return [line.rstrip() for line in f if LOG_RECORD.match(line)]

    def count_warnings(self, path):
        return len(self.warning_records(path))


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "soak", SoakTest, sys.argv)
