#!/usr/bin/env python3
"""The batch runner's test subject (sleeper.test): ~outcome pass, fail, crash (exits 3 without a result) or
hang (never ends; a child in a process group of its own hangs too) or lose_worker (on a run's first attempt
under Ray, SIGKILLs the Ray worker running it, as a machine lost mid-run would; passes on the retry).
~seconds of /clock-free sleeping first. It publishes nothing on /clock, so its runs report no sim time."""
import os
import signal
import subprocess
import sys
import time
import unittest

import rospy
import rostest


def hang_until_ended():
    """Block until a signal ends this process (the runner's SIGTERM or SIGKILL; SIGINT only stops rospy)."""
    while True:
        signal.pause()


def ray_worker_above():
    """Pid of the Ray worker process this process descends from (its title starts with 'ray::')."""
    pid = os.getppid()
    while pid > 1:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            if f.read().startswith(b"ray::"):
                return pid
        with open(f"/proc/{pid}/stat") as f:
            pid = int(f.read().rsplit(")", 1)[1].split()[1])
    raise AssertionError("not run by a Ray worker")


class Sleeper(unittest.TestCase):
    def test_outcome(self):
        outcome = rospy.get_param("~outcome", "pass")
        time.sleep(float(rospy.get_param("~seconds", 0.5)))
        print("METRIC slept_s={}".format(rospy.get_param("~seconds", 0.5)), flush=True)
        if outcome == "fail":
            self.fail("told to fail")
        if outcome == "crash":
            os._exit(3)
        if outcome == "lose_worker" and os.environ.get("DIFFBOT_BATCH_RUN", "").endswith("/1"):
            os.kill(ray_worker_above(), signal.SIGKILL)
            hang_until_ended()  # by the runner's clean-up of the lost attempt
        if outcome == "hang":
            subprocess.Popen(["sleep", "3600"], start_new_session=True)
            hang_until_ended()


if __name__ == "__main__":
    rospy.init_node("sleeper")
    rostest.rosrun("diffbot_sim", "sleeper", Sleeper, sys.argv)
