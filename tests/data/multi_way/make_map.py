#!/usr/bin/env python3
"""Writes tb3like_navigation/maps/house.{pgm,yaml}: the map a Gazebo user would have made of the house with
SLAM and map_saver, drawn instead from the house's true geometry cut at the laser's height
(diffbot_sim.check.map_check.true_map), so the multi-robot navigation suite's map is exact. Run once; the
outputs are committed:

    bash tools/rosenv.sh python3 tests/data/multi_way/make_map.py
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "..", "src"))
os.environ["ROS_PACKAGE_PATH"] = os.pathsep.join([HERE, os.environ.get("ROS_PACKAGE_PATH", "")])

from diffbot_sim.check import map_check
from diffbot_sim.world import map_image
from diffbot_sim.world.loading import load_world

LASER_HEIGHT = 0.181  # m: tb3like's base_scan above the ground
RESOLUTION = 0.05  # m, gmapping's default delta
X0, Y0, WIDTH, HEIGHT = -5.6, -4.6, 224, 184  # the house (walls at x = +-5.0 .. 5.2, y = +-4.0 .. 4.2) and a margin
OUT = os.path.join(HERE, "tb3like_navigation", "maps")


def main():
    world = load_world(os.path.join(HERE, "tb3like_gazebo", "worlds", "house.world"), 1.0)
    grid = map_check.true_map(map_check.world_section(world, LASER_HEIGHT), X0, Y0, RESOLUTION, WIDTH, HEIGHT)
    # the image's top row is the grid's last
    map_image.write_map(os.path.join(OUT, "house.yaml"), grid.data[::-1] == 100, RESOLUTION, (X0, Y0),
                        "made by tests/data/multi_way/make_map.py from house.world")


if __name__ == "__main__":
    main()
