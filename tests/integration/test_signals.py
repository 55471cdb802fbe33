#!/usr/bin/env python3
"""Signals (signals.test): SIGINT and SIGTERM end ``bullet_sim`` within 2 s and leave nothing behind; a teleop
killed with SIGKILL (no chance to publish a stop) while the robot moves does not leave it running when
``~cmd_vel_timeout`` is set.

The 2 s are the process's own time: the wall time from the signal to its end less the time it waited for a
CPU (simtest.CpuWait, from the kernel's schedstat): on an idle machine the wall time, on a loaded one the part
that is the process's doing.

Each case starts its own ``rosrun diffbot_sim bullet_sim`` in a new session against the rostest master
(rosrun execs the node, so the child's pid is the node's, which getPid confirms), waits until it publishes,
and signals it while the robot drives. "Nothing behind" means: no live process left in its session, and its
topics and services gone from the master.
"""
import os
import pty
import signal
import subprocess
import sys
import tempfile
import time
import unittest
import xmlrpc.client

import rosgraph
import rospkg
import rospy
import rostest
from geometry_msgs.msg import Twist
from simtest import CpuWait, Recorder, alive, exited, figure, node_pid, session_pids, sim_now
from test_teleop_pty import READY_TEXT, PtyReader

PKG = "diffbot_sim"
MODEL = os.path.join(rospkg.RosPack().get_path(PKG), "urdf", "diffbot.urdf.xacro")
EXIT_BOUND = 2.0  # s of the process's own time from the signal to the process being gone
HANG_WALL = 60.0  # s wall: a process still running then after a signal has hung, whatever the machine
START_TIMEOUT = 60.0  # s: rosrun + imports + xacro + PyBullet on a 4x slower machine
MOTION_TIMEOUT = 30.0  # s wall: a command or a stop shows in odometry (milliseconds on an idle machine)
TIMEOUT = 0.5  # s, ~cmd_vel_timeout of the teleop case


