"""Items ``fast``, ``realtime``, ``latency``, ``ros_control``: the seed robot driving its circle.

- ``fast``: fast mode, every standard topic subscribed by its own process: RTF (with and without
  robot_state_publisher, and with a rospy node publishing cmd_vel in the loop); bare PyBullet's RTF (same
  model, same step, same run) and the ratio; medians of interleaved trials.
- ``realtime``: real-time mode for 60 s: RTF error, simulator CPU (% of one core), /odom period jitter; bare
  PyBullet paced the same way (the CPU floor).
- ``latency``: cmd_vel published -> wheel motor target applied (``~debug/cmd_applied``), wall ms, at RTF 1.
- ``ros_control``: fast-mode RTF of the four-wheel ros_control fixture (diff_drive_controller from its YAML),
  its odom, /joint_states and /tf each subscribed by a process of its own; median of 3.
"""
import json
import os
import threading
import time
import warnings

from benchkit.bare import check_upright, load
from benchkit.common import MODEL, ROBOTS, STEP, TOPICS
from benchkit.launching import Launch, sim_args, subscriber
from benchkit.report import Item
from benchkit.stats import median_trial, percentile

from diffbot_sim.waiting import wait_for

ROS_CONTROL_MODEL = os.path.join(ROBOTS, "ros_control_4wd.urdf")
ROS_CONTROL_YAML = os.path.join(ROBOTS, "ros_control_4wd.yaml")
#: [rad/s] and [N m]: the seed robot's wheels in the bare references (a circle, as the probe drives it)
BARE_WHEELS, BARE_TORQUE = [5.0, 8.0], [30.0, 30.0]


def bare_rtf(seconds):
    """The seed robot stepped by PyBullet alone as fast as it goes (steps in batches of 240, no Python between
    them but the loop): its RTF."""
    import pybullet

    from diffbot_sim.physics import World
    text, parsed = load(MODEL)
    world = World(STEP)
    try:
        robot = world.load_robot(text, parsed)
        robot.set_velocities(robot.indices(["left_wheel_joint", "right_wheel_joint"]), BARE_WHEELS, BARE_TORQUE)
        client = world.client
        for _ in range(240):
            pybullet.stepSimulation(physicsClientId=client)
        steps, start = 0, time.perf_counter()
        while time.perf_counter() - start < seconds:
            for _ in range(240):
                pybullet.stepSimulation(physicsClientId=client)
            steps += 240
        elapsed = time.perf_counter() - start
        check_upright(robot, "seed robot")
    finally:
        world.close()
    return {"steps_per_s": steps / elapsed, "rtf": steps * STEP / elapsed}


def bare_paced(seconds):
    """The seed robot stepped by PyBullet alone but paced to the wall clock, waking every 10 ms (the
    simulator's publish period) to run the steps due: the floor under the simulator's real-time CPU."""
    import pybullet

    from diffbot_sim.physics import World
    text, parsed = load(MODEL)
    world = World(STEP)
    try:
        robot = world.load_robot(text, parsed)
        robot.set_velocities(robot.indices(["left_wheel_joint", "right_wheel_joint"]), BARE_WHEELS, BARE_TORQUE)
        sleeper, steps = threading.Event(), 0
        cpu0, start = time.process_time(), time.monotonic()
        while time.monotonic() - start < seconds:
            while (steps + 1) * STEP <= time.monotonic() - start:
                pybullet.stepSimulation(physicsClientId=world.client)
                steps += 1
            wake = (int((steps + 1) * STEP / 0.01 - 1e-9) + 1) * 0.01
            sleeper.wait(max(0.0, wake - (time.monotonic() - start)))
        elapsed = time.monotonic() - start
        return {"cpu_percent": 100.0 * (time.process_time() - cpu0) / elapsed, "rtf": steps * STEP / elapsed}
    finally:
        world.close()


def fast_trial(seconds, rsp, leave=True):
    """Fast mode, every topic subscribed; ``leave``: the probe gives the robot its command and leaves (no node in
    the loop), else it keeps publishing to cmd_vel and fast mode waits for it after each /clock tick."""
    with Launch(sim_args("real_time:=false", f"robot_state_publisher:={str(rsp).lower()}"), "fast") as launch:
        for topic in TOPICS[1:]:  # /clock is subscribed by the RTF probe itself, a process of its own
            subscriber(launch, [topic])
        result = launch.probe("rtf", seconds=seconds, warmup=3.0, leave=leave)
        result["subscriber_messages"] = launch.subscriber_messages()
    return result


def fast(seconds, repeats):
    """Fast mode with and without robot_state_publisher, and bare PyBullet, interleaved; medians."""
    runs = {"bare": [], "fast": [], "fast_no_rsp": [], "fast_commander": []}
    for _ in range(repeats):
        runs["bare"].append(bare_rtf(seconds / 2))
        runs["fast"].append(fast_trial(seconds, True))
        runs["fast_no_rsp"].append(fast_trial(seconds, False))
        runs["fast_commander"].append(fast_trial(seconds, False, leave=False))
    return {key: median_trial(trials) for key, trials in runs.items()}


def realtime_trial(seconds, extra_subscribers):
    with Launch(sim_args(), "realtime") as launch:
        for topic in extra_subscribers:
            subscriber(launch, [topic])
        result = launch.probe("rtf", seconds=seconds, warmup=3.0, odom_jitter=True, timeout=seconds + 120)
    result["rtf_error_percent"] = 100.0 * abs(result["rtf"] - 1.0)
    return result


