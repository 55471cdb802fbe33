#!/usr/bin/env python3
"""Bad models fail fast: non-zero exit within 5 s, one line naming the culprit, no traceback, no odom.

The 5 s are the process's own time: the wall time from start to exit less the time it waited for a CPU
(simtest.CpuWait, from the kernel's schedstat). On an idle machine that is the wall time; on a loaded one
(measured: 6.6-8.5 s of wall time at a quarter of a core, 1.6 s of it computing) the rest is the machine's.
"""
import os
import subprocess
import sys
import time
import unittest

import rosgraph
import rospkg
import rospy
import rostest
from simtest import CpuWait, exited, figure

DATA = os.path.join(rospkg.RosPack().get_path("diffbot_sim"), "tests", "data")
EXIT_BOUND = 5.0  # s of the process's own time from start to exit
HANG_WALL = 60.0  # s wall: a process still running then is killed (a hang, whatever the machine)


class BadModelTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_bad_models")
        cls.master = rosgraph.Master("/test_bad_models")
        cls.count = 0

    def _odom_published(self):
        return any(topic.endswith("/odom") for topic, _ in self.master.getPublishedTopics(""))

    def _run(self, model, culprit, extra=()):
        BadModelTest.count += 1
        args = ["rosrun", "diffbot_sim", "bullet_sim", f"__name:=bad_{self.count}", *extra]
        if model is not None:
            args.append(f"_model:={model}")
        started = time.monotonic()
        proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                stdin=subprocess.DEVNULL)
        waits = CpuWait(proc.pid, from_start=True)
        saw_odom = False
        while not exited(proc.pid) and time.monotonic() - started < HANG_WALL:
            saw_odom = saw_odom or self._odom_published()
            waits.sample()
            time.sleep(0.05)
        elapsed = time.monotonic() - started
        waits.sample()  # the ended process's figures, before it is reaped
        if proc.poll() is None:
            proc.kill()
        out, err = proc.communicate()
        own = waits.own(elapsed)
        figure(f"bad_models: {os.path.basename(str(model))}: exit {proc.returncode} after {elapsed:.2f} s wall, "
               f"{waits.waited():.2f} s of it waiting for a CPU: {own:.2f} s of its own")
        lines = [line for line in err.splitlines() if line.strip()]
        self.assertNotEqual(proc.returncode, 0, f"exit status for {model}")
        self.assertLess(own, EXIT_BOUND, f"failed within {EXIT_BOUND:g} s of its own time ({own:.1f} s: "
                        f"{elapsed:.1f} s wall, {waits.waited():.1f} s of it waiting for a CPU)")
        self.assertNotIn("Traceback", err + out)
        self.assertEqual(len(lines), 1, f"one line on stderr, got: {lines}")
        self.assertIn(culprit, lines[0])
        self.assertFalse(saw_odom, "no odom publisher appeared")
        return lines[0]

    def test_missing_file(self):
        self._run("/nonexistent/robot.urdf", "/nonexistent/robot.urdf")

    def test_xacro_error(self):
        line = self._run(os.path.join(DATA, "bad_xacro.urdf.xacro"), "bad_xacro.urdf.xacro")
        self.assertIn("does_not_exist.xacro", line)

    def test_truncated_xml(self):
        self._run(os.path.join(DATA, "truncated.urdf"), "malformed XML")

    def test_transmission_names_missing_joint(self):
        self._run(os.path.join(DATA, "missing_joint_transmission.urdf"), "leftt_wheel_joint")

    def test_plugin_names_missing_joint(self):
        self._run(os.path.join(DATA, "missing_joint_plugin.urdf"), "no_such_joint")

    def test_effort_interface_on_drive_wheel(self):
        self._run(os.path.join(DATA, "effort_drive_wheel.urdf"), "EffortJointInterface")

    def test_zero_wheel_radius(self):
        self._run(os.path.join(DATA, "zero_radius.urdf"), "radius")

    def test_negative_wheel_diameter(self):
        self._run(os.path.join(DATA, "negative_diameter.urdf"), "wheel_diameter")

    def test_missing_robot_description(self):
        self._run(None, "robot_description")

    # -- worlds: one line naming the file (and line, or the URI and every directory searched) ----------
    def _world(self, name):
        return [f"_world:={os.path.join(DATA, 'bad_worlds', name)}"]

    def test_malformed_world_names_file_and_line(self):
        seed = os.path.join(rospkg.RosPack().get_path("diffbot_sim"), "urdf", "diffbot.urdf.xacro")
        line = self._run(seed, "malformed.world", self._world("malformed.world"))
        self.assertIn("line 5", line)

    def test_unresolved_model_uri_names_uri_and_search_path(self):
        seed = os.path.join(rospkg.RosPack().get_path("diffbot_sim"), "urdf", "diffbot.urdf.xacro")
        line = self._run(seed, "model://no_such_model_anywhere", self._world("unresolved.world"))
        self.assertIn("unresolved.world", line)
        self.assertIn(".gazebo/models", line)

    def test_unreadable_map_image(self):
        seed = os.path.join(rospkg.RosPack().get_path("diffbot_sim"), "urdf", "diffbot.urdf.xacro")
        line = self._run(seed, "not_an_image.pgm", self._world("unreadable_map.yaml"))
        self.assertIn("unreadable_map.yaml", line)


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_bad_models", BadModelTest, sys.argv)
