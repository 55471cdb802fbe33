#!/usr/bin/env python3
"""A frozen subscriber (SIGSTOP: connected, reading nothing) cannot stall the simulator.

Publishers are synchronous, so without a guard the loop would block for good in a write once the frozen
process's socket buffers fill (a few seconds in fast mode). bullet_sim gives each connection a send timeout
(~send_timeout, 0.5 s): the frozen subscriber is dropped and the simulation goes on for everybody else.
"""
import os
import signal
import subprocess
import sys
import time
import unittest
import xmlrpc.client

import rosgraph
import rospy
import rostest
from rosgraph_msgs.msg import Clock
from simtest import figure

SUBSCRIBER = """
import rosgraph
import rospy
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage
rospy.init_node("frozen", anonymous=True)
for topic, cls in (("/odom", Odometry), ("/joint_states", JointState), ("/tf", TFMessage)):
    rospy.Subscriber(topic, cls, lambda m: None, queue_size=1)
print("subscribed", flush=True)
rospy.spin()
"""


#: s wall: sim time (fast mode) stuck this long while the frozen subscriber is connected is the stall this suite
#: guards against (without the send timeout the loop blocks in a write for good); a starved machine still
#: advances it every second or two.
STALL_WALL = 20.0
#: s wall: the frozen subscriber's buffers fill after a fixed amount of published data, i.e. of sim time (about
#: 180 sim s here, 10 s of wall time on an idle machine, 56 s at a quarter of a core): a hang guard only.
DROP_TIMEOUT = 300.0
ADVANCE_TIMEOUT = 60.0  # s wall for 5 s of fast-mode sim time after the drop (a hang guard; 2 s on an idle machine)


class StalledSubscriberTest(unittest.TestCase):
    def _frozen_links(self):
        """The simulator's open connections to the frozen node, from its getBusInfo."""
        _, _, info = self.sim.getBusInfo("/test_stalled")
        return [c for c in info if c[1].startswith("/frozen") and c[5]]

    def _wait(self, predicate, timeout, what, clock=None):
        """Poll ``predicate``; with ``clock`` (the /clock stamps received) also fail as soon as sim time has
        not advanced for STALL_WALL s: the simulator is stalled, whatever the wall deadline says."""
        started = time.monotonic()
        deadline = started + timeout
        seen, seen_at = (clock[-1], started) if clock else (None, None)
        while time.monotonic() < deadline:
            value = predicate()
            if value:
                return value
            if clock:
                if clock[-1] != seen:
                    seen, seen_at = clock[-1], time.monotonic()
                elif time.monotonic() - seen_at > STALL_WALL:
                    self.fail(f"the simulator stalled: sim time stuck at {seen:.2f} s for {STALL_WALL:g} s of wall "
                              f"time while waiting for {what}; simulator connections: {self._connections()}")
            time.sleep(0.05)
        progress = f"; sim time advanced {clock[-1] - clock[0]:.1f} s in all" if clock else ""
        self.fail(f"timed out after {timeout} s waiting for {what}{progress}; simulator connections: "
                  + self._connections())

    def _connections(self):
        _, _, info = self.sim.getBusInfo("/test_stalled")
        return "; ".join(f"{c[1]} {c[4]} {'up' if c[5] else 'down'}" for c in info)

    def test_frozen_subscriber_is_dropped_and_the_sim_goes_on(self):
        rospy.init_node("test_stalled")
        clock = []
        rospy.Subscriber("/clock", Clock, lambda m: clock.append(m.clock.to_sec()), queue_size=100)
        deadline = time.monotonic() + 30.0
        while not clock and time.monotonic() < deadline:
            time.sleep(0.05)
        self.assertTrue(clock, "no /clock from the simulator")
        self.sim = xmlrpc.client.ServerProxy(rosgraph.Master("/test_stalled").lookupNode("/bullet_sim"))
        proc = subprocess.Popen([sys.executable, "-c", SUBSCRIBER], stdout=subprocess.PIPE, text=True)
        try:
            self.assertEqual(proc.stdout.readline().strip(), "subscribed")
            self._wait(lambda: {"/odom", "/joint_states", "/tf"} <= {c[4] for c in self._frozen_links()}, 60.0,
                       "the frozen-to-be node connected on /odom, /joint_states and /tf")
            os.kill(proc.pid, signal.SIGSTOP)
            frozen_at, frozen_sim = time.monotonic(), clock[-1]
            # Its socket buffers fill after some sim seconds of fast-mode publishing; then a write times out
            # (~send_timeout) and rospy closes that connection. Without the guard it never happens: the loop
            # blocks in a write, and sim time stops (which _wait reports as the stall it is).
            # (/clock, 8 bytes a message, would take minutes to fill a buffer: only the big topics count.)
            big = {"/odom", "/joint_states", "/tf"}
            self._wait(lambda: not big & {c[4] for c in self._frozen_links()}, DROP_TIMEOUT,
                       "the simulator to drop the frozen subscriber's odom, joint_states and tf connections", clock)
            dropped, dropped_sim = time.monotonic() - frozen_at, clock[-1] - frozen_sim
            start = clock[-1]
            self._wait(lambda: clock[-1] >= start + 5.0, ADVANCE_TIMEOUT, "sim time to advance 5 s after the drop",
                       clock)
            figure(f"stalled: frozen subscriber dropped {dropped:.1f} s ({dropped_sim:.1f} s of sim time) after "
                   f"SIGSTOP; sim time then advanced {clock[-1] - start:.1f} s")
        finally:
            os.kill(proc.pid, signal.SIGCONT)
            proc.kill()
            proc.wait()


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "stalled", StalledSubscriberTest, sys.argv)
