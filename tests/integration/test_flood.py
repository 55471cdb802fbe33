#!/usr/bin/env python3
"""Flood (slow_flood.test): three processes publish /cmd_vel at up to 5 kHz each for 30 s while the simulator
runs in real-time mode.

Checked: the real-time factor during the flood (from /clock against the wall clock) stays >= 0.95; the
simulator's resident memory (VmRSS of the pid the node reports over XML-RPC) grows by < 10 MB; a command
applied later (``~debug/cmd_applied``) is never older than one applied earlier from the same flooder; after
the flood, the newest of a burst of distinct commands is the one left applied, and it reached the motors
within one physics step (+ a small margin) of being published; the robot then moves as that command says.
The figures (achieved publish rate, RTF, RSS growth, latency) are logged as FIGURE lines.
"""
import json
import os
import signal
import statistics
import subprocess
import sys
import threading
import time
import unittest
import xmlrpc.client

import rosgraph
import rospy
import rostest
from geometry_msgs.msg import TwistStamped
from rosgraph_msgs.msg import Clock
from simtest import SIM, Recorder, alive, figure, node_pid, rss_kib

FLOODERS = 3
RATE = 5000.0  # Hz per flooder (target; the achieved rate is measured and reported)
DURATION = 30.0  # s of flood, wall clock
MIN_RTF = 0.95
MAX_RSS_GROWTH_KIB = 10 * 1024
STEP = 1.0 / 240.0  # s, the simulator's default physics step (checked against ~time_step)
LATENCY_MARGIN = 0.002  # s on top of one step: publish -> TCP -> subscriber thread -> loop wake
SEQ_SCALE = 1e-7  # flood_cmd_vel.py: angular.z = seq * SEQ_SCALE, linear.x = 0.2 + 0.01 * id
HERE = os.path.dirname(os.path.abspath(__file__))


