#!/usr/bin/env python3
"""SLAM with the real gmapping on our scans, TF and clock (slam.launch drive:=tour): once the scripted tour is
through, the map gmapping publishes is judged against the world's true geometry (diffbot_sim.check.map_check:
occupied cells on true surfaces, every obstacle mapped where it was seen, no free cell deep inside a solid), and
map_server's map_saver saves it as a user would.

Private parameters: ~world (the world file the simulator loaded), ~laser_height (m above the ground: where the
world is cut), ~timeout (wall s for the tour), ~save_as (optional: also keep
the saved map as this path's .yaml and .pgm, e.g. to make worlds/room_map.yaml). Figures: FIGURE lines (map error,
obstacles, sim/wall seconds, RTF).
"""
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import unittest

import rospy
import rostest
from nav_msgs.msg import OccupancyGrid
from simtest import figure, sim_now, wait_for

from diffbot_sim.check import map_check
from diffbot_sim.world.loading import load_world


class SlamTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_slam")
        cls.lock = threading.Lock()
        cls.map = None
        rospy.Subscriber("/map", OccupancyGrid, cls._keep, queue_size=1)

    @classmethod
    def _keep(cls, msg):
        with cls.lock:
            cls.map = msg

    def latest_map(self):
        with self.lock:
            return self.map

    def test_the_map_matches_the_world(self):
        timeout = float(rospy.get_param("~timeout", 900.0))
        wall0 = time.monotonic()
        wait_for(lambda: rospy.get_time() > 0, 60.0, "sim time")
        sim0 = rospy.get_time()
        wait_for(lambda: rospy.get_param("/tour/done", False), timeout, "the tour to end (/tour/done)")
        done_at = rospy.get_time()
        wall = time.monotonic() - wall0
        figure(f"tour: {done_at - sim0:.1f} s of sim time in {wall:.1f} s of wall time: "
               f"RTF {(done_at - sim0) / wall:.2f}")
        # a map stamped after the simulator's time now, when the tour is known to be over (this node's clock can
        # lag it: a map stamped after that could still miss the tour's last part)
        ended = sim_now()
        msg = wait_for(lambda: (m := self.latest_map()) is not None and m.header.stamp.to_sec() > ended and m,
                       120.0, "a map published after the tour")
        grid = map_check.Grid.from_message(msg)
        world = load_world(rospy.get_param("~world"), 1.0)
        sections = map_check.world_section(world, float(rospy.get_param("~laser_height")))
        report = map_check.judge(grid, sections)
        figure(f"map: {report.occupied} occupied cells, {report.near_fraction:.1%} within {map_check.NEAR} m of a true "
               f"surface, median error {report.median_error * 100:.1f} cm, {report.free_inside} free cells deep "
               f"inside solids, obstacles mapped " + ", ".join(f"{o.mapped}/{o.seen}" for o in report.obstacles))
        self.assertTrue(report.passed, "; ".join(report.failures))

        with tempfile.TemporaryDirectory() as tmp:
            base = os.path.join(tmp, "map")
            proc = subprocess.run(["rosrun", "map_server", "map_saver", "-f", base], stdin=subprocess.DEVNULL,
                                  capture_output=True, text=True, timeout=60)
            self.assertEqual(proc.returncode, 0, proc.stdout + proc.stderr)
            self.assertTrue(os.path.isfile(base + ".yaml") and os.path.isfile(base + ".pgm"))
            with open(base + ".pgm", "rb") as pgm:
                lines = [line for line in pgm.read(200).split(b"\n") if not line.startswith(b"#")]
            self.assertEqual(lines[0], b"P5")
            self.assertEqual(tuple(int(v) for v in lines[1].split()), (grid.width, grid.height))
            keep = rospy.get_param("~save_as", "")
            if keep:
                shutil.copy(base + ".pgm", keep + ".pgm")
                with open(base + ".yaml") as saved, open(keep + ".yaml", "w") as kept:
                    kept.write(saved.read().replace(base + ".pgm", os.path.basename(keep) + ".pgm"))


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_slam", SlamTest, sys.argv)