def realtime(seconds):
    """sim.launch defaults (with robot_state_publisher; rosout and it follow /clock); the probe subscribes
    /clock and /odom. Then the same with /joint_states and /tf also subscribed by processes of their own."""
    return {"realtime": realtime_trial(seconds, ()),
            "realtime_all_topics": realtime_trial(seconds, ("/joint_states", "/tf")),
            "bare_paced": bare_paced(min(seconds, 20.0))}


def probe_latency(options):
    """cmd_vel publish (wall) -> ~debug/cmd_applied stamp (wall, set when the motor targets were set)."""
    import rospy
    from geometry_msgs.msg import Twist, TwistStamped
    rospy.init_node("bench_latency", disable_signals=True)
    applied = {}
    rospy.Subscriber("/bullet_sim/debug/cmd_applied", TwistStamped,
                     lambda m: applied.setdefault(round(m.twist.linear.x, 6), m.header.stamp.to_sec()),
                     queue_size=1000)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # rospy warns on queue_size=None, which we mean
        pub = rospy.Publisher("/cmd_vel", Twist, queue_size=None)  # synchronous: sent when publish returns
    wait_for(lambda: pub.get_num_connections() > 0, 30, "the simulator to subscribe /cmd_vel")
    time.sleep(1.0)
    sent = {}
    for i in range(options["count"]):
        value = round(0.05 + 0.0001 * i, 6)  # distinct, small: the robot creeps forward
        msg = Twist()
        msg.linear.x = value
        sent[value] = time.time()
        pub.publish(msg)
        time.sleep(1.0 / options["rate"])
    wait_for(lambda: len(applied) >= len(sent) - 2, 10, "the last commands to be applied")
    lat = [1000.0 * (applied[v] - t) for v, t in sent.items() if v in applied]
    print(json.dumps({"p50_ms": percentile(lat, 50), "p99_ms": percentile(lat, 99), "max_ms": max(lat),
                      "commands": len(sent), "applied": len(lat)}), flush=True)


def latency(count):
    with Launch(sim_args("debug_cmd_applied:=true"), "latency") as launch:
        return launch.probe("latency", count=count, rate=20.0, timeout=count / 20.0 + 120)


def ros_control_trial(seconds):
    args = sim_args("real_time:=false", f"model:={ROS_CONTROL_MODEL}", f"controllers:={ROS_CONTROL_YAML}",
                    "robot_state_publisher:=false")
    with Launch(args, "ros_control") as launch:
        for topic in ("/mobile_base_controller/odom", "/joint_states", "/tf"):
            subscriber(launch, [topic])
        result = launch.probe("rtf", seconds=seconds, warmup=3.0, cmd_topics=["/mobile_base_controller/cmd_vel"],
                              leave=True)
        result["subscriber_messages"] = launch.subscriber_messages()
    return result


def ros_control(seconds, repeats):
    return median_trial([ros_control_trial(seconds) for _ in range(repeats)])


def fast_rows(r):
    f, n, b = r.get("fast"), r.get("fast_no_rsp"), r.get("bare")
    if not (f and b):
        return []
    rows = [("bare PyBullet RTF, same model and step", f"{b['rtf']:.1f}", ""),
            ("fast-mode RTF, sim.launch defaults (+RSP)", f"{f['rtf']:.1f}", ">= 40"),
            ("  fast / bare", f"{f['rtf'] / b['rtf']:.2f}", ">= 0.5"),
            ("fast-mode RTF, robot_state_publisher:=false", f"{n['rtf']:.1f}", ">= 40"),
            ("  fast / bare", f"{n['rtf'] / b['rtf']:.2f}", ">= 0.5")]
    if r.get("fast_commander"):
        rows.append(("  the same, a rospy node publishing cmd_vel in the loop", f"{r['fast_commander']['rtf']:.1f}",
                     ""))
    return rows


def realtime_rows(r):
    rows = []
    for key, label in (("realtime", "real time, /clock + /odom subscribed"),
                       ("realtime_all_topics", "real time, all four topics subscribed")):
        if r.get(key):
            rt = r[key]
            rows += [(f"{label}: RTF error over {rt['wall_s']:.0f} s", f"{rt['rtf_error_percent']:.3f} %", "<= 0.5 %"),
                     ("  simulator CPU", f"{rt['cpu_percent']:.1f} % of a core", "<= 8 %"),
                     ("  /odom arrival period p50 / p99", f"{rt['odom_period_p50_ms']:.2f} / "
                      f"{rt['odom_period_p99_ms']:.2f} ms", ""),
                     ("  /odom delivery jitter p99", f"{rt['odom_jitter_p99_ms']:.2f} ms", "")]
    if r.get("bare_paced"):
        rows.append(("bare PyBullet paced to real time, CPU (the floor)",
                     f"{r['bare_paced']['cpu_percent']:.1f} % of a core", ""))
    return rows


def latency_rows(r):
    if not r.get("latency"):
        return []
    lat = r["latency"]
    return [("cmd_vel -> motor target p50 / p99", f"{lat['p50_ms']:.2f} / {lat['p99_ms']:.2f} ms",
             f"p99 <= {1000 * STEP + 2:.2f} ms")]


def ros_control_rows(r):
    if not r.get("ros_control"):
        return []
    return [("fast-mode RTF, 4-wheel ros_control robot (DDC)", f"{r['ros_control']['rtf']:.1f}", ">= 30")]


ITEMS = [Item("fast", lambda q: fast(4 if q else 12, 1 if q else 3), fast_rows, flat=True),
         Item("realtime", lambda q: realtime(10 if q else 60), realtime_rows, flat=True),
         Item("latency", lambda q: latency(100 if q else 600), latency_rows),
         Item("ros_control", lambda q: ros_control(4 if q else 12, 1 if q else 3), ros_control_rows)]
PROBES = {"latency": probe_latency}
