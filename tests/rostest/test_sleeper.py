#!/usr/bin/env python3
"""The batch runner's test subject (sleeper.test): ~outcome pass, fail, crash (exits 3 without a result) or
hang (never ends; a child in a process group of its own hangs too). ~seconds of /clock-free sleeping first.
It publishes nothing on /clock, so its runs report no sim time."""
import os
import subprocess
import sys
import time
import unittest

import rospy
import rostest


class Sleeper(unittest.TestCase):
    def test_outcome(self):
        outcome = rospy.get_param("~outcome", "pass")
        time.sleep(float(rospy.get_param("~seconds", 0.5)))
        print("METRIC slept_s=%s" % rospy.get_param("~seconds", 0.5), flush=True)
        if outcome == "fail":
            self.fail("told to fail")
        if outcome == "crash":
            os._exit(3)
        if outcome == "hang":
            subprocess.Popen(["sleep", "3600"], start_new_session=True)
            time.sleep(3600)


if __name__ == "__main__":
    rospy.init_node("sleeper")
    rostest.rosrun("diffbot_sim", "sleeper", Sleeper, sys.argv)
