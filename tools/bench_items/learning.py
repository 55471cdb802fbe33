"""Items ``lockstep`` and ``gym``: the two ways a learning agent drives a robot.

- ``lockstep``: a Gazebo-style step-and-wait learning environment (publish cmd_vel, rospy.wait_for_message
  /scan, 5 Hz laser) against fast mode: steps per second, the sim time each action was held (median and 95th
  percentile; one scan period is right).
- ``dqn_env``: tests/integration/tb3_env.py (TurtleBot3's learning environment's traits: its own odometry
  subscriber made just before its first reset_simulation, goal models spawned and deleted with 0.5 s sleeps,
  wait_for_message scan) 20 times, each a fresh simulator in fast mode and a fresh environment process, as a
  user starting a training run: per run the sim time each action was held (min / median / max; one scan period
  is right), a crash, and whether every episode begun one scan period after its reset, in every run, moved the
  body the same at every scan (the same actions from the same reset: a command taken late shows).
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
LASER_ROOM = os.path.join(ROOT, "tests", "data", "worlds", "laser_room.world")
TB3_ENV = os.path.join(ROOT, "tests", "integration", "tb3_env.py")


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


def dqn_env(runs, episodes, steps):
    """``runs`` runs of tb3_env.py (``episodes`` x ``steps``, the same seed), each against a fresh simulator."""
    sys.path.insert(0, os.path.dirname(TB3_ENV))
    from tb3_env import same_starts
    records = []
    for k in range(runs):
        with Launch(sim_args("real_time:=false", f"model:={LASER_ROBOT}", "robot_state_publisher:=false",
                             f"world:={LASER_ROOM}"), f"dqn_env{k}") as launch:
            out = subprocess.run([sys.executable, TB3_ENV, str(episodes), str(steps), "16"], env=launch.env,
                                 capture_output=True, text=True, timeout=900, stdin=subprocess.DEVNULL)
        lines = [line for line in out.stdout.splitlines() if line.startswith("{")]
        records.append(json.loads(lines[-1]) if lines else {"error": f"no record: {out.stderr.strip()[-300:]}"})
    # the body's motion of the episodes begun one scan period after their reset, the same in every run
    begun = [json.dumps(t) for r in records for t in same_starts(r, 0.2)]
    reference = max(set(begun), key=begun.count) if begun else None
    per_run = []
    for record in records:
        spans, error = record.get("spans") or [], (record.get("error") or "").splitlines()
        same = [json.dumps(t) for t in same_starts(record, 0.2)]
        per_run.append({"actions": len(spans), "min_s": min(spans, default=None),
                        "median_s": statistics.median(spans) if spans else None, "max_s": max(spans, default=None),
                        "off": sum(abs(s - 0.2) > 1e-6 for s in spans), "error": error[0] if error else None,
                        "starts": record.get("starts"), "same_body": bool(same) and all(t == reference for t in same),
                        "steps_per_s": len(spans) / record["wall_s"] if record.get("wall_s") else None})
    right = [r for r in per_run if r["actions"] and not r["off"] and not r["error"] and r["same_body"]]
    return {"runs": per_run, "right": len(right), "crashed": sum(bool(r["error"]) for r in per_run)}


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


def dqn_env_rows(r):
    if not r.get("dqn_env"):
        return []
    d = r["dqn_env"]
    runs = [x for x in d["runs"] if x["actions"]]
    medians = [x["median_s"] for x in runs]
    return [(f"TurtleBot3-style env (tb3_env.py), {len(d['runs'])} fresh runs: right / crashed",
             f"{d['right']} / {d['crashed']}", f"{len(d['runs'])} / 0"),
            ("  action spans over the runs: min / median / max",
             f"{min(x['min_s'] for x in runs):.3f} / {statistics.median(medians):.3f} / "
             f"{max(x['max_s'] for x in runs):.3f} s" if runs else "-", "0.2 / 0.2 / 0.2 (one scan)")]


def gym_rows(r):
    if not r.get("gym"):
        return []
    g = r["gym"]
    return [("gym env steps/s per core (24 beams, 0.2 s period)", f"{g['env_steps_per_s_cpu']:.0f}", ""),
            ("  / bare PyBullet, same sim time (CPU)", f"{g['ratio_to_bare_cpu']:.2f}", ">= 0.7"),
            ("  resets per second per core", f"{g['resets_per_s_cpu']:.0f}", "")]


ITEMS = [Item("lockstep", lambda q: lockstep(50 if q else 300, 1 if q else 3), lockstep_rows),
         Item("dqn_env", lambda q: dqn_env(2 if q else 20, 2, 15 if q else 40), dqn_env_rows),
         Item("gym", lambda q: gym(), gym_rows)]
PROBES = {"lockstep": probe_lockstep}