class SignalTest(unittest.TestCase):
    count = 0

    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_signals")
        cls.rec = Recorder()
        cls.master = rosgraph.Master("/test_signals")
        cls.twists = []  # (monotonic receipt, linear.x, angular.z) of every /cmd_vel message
        cls.twist_sub = rospy.Subscriber("/cmd_vel", Twist, lambda m: cls.twists.append(
            (time.monotonic(), m.linear.x, m.angular.z)))

    def setUp(self):
        self.procs = []
        self.readers = []
        self.fds = []

    def tearDown(self):
        for proc in self.procs:
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait(10.0)
        for reader in self.readers:
            reader.halt()
        for fd in self.fds:
            os.close(fd)

    # -- helpers -------------------------------------------------------------------------------------------

    def start_sim(self, *params):
        """A bullet_sim of its own name in a new session; returns (proc, name, log) once it publishes odom."""
        SignalTest.count += 1
        name = f"/sig_sim_{self.count}"
        log = tempfile.TemporaryFile(mode="w+")
        proc = subprocess.Popen(["rosrun", PKG, "bullet_sim", f"__name:={name[1:]}", f"_model:={MODEL}", *params],
                                stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                                start_new_session=True)
        self.procs.append(proc)
        self.rec.clear()

        def publishing():
            if proc.poll() is not None:
                raise AssertionError(f"{name} exited during start-up: {self.read(log)}")
            return self.rec.last(self.rec.odom) is not None and self.publishes(name, "/odom")
        self.rec.wait(publishing, START_TIMEOUT, f"{name} to publish odom")
        self.assertEqual(node_pid(name), proc.pid, "rosrun did not exec the node: the signal would miss it")
        return proc, name, log

    def publishes(self, node, topic):
        pubs, _, _ = self.master.getSystemState()
        return any(t == topic and node in nodes for t, nodes in pubs)

    def listed(self, node):
        """True while ``node`` has a publication, subscription or service on the master (``rosnode list``).

        Not lookupNode: rospy's log handler subscribes /rosout_disable_topics_generation as a parameter
        (get_param_cached) and never unsubscribes, so the master keeps every rospy node's URI forever.
        """
        return any(node in nodes for group in self.master.getSystemState() for _, nodes in group)

    @staticmethod
    def read(log):
        log.seek(0)
        return log.read()[-3000:]

    def signal_case(self, sig, *params):
        proc, name, log = self.start_sim(*params)
        # The robot is driving when the signal comes (re-sent until seen: our publisher connects to each new sim).
        self.rec.wait(lambda: self.rec.send(0.3, 0.5) and self.rec.last(self.rec.odom).twist.twist.linear.x > 0.1,
                      MOTION_TIMEOUT, "the robot to move")
        members = session_pids(proc.pid)
        waits = CpuWait(proc.pid)
        sent = time.monotonic()
        os.kill(proc.pid, sig)
        deadline = sent + HANG_WALL
        polls = 0
        while not exited(proc.pid) and time.monotonic() < deadline:
            polls += 1
            waits.sample(rescan=polls % 25 == 0)  # the known pids every 2 ms, new descendants every 50 ms
            time.sleep(0.002)
        elapsed = time.monotonic() - sent
        waits.sample()  # the ended process's figures, before it is reaped
        code = proc.poll()
        own = waits.own(elapsed)
        left = session_pids(proc.pid)
        mode = "fast" if "_real_time:=false" in params else "real-time"
        figure(f"signals: {sig.name} -> bullet_sim ({mode}) gone after {elapsed * 1000:.0f} ms ({own * 1000:.0f} ms "
               f"of its own, {waits.waited() * 1000:.0f} ms waiting for a CPU), exit status {code}, "
               f"session had {len(members)} process(es), {len(left)} left")
        output = self.read(log)
        self.assertIsNotNone(code, f"{name} still running {HANG_WALL:g} s after {sig.name}\n{output}")
        self.assertLess(own, EXIT_BOUND, f"{name} took {own:.2f} s of its own to exit after {sig.name} "
                        f"({elapsed:.2f} s wall, {waits.waited():.2f} s of it waiting for a CPU)\n{output}")
        self.assertEqual(left, [], f"processes left in the session of {name}")
        self.assertFalse(alive(proc.pid))
        self.assertIn(code, (0, -sig), f"exit status after {sig.name}\n{output}")
        self.assertNotIn("Traceback", output)
        self.rec.wait(lambda: not self.listed(name), MOTION_TIMEOUT,
                      f"{name}'s topics and services to leave the master")

    # -- cases ---------------------------------------------------------------------------------------------

    def test_sigint_real_time(self):
        self.signal_case(signal.SIGINT)

    def test_sigterm_real_time(self):
        self.signal_case(signal.SIGTERM)

    def test_sigint_fast_mode(self):
        self.signal_case(signal.SIGINT, "_real_time:=false")

    def test_sigterm_fast_mode(self):
        self.signal_case(signal.SIGTERM, "_real_time:=false")

    def test_teleop_sigkill_with_timeout_stops_robot(self):
        """SIGKILL gives the teleop no chance to publish its stop: the simulator's timeout has to brake."""
        rec = self.rec
        proc, name, log = self.start_sim(f"_cmd_vel_timeout:={TIMEOUT}")
        self.assertEqual(rospy.get_param(name + "/cmd_vel_timeout"), TIMEOUT)
        master, slave = pty.openpty()
        self.fds += [master, slave]
        reader = PtyReader(master)
        reader.start()
        self.readers.append(reader)
        teleop_name = f"/sig_teleop_{self.count}"
        # Repeating at 10 Hz keeps a live teleop's command fresh, so a stop can only come from the kill.
        teleop = subprocess.Popen(["rosrun", PKG, "teleop_key", f"__name:={teleop_name[1:]}", "_speed:=0.5",
                                   "_repeat_rate:=10"],
                                  stdin=slave, stdout=slave, stderr=slave, start_new_session=True, close_fds=True)
        self.procs.append(teleop)
        rec.wait(lambda: READY_TEXT in reader.output() or teleop.poll() is not None, START_TIMEOUT,
                 "the teleop's ready banner")
        self.assertIsNone(teleop.poll(), reader.output()[-1500:])
        rec.wait(lambda: self.sends_to(teleop_name, name), START_TIMEOUT, "the teleop to connect to the simulator")
        os.write(master, b"i")
        rec.wait(lambda: rec.last(rec.odom).twist.twist.linear.x > 0.45, MOTION_TIMEOUT, "the robot to reach 0.5 m/s")
        # Still driving well past the timeout: the teleop's repeats keep the command fresh.
        moving_from = rec.sim_time()
        rec.wait_sim(3 * TIMEOUT, timeout=MOTION_TIMEOUT)
        window = [m for m in rec.snapshot(rec.odom) if m.header.stamp.to_sec() >= moving_from]
        self.assertGreater(min(m.twist.twist.linear.x for m in window), 0.4, "the robot stopped while the teleop lived")
        # The simulator's own time just before the kill: the newest odom this node has received may be older
        # (on a loaded machine it queues up), which would add its age to the stop's delay.
        killed_sim = sim_now()
        os.killpg(teleop.pid, signal.SIGKILL)
        killed_wall = time.monotonic()
        teleop.wait(10.0)
        self.assertEqual(teleop.returncode, -signal.SIGKILL)

        def stopped():
            """The first odom after the kill showing the robot still (not the newest one received: several
            may arrive at once on a loaded machine)."""
            return next((m for m in rec.snapshot(rec.odom) if m.header.stamp.to_sec() >= killed_sim
                         and abs(m.twist.twist.linear.x) < 0.01 and abs(m.twist.twist.angular.z) < 0.01), None)
        stop = rec.wait(stopped, MOTION_TIMEOUT, "the robot to stop after the teleop was killed")
        stop_after = stop.header.stamp.to_sec() - killed_sim
        # It stays stopped: one more sim second, no motion.
        rec.wait_sim(1.0)
        later = rec.last(rec.odom)
        drift = abs(later.pose.pose.position.x - stop.pose.pose.position.x)
        zeros = [t for t in self.twists if t[0] >= killed_wall - 0.2 and t[1] == 0.0 and t[2] == 0.0]
        figure(f"signals: teleop SIGKILLed at 0.5 m/s with cmd_vel_timeout {TIMEOUT} s: robot stopped "
               f"{stop_after:.2f} s (sim) later, drift {drift * 1000:.1f} mm over the next sim second")
        self.assertEqual(zeros, [], "the killed teleop published a stop: this case would prove nothing")
        self.assertLess(stop_after, TIMEOUT + 1.0, "timeout + braking (0.5 m/s at 1.8 m/s^2 is 0.3 s)")
        self.assertGreater(stop_after, TIMEOUT * 0.5, "stopped before the command could be stale")
        self.assertLess(drift, 0.005)
        self.assertTrue(alive(proc.pid), "the simulator died")
        self.assertEqual(session_pids(teleop.pid), [], "processes left in the teleop's session")

    def sends_to(self, node, dest):
        """True once ``node``'s /cmd_vel publisher lists a connection to ``dest`` (its bus info)."""
        try:
            uri = self.master.lookupNode(node)
            _, _, info = xmlrpc.client.ServerProxy(uri).getBusInfo("/test_signals")
        except (rosgraph.MasterError, OSError, xmlrpc.client.Error):
            return False
        return any(c[2] == "o" and c[4] == "/cmd_vel" and c[1] == dest for c in info)


if __name__ == "__main__":
    rostest.rosrun(PKG, "signals", SignalTest, sys.argv)
