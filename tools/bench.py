#!/usr/bin/env python3
"""``make bench``: speed, latency, start-up and scale of bullet_sim, each item against a reference.

Plain Python + the ROS CLI, no timing assertions: it prints a table and writes bench-results/bench.json.
Every measurement starts its own master (``roslaunch -p PORT``) and stops it with SIGINT, so nothing is
shared between items. ROS-side probes (``--probe ...``) run in child processes, one ROS node each.
The kit they are made of is tools/benchkit/; the items, by theme, are tools/bench_items/ (each module's
docstring says what its items measure and how).

Items (``--only a,b``, or ``make bench ITEMS=a,b``):
  fast         fast mode, every standard topic subscribed: RTF; bare PyBullet's (same model, step, run); ratio
  realtime     real time for 60 s: RTF error, simulator CPU, /odom jitter; bare PyBullet paced the same way
  latency      cmd_vel published -> wheel motor target applied, wall ms, at RTF 1
  ros_control  fast-mode RTF of the four-wheel ros_control fixture (diff_drive_controller from its YAML)
  startup      `roslaunch diffbot_sim sim.launch` -> first /odom, median of 5
  meshes       the same with 2 MB of STL meshes, mesh cache empty and filled
  worlds       the same in worlds of meshes and of 4000 x 4000 maps; fast-mode RTF in room.world / none
  sensors      a 360-beam laser and an IMU subscribed: fast-mode RTF, real-time simulator CPU
  world_api    /gazebo/spawn_urdf_model -> first odom of the new robot; set_model_state round trips
  batch        `batch`'s overhead per run; the drive example at --jobs 1 and 2
  arm          fast-mode RTF of a base with a 6-joint arm on a trajectory, against bare PyBullet; command ->
               first motion
  fixed_arm    fast-mode RTF of 6-joint effort arms bolted to the world at a 1 ms step (UR5-like; and the arm
               cell with its gripper, item fixed_arm_cell), against bare PyBullet with a PD, by RTF and by CPU
  lockstep     a Gazebo-style step-and-wait learning environment against fast mode
  dqn_env      a TurtleBot3-style learning environment (tests/integration/tb3_env.py), 20 fresh runs: every
               action held one scan period, no crash, the same body motion in every episode of every run
  gym          the Gymnasium environment: env steps per CPU second, against bare PyBullet
  scale        namespaced seed robots kept at real time (scale_rsp: with a robot_state_publisher each)
  fleet        TurtleBot3-class laser robots kept at real time, against bare PyBullet in back-to-back pairs
"""
import argparse
import json
import os
import sys
import time

from bench_items import arm, batch, drive, fixed_arm, fleet, learning, sensors, startup, world_api
from benchkit import probes
from benchkit.common import RESULTS, STEP
from benchkit.report import table, write_results

#: the item modules, in the order their items run and their rows are printed
THEMES = [drive, startup, sensors, world_api, batch, arm, fixed_arm, learning, fleet]
ITEMS = [item for theme in THEMES for item in theme.ITEMS]
PROBES = dict(probes.PROBES, **{kind: probe for theme in THEMES for kind, probe in theme.PROBES.items()})


def run(names, quick):
    """Run the items ``names`` selects; the results (also written to bench-results/bench.json)."""
    os.makedirs(RESULTS, exist_ok=True)
    results = {"time_step": STEP, "date": time.strftime("%Y-%m-%d %H:%M:%S"), "cpus": os.cpu_count()}
    for item in ITEMS:
        if not item.wanted(names):
            continue
        print(f"[bench] {item.name} ...", flush=True)
        figures = item.run(quick)
        if item.flat:
            results.update(figures)
        else:
            results[item.name] = figures
        print(f"[bench] {item.name}: {json.dumps(results.get(item.name))}", flush=True)
    path = write_results(results, RESULTS)
    print(table([row for item in ITEMS for row in item.rows(results)]))
    print(f"[bench] written {path}")
    return results


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--probe", help=argparse.SUPPRESS)
    parser.add_argument("--options", default="{}", help=argparse.SUPPRESS)
    parser.add_argument("--only", default=",".join(item.name for item in ITEMS if item.part_of is None),
                        help="comma-separated items to run (default: all)")
    parser.add_argument("--quick", action="store_true", help="shorter windows (smoke run, not for figures)")
    args = parser.parse_args()
    if args.probe:
        PROBES[args.probe](json.loads(args.options))
        return 0
    names = set(args.only.split(","))
    unknown = names - {item.name for item in ITEMS}
    if unknown:
        parser.error(f"no such item: {', '.join(sorted(unknown))} (items: {', '.join(i.name for i in ITEMS)})")
    run(names, args.quick)
    return 0


if __name__ == "__main__":
    from diffbot_sim import streams  # a closed pipe (`make bench | head`) must not turn the status into 120

    try:
        STATUS = main()
    finally:
        streams.finish()
    sys.exit(STATUS)
