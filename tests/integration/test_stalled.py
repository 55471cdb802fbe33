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

import rospy
import rostest
from rosgraph_msgs.msg import Clock

from simtest import figure

SUBSCRIBER = """
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


class StalledSubscriberTest(unittest.TestCase):
    def test_frozen_subscriber_is_dropped_and_the_sim_goes_on(self):
        rospy.init_node("test_stalled")
        clock = []
        rospy.Subscriber("/clock", Clock, lambda m: clock.append((time.monotonic(), m.clock.to_sec())),
                         queue_size=100)
        proc = subprocess.Popen([sys.executable, "-c", SUBSCRIBER], stdout=subprocess.PIPE, text=True)
        try:
            self.assertEqual(proc.stdout.readline().strip(), "subscribed")
            deadline = time.monotonic() + 20
            while time.monotonic() < deadline and not clock:
                time.sleep(0.05)
            self.assertTrue(clock, "no /clock from the simulator")
            time.sleep(2.0)  # the frozen process is connected and receiving by now
            os.kill(proc.pid, signal.SIGSTOP)
            frozen_at = time.monotonic()
            # Long enough to fill its socket buffers many times over at fast-mode rates.
            time.sleep(12.0)
            recent = [(w, s) for w, s in clock if w > time.monotonic() - 3.0]
            self.assertGreater(len(recent), 10, "the simulator stopped publishing /clock")
            advanced = recent[-1][1] - recent[0][1]
            figure(f"stalled: sim time advanced {advanced:.1f} s in the last 3 s wall, "
                   f"{time.monotonic() - frozen_at:.0f} s after SIGSTOP")
            self.assertGreater(advanced, 3.0, "sim time stalled behind a frozen subscriber")
        finally:
            os.kill(proc.pid, signal.SIGCONT)
            proc.kill()
            proc.wait()


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "stalled", StalledSubscriberTest, sys.argv)
