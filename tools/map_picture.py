#!/usr/bin/env python3
"""docs/slam_room.png: a map gmapping made here (maps/room.yaml) next to the world it maps (worlds/room.world cut
at the laser's height, its solids drawn black), on the same grid.  bash tools/rosenv.sh python3 tools/map_picture.py"""
import os
import sys

import numpy as np
import yaml
from PIL import Image

from diffbot_sim.check import map_check
from diffbot_sim.world.loading import load_world

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    meta = yaml.safe_load(open(os.path.join(ROOT, "maps", "room.yaml")))
    pgm = np.array(Image.open(os.path.join(ROOT, "maps", meta["image"])))[::-1]  # row 0 at the origin's y
    res, (x0, y0, _) = meta["resolution"], meta["origin"]
    grid = map_check.Grid(x0, y0, res, pgm.shape[1], pgm.shape[0], np.zeros(pgm.shape, dtype=np.int16))
    sections = map_check.world_section(load_world(os.path.join(ROOT, "worlds", "room.world"), 1.0), 0.156)
    rows, cols = np.indices(pgm.shape)
    centres = grid.centres(rows.ravel(), cols.ravel())
    solid = np.zeros(len(centres), dtype=bool)
    for _, segments in sections:
        solid |= map_check.inside(centres, segments)
    world = np.where(solid.reshape(pgm.shape), 0, 255).astype(np.uint8)
    # the room with a margin: x -3.5 .. 3.5, y -2.5 .. 2.5
    c0, c1 = int((-3.5 - x0) / res), int((3.5 - x0) / res)
    r0, r1 = int((-2.5 - y0) / res), int((2.5 - y0) / res)
    left, right = world[r0:r1, c0:c1][::-1], pgm[r0:r1, c0:c1][::-1]
    gap = np.full((left.shape[0], 8), 255, dtype=np.uint8)
    picture = Image.fromarray(np.hstack([left, gap, right])).resize((2 * (left.shape[1] * 3) + 24, left.shape[0] * 3),
                                                                   Image.NEAREST)
    out = os.path.join(ROOT, "docs", "slam_room.png")
    picture.save(out)
    print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