class Flooder:
    """One flood_cmd_vel.py process in its own session; a thread collects its stdout lines."""

    def __init__(self, ident):
        self.ident = ident
        self.lines = []
        self.proc = subprocess.Popen(
            [sys.executable, os.path.join(HERE, "flood_cmd_vel.py"), str(ident), str(RATE), str(DURATION),
             f"__name:=flood_{ident}"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
            start_new_session=True)
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        for line in self.proc.stdout:
            self.lines.append(line.rstrip("\n"))

    def ready(self):
        return "READY" in self.lines

    def go(self):
        self.proc.stdin.write("go\n")
        self.proc.stdin.flush()

    def result(self):
        for line in self.lines:
            if line.startswith("{"):
                return json.loads(line)
        return None

    def stop(self):
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
        self.proc.wait(10.0)


class FloodTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_flood")
        cls.rec = rec = Recorder()
        cls.applied = []  # (receipt monotonic, TwistStamped)
        cls.applied_lock = threading.Lock()
        cls.debug_sub = rospy.Subscriber(SIM + "/debug/cmd_applied", TwistStamped, cls._on_applied,
                                         queue_size=10000)
        rec.wait_connected()
        rec.wait(lambda: cls.debug_sub.get_num_connections() > 0, 20.0, "the ~debug/cmd_applied publisher")
        cls.pid = node_pid(SIM)
        cls.flooders = []
        try:
            cls._flood()
        finally:
            for flooder in cls.flooders:
                flooder.stop()

    @classmethod
    def _on_applied(cls, msg):
        with cls.applied_lock:
            cls.applied.append((time.monotonic(), msg))

    @classmethod
    def applied_since(cls, t):
        with cls.applied_lock:
            return [m for r, m in cls.applied if r >= t]

    @classmethod
    def _rtf(cls, since, until):
        """Sim seconds per wall second from the /clock messages received in [since, until] (monotonic)."""
        clocks = [(r, m.clock.to_sec()) for r, m in list(cls.clock_log) if since <= r <= until]
        if len(clocks) < 2:
            raise AssertionError(f"only {len(clocks)} /clock messages between {since:.1f} and {until:.1f}")
        return (clocks[-1][1] - clocks[0][1]) / (clocks[-1][0] - clocks[0][0])

    @classmethod
    def _flood(cls):
        rec = cls.rec
        cls.clock_log = []  # (receipt monotonic, Clock): the Recorder keeps no receipt times
        cls.clock_sub = rospy.Subscriber("/clock", Clock, lambda m: cls.clock_log.append((time.monotonic(), m)),
                                         queue_size=1000)
        rec.wait(lambda: len(cls.clock_log) > 10, 20.0, "/clock")
        # Warm-up, and the real-time factor with no flood, for comparison.
        idle_start = time.monotonic()
        rec.wait(lambda: time.monotonic() - idle_start >= 5.0 and alive(cls.pid), 10.0, "5 s of idle running")
        cls.idle_rtf = cls._rtf(idle_start, time.monotonic())
        cls.rss_before = rss_kib(cls.pid)
        cls.flooders = [Flooder(i) for i in range(1, FLOODERS + 1)]
        rec.wait(lambda: all(f.ready() or f.proc.poll() is not None for f in cls.flooders), 60.0,
                 "the flooders to connect")
        for f in cls.flooders:
            if not f.ready():
                raise AssertionError(f"flooder {f.ident} did not start: {f.lines}")
        cls.flood_start = time.monotonic()
        for f in cls.flooders:
            f.go()
        cls.rss_max = cls.rss_before
        samples = []
        deadline = cls.flood_start + DURATION + 30.0
        while any(f.proc.poll() is None for f in cls.flooders):
            if time.monotonic() > deadline:
                raise AssertionError("the flooders did not finish within 30 s of the end of the flood")
            if time.monotonic() < cls.flood_start + DURATION:
                rss = rss_kib(cls.pid)
                samples.append(rss)
                cls.rss_max = max(cls.rss_max, rss)
            time.sleep(0.05)
        cls.flood_end = min(time.monotonic(), cls.flood_start + DURATION)
        cls.rss_after = samples[-1] if samples else rss_kib(cls.pid)
        cls.results = [f.result() for f in cls.flooders]
        cls.exit_codes = [f.proc.returncode for f in cls.flooders]
        cls.outputs = [f.lines for f in cls.flooders]
        cls.flood_rtf = cls._rtf(cls.flood_start + 0.5, cls.flood_end)

    # -- checks --------------------------------------------------------------------------------------------

    def test_1_flooders_ran(self):
        for code, result, lines in zip(self.exit_codes, self.results, self.outputs):
            self.assertEqual(code, 0, lines)
            self.assertIsNotNone(result, lines)
            self.assertNotIn("error", result)
        rates = [r["rate"] for r in self.results]
        figure(f"flood: {FLOODERS} publishers x {DURATION:.0f} s, target {RATE:.0f} Hz each; achieved "
               + ", ".join(f"{r:.0f}" for r in rates) + f" Hz (total {sum(rates):.0f} Hz, "
               f"{sum(r['sent'] for r in self.results)} messages)")
        # The flood is a flood: each publisher reached at least a tenth of the target.
        for rate in rates:
            self.assertGreater(rate, RATE / 10)

    def test_2_real_time_factor(self):
        figure(f"flood: RTF {self.flood_rtf:.4f} during the flood (idle before: {self.idle_rtf:.4f})")
        self.assertGreaterEqual(self.flood_rtf, MIN_RTF)
        self.assertLess(self.flood_rtf, 1.05, "real-time mode must not run ahead of the wall clock")

    def test_3_memory(self):
        growth = self.rss_after - self.rss_before
        figure(f"flood: bullet_sim VmRSS {self.rss_before / 1024:.1f} MiB before, {self.rss_after / 1024:.1f} MiB "
               f"at the end, max {self.rss_max / 1024:.1f} MiB; growth {growth / 1024:+.2f} MiB "
               f"(max {(self.rss_max - self.rss_before) / 1024:+.2f} MiB)")
        self.assertLess(self.rss_max - self.rss_before, MAX_RSS_GROWTH_KIB)

    def test_4_never_an_older_command_after_a_newer_one(self):
        applied = self.applied_since(self.flood_start)
        last_seq = {}
        per_flooder = {i: 0 for i in range(1, FLOODERS + 1)}
        for msg in applied:
            ident = round((msg.twist.linear.x - 0.2) / 0.01)
            if ident not in per_flooder or abs(msg.twist.linear.x - (0.2 + 0.01 * ident)) > 1e-12:
                continue  # not a flood command (e.g. the final burst below)
            seq = round(msg.twist.angular.z / SEQ_SCALE)
            self.assertGreater(seq, last_seq.get(ident, 0), f"flooder {ident}: seq {seq} applied after a newer one")
            last_seq[ident] = seq
            per_flooder[ident] += 1
        steps = (self.flood_end - self.flood_start) * 240
        figure(f"flood: commands applied during the flood per flooder {per_flooder} "
               f"(about {steps:.0f} physics steps)")
        for ident, count in per_flooder.items():
            self.assertGreater(count, 0, f"no command of flooder {ident} was ever applied")
        # In real time a command that wakes the loop is applied at once, between steps; only the newest
        # pending one is taken each time, so the simulator applies a fraction of what arrives.
        sent = sum(r["sent"] for r in self.results)
        self.assertLess(sum(per_flooder.values()), sent / 2, "the simulator applied most arriving commands one by one")

    def test_5_newest_command_wins_within_one_step(self):
        rec = self.rec
        self.assertAlmostEqual(rospy.get_param(SIM + "/time_step"), STEP, places=9)
        self.assertTrue(rospy.get_param(SIM + "/real_time"))
        # The flooders are gone, and so are their connections in the simulator (their last bytes read).
        sim_uri = rosgraph.Master("/test_flood").lookupNode(SIM)
        sim = xmlrpc.client.ServerProxy(sim_uri)

        def flood_connections():
            _, _, info = sim.getBusInfo("/test_flood")
            return [c for c in info if c[4] == "/cmd_vel" and c[1].startswith("/flood_") and c[5]]
        rec.wait(lambda: not flood_connections(), 20.0, "the flooders' connections to close")
        # A burst of distinct commands, published back to back: the last one must be the one applied last.
        burst = [(0.30 + i * 1e-4, -0.20 - i * 1e-4) for i in range(20)]
        start = time.monotonic()
        for linear, angular in burst:
            rec.send(linear, angular)
            sent_wall = time.time()
        final = burst[-1]

        def final_applied():
            for m in self.applied_since(start):
                if (m.twist.linear.x, m.twist.angular.z) == final:
                    return m
            return None
        applied_final = rec.wait(final_applied, 10.0, "the final command on ~debug/cmd_applied")
        delay = applied_final.header.stamp.to_sec() - sent_wall
        # Nothing older is applied after it: wait half a sim second, then look at everything applied.
        rec.wait_sim(0.5)
        seen = [(m.twist.linear.x, m.twist.angular.z) for m in self.applied_since(start)]
        order = [burst.index(v) for v in seen if v in burst]
        self.assertEqual(len(order), len(seen), f"applied something not in the burst: {seen}")
        self.assertEqual(order, sorted(set(order)), "burst commands applied out of order")
        self.assertEqual(seen[-1], final, "the last command applied is the last one sent")
        # Latency of single commands, one at a time, for the figure (each waits for its own application).
        delays = [delay]
        for i in range(20):
            values = (0.25 + i * 1e-4, 0.15 + i * 1e-4)
            t0 = time.monotonic()
            rec.send(*values)
            sent = time.time()
            msg = rec.wait(lambda: next((m for m in self.applied_since(t0)
                                         if (m.twist.linear.x, m.twist.angular.z) == values), None),
                           10.0, f"command {values} applied")
            delays.append(msg.header.stamp.to_sec() - sent)
        ms = sorted(d * 1000 for d in delays)
        figure(f"flood: publish -> applied to the motors after the flood: burst final {delay * 1000:.2f} ms; "
               f"single commands median {statistics.median(ms):.2f} ms, max {ms[-1]:.2f} ms (n={len(ms)}); "
               f"one step is {STEP * 1000:.2f} ms")
        self.assertGreaterEqual(delay, -0.0005, "applied before it was sent? clocks disagree")
        self.assertLessEqual(delay, STEP + LATENCY_MARGIN, "the final command waited more than one step")
        self.assertLessEqual(statistics.median(ms) / 1000, STEP + LATENCY_MARGIN)
        # And it takes effect: the robot drives as the last single command says.
        values = (0.25 + 19 * 1e-4, 0.15 + 19 * 1e-4)
        end = rec.odom_after(rec.sim_time() + 2.0)
        self.assertAlmostEqual(end.twist.twist.linear.x, values[0], delta=0.02)
        self.assertAlmostEqual(end.twist.twist.angular.z, values[1], delta=0.05)

    def test_6_simulator_survived(self):
        self.assertTrue(alive(self.pid), "bullet_sim is gone")
        self.assertEqual(node_pid(SIM), self.pid, "bullet_sim was restarted")
        t = self.rec.sim_time()
        self.rec.odom_after(t + 0.5, timeout=10.0)


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "flood", FloodTest, sys.argv)
