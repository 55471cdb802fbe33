"""Items ``lockstep`` and ``gym``: the two ways a learning agent drives a robot.

- ``lockstep``: a Gazebo-style step-and-wait learning environment (publish cmd_vel, rospy.wait_for_message
  /scan, 5 Hz laser) against fast mode: steps per second, the sim time each action was held (median and 95th
  percentile; one scan period is right).
- ``gym``: tools/gym_speed.py: in-process env steps per second per core, its ratio to bare PyBullet, resets
  per second.
"""
import json
import os
import statistics
import subprocess
import sys
import time

from benchkit.common import ROBOTS, ROOT
from benchkit.launching import Launch, sim_args
from benchkit.report import Item
from benchkit.stats import percentile

from diffbot_sim.waiting import wait_for

LASER_ROBOT = os.path.join(ROBOTS, "laser_robot.urdf")


def probe_lockstep(options):
    """TurtleBot3's learning environment's step (publish cmd_vel, wait_for_message scan) repeated."""
    import rospy
    from geometry_msgs.msg import Twist
    from sensor_msgs.msg import LaserScan
    rospy.init_node("bench_lockstep", disable_signals=True)
    pub = rospy.Publisher("/cmd_vel", Twist, queue_size=5)
    wait_for(lambda: pub.get_num_connections() > 0, 60, "the simulator's cmd_vel")
    stamps = [rospy.wait_for_message("/scan", LaserScan, timeout=30).header.stamp.to_sec()]
    start = time.monotonic()
    for k in range(options["steps"]):
        twist = Twist()
        twist.linear.x, twist.angular.z = 0.15, (2 - k % 5) * 0.75
        pub.publish(twist)
        stamps.append(rospy.wait_for_message("/scan", LaserScan, timeout=30).header.stamp.to_sec())
    wall = time.monotonic() - start
    held = [b - a for a, b in zip(stamps, stamps[1:])]
    print(json.dumps({"steps_per_s": options["steps"] / wall, "rtf": (stamps[-1] - stamps[0]) / wall,
                      "held_median_s": statistics.median(held), "held_p95_s": percentile(held, 95),
                      "held_max_s": max(held)}), flush=True)


def lockstep(steps, repeats):
    trials = []
    for _ in range(repeats):
        with Launch(sim_args("real_time:=false", f"model:={LASER_ROBOT}", "robot_state_publisher:=false",
                             f"world:={os.path.join(ROOT, 'tests', 'data', 'worlds', 'laser_room.world')}"),
                    "lockstep") as launch:
            trials.append(launch.probe("lockstep", steps=steps, timeout=600))
    best = sorted(trials, key=lambda t: t["steps_per_s"])[len(trials) // 2]
    return dict(best, steps_per_s_runs=[t["steps_per_s"] for t in trials])


def gym():
    out = subprocess.run([sys.executable, os.path.join(ROOT, "tools", "gym_speed.py")],
                         capture_output=True, text=True, timeout=1200)
    lines = [line for line in out.stdout.splitlines() if line.startswith("{")]
    if not lines:
        raise RuntimeError(f"gym_speed.py printed no figures: {out.stderr.strip()[-300:]}")
    return json.loads(lines[-1])


def lockstep_rows(r):
    if not r.get("lockstep"):
        return []
    s = r["lockstep"]
    return [("Gazebo-style step-and-wait env (fast mode)", f"{s['steps_per_s']:.1f} steps/s", ">= 50"),
            ("  sim time each action held, median / p95", f"{s['held_median_s']:.3f} / {s['held_p95_s']:.3f} s",
             "0.2 / 0.2 (one scan)")]


def gym_rows(r):
    if not r.get("gym"):
        return []
    g = r["gym"]
    return [("gym env steps/s per core (24 beams, 0.2 s period)", f"{g['env_steps_per_s_cpu']:.0f}", ""),
            ("  / bare PyBullet, same sim time (CPU)", f"{g['ratio_to_bare_cpu']:.2f}", ">= 0.7"),
            ("  resets per second per core", f"{g['resets_per_s_cpu']:.0f}", "")]


ITEMS = [Item("lockstep", lambda q: lockstep(50 if q else 300, 1 if q else 3), lockstep_rows),
         Item("gym", lambda q: gym(), gym_rows)]
PROBES = {"lockstep": probe_lockstep}
