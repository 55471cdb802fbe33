#!/usr/bin/env python3
"""``make bench``: speed, latency, start-up and scale of bullet_sim, measured on the seed robot.

Plain Python + the ROS CLI, no timing assertions: it prints a table and writes bench-results/bench.json.
Every measurement starts its own master (``roslaunch -p PORT``) and stops it with SIGINT, so nothing is
shared between items. ROS-side probes (``--probe ...``) run in child processes, one ROS node each.

Items (issue 4):
  fast       fast mode, every standard topic subscribed by its own process: RTF; bare PyBullet RTF
             (same model, same step, same run) and the ratio.
  realtime   real-time mode for 60 s: RTF error, simulator CPU (% of one core), /odom period jitter.
  latency    cmd_vel published -> wheel motor target applied (~debug/cmd_applied), wall ms, at RTF 1.
  startup    `roslaunch diffbot_sim sim.launch` -> first /odom, median of 5.
  scale      namespaced seed robots one simulator keeps at RTF >= 1, all topics subscribed.
Items (issue 9):
  meshes     roslaunch -> first /odom for a robot with 2 MB of binary STL meshes (collision and visual),
             with an empty mesh cache and with the cache filled; median of 3 each.
  ros_control  fast-mode RTF of the four-wheel ros_control fixture (diff_drive_controller from its YAML),
             its odom, /joint_states and /tf each subscribed by a process of its own; median of 3.
Items (issue 11):
  sensors    a robot with a 360-beam laser at 5 Hz and an IMU at 100 Hz, both subscribed (with /odom and
             /tf), in worlds/room.world: fast-mode RTF (median of 3) and real-time simulator CPU (30 s).
             Cameras: tools/camera_speed.py.
Items of tools/bench_wave.py: arm, lockstep, gym, fleet (see its docstring).
Items (issue 10):
  worlds     roslaunch -> first /odom in a world of 30 models with COLLADA collision meshes (empty mesh
             cache), in the furnished house of meshes of tests/data/multi_way (cache warm) against no world,
             and with a 4000 x 4000 map image (a floor plan, and the same with 2 % speckle);
             fast-mode RTF of the seed robot in worlds/room.world against the empty world (medians of 3).
"""
import argparse
import json
import os
import shutil
import signal
import socket
import statistics
import subprocess
import sys
import time
import warnings
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
RESULTS = os.path.join(ROOT, "bench-results")
MODEL = os.path.join(ROOT, "urdf", "diffbot.urdf.xacro")
STEP = 1.0 / 240.0
TOPICS = ["/clock", "/odom", "/joint_states", "/tf"]
#: (m/s, rad/s): the circle the RTF probe drives every robot in
CIRCLE = (0.2, 0.5)


# ------------------------------------------------------------------------------------------------ helpers

def free_port():
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def percentile(values, q):
    ordered = sorted(values)
    if not ordered:
        return float("nan")
    k = min(len(ordered) - 1, max(0, int(round(q / 100.0 * (len(ordered) - 1)))))
    return ordered[k]


class Launch:
    """``roslaunch -p PORT ...`` with its own master; stopped with SIGINT (then SIGKILL) on exit."""

    def __init__(self, args, log_name):
        self.port = free_port()
        self.env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{self.port}",
                        ROS_HOME=os.path.join(RESULTS, "ros_home"))
        self.args = ["roslaunch", "-p", str(self.port)] + list(args)
        self.log_path = os.path.join(RESULTS, f"{log_name}.log")
        self.proc = None
        self.children = []

    def __enter__(self):
        os.makedirs(RESULTS, exist_ok=True)
        self.log = open(self.log_path, "w")
        self.started = time.time()
        self.proc = subprocess.Popen(self.args, env=self.env, stdout=self.log, stderr=subprocess.STDOUT,
                                     stdin=subprocess.DEVNULL, start_new_session=True)
        return self

    def spawn(self, argv):
        """A helper process (a subscriber) against this launch's master; stopped with SIGINT on exit."""
        proc = subprocess.Popen(argv, env=self.env, stdout=subprocess.PIPE, stderr=self.log,
                                stdin=subprocess.DEVNULL, text=True)
        self.children.append(proc)
        return proc

    def probe(self, kind, timeout=300, **options):
        """Run ``bench.py --probe kind`` against this master and return its JSON answer."""
        argv = [sys.executable, os.path.abspath(__file__), "--probe", kind, "--options", json.dumps(options)]
        out = subprocess.run(argv, env=self.env, stdout=subprocess.PIPE, stderr=self.log, text=True,
                             timeout=timeout, stdin=subprocess.DEVNULL)
        lines = [line for line in out.stdout.splitlines() if line.startswith("{")]
        if out.returncode != 0 or not lines:
            raise RuntimeError(f"probe {kind} failed (exit {out.returncode}); see {self.log_path}")
        return json.loads(lines[-1])

    def stop_children(self):
        counts = []
        for proc in self.children:
            proc.send_signal(signal.SIGINT)
        for proc in self.children:
            try:
                out, _ = proc.communicate(timeout=10)
                counts.append(json.loads(out.strip().splitlines()[-1]) if out.strip() else None)
            except (subprocess.TimeoutExpired, ValueError, IndexError):
                proc.kill()
                counts.append(None)
        self.children = []
        return counts

    def __exit__(self, *exc):
        self.stop_children()
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()
        self.log.close()


def subscriber(launch, topics):
    """A separate process subscribing ``topics`` (as `rostopic echo` would, without printing)."""
    return launch.spawn([sys.executable, os.path.abspath(__file__), "--probe", "count",
                         "--options", json.dumps({"topics": topics})])


def sim_args(*extra):
    return ["diffbot_sim", "sim.launch"] + list(extra)


# ------------------------------------------------------------------------------------------------- probes
# Each runs in its own process, as one ROS node, and prints one JSON line.

def _sim_pid():
    import xmlrpc.client

    import rosnode
    uri = rosnode.get_api_uri(rosnode.rosgraph.Master("/bench"), "/bullet_sim", skip_cache=True)
    return xmlrpc.client.ServerProxy(uri).getPid("/bench")[2]


def _cpu_seconds(pid):
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _wait(predicate, timeout, what):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return
        time.sleep(0.01)
    raise RuntimeError(f"timed out waiting for {what}")


def probe_count(options):
    """Subscribe (AnyMsg: no deserialisation, like `rostopic hz`) and print the count on SIGINT."""
    import rospy
    rospy.init_node("bench_sub", anonymous=True, disable_signals=True)
    counts = {topic: 0 for topic in options["topics"]}

    def keep(_msg, topic):
        counts[topic] += 1
    subs = [rospy.Subscriber(t, rospy.AnyMsg, keep, callback_args=t, queue_size=100) for t in counts]
    stop = []
    signal.signal(signal.SIGINT, lambda *_: stop.append(1))
    while not stop:
        time.sleep(0.05)
    for sub in subs:
        sub.unregister()
    print(json.dumps(counts), flush=True)


def probe_rtf(options):
    """RTF from /clock over a window after a warm-up; simulator CPU; /odom receipt-period percentiles."""
    import rospy
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry
    from rosgraph_msgs.msg import Clock
    if not rospy.core.is_initialized():  # a probe that set up its scenario first (bench_wave) already is
        rospy.init_node("bench_rtf", disable_signals=True)
    clock, odom = [], []
    rospy.Subscriber("/clock", Clock, lambda m: clock.append((time.monotonic(), m.clock.to_sec())),
                     queue_size=1000)
    if options.get("odom_jitter"):
        rospy.Subscriber(options.get("odom", "/odom"), Odometry,
                         lambda m: odom.append((time.monotonic(), m.header.stamp.to_sec())), queue_size=1000)
    _wait(lambda: len(clock) > 2, 60, "/clock")
    topics = options.get("cmd_topics") or [f"{ns}/cmd_vel" for ns in options.get("namespaces", [""])]
    pubs = [rospy.Publisher(topic, Twist, queue_size=1, latch=True) for topic in topics]
    circle = Twist()
    circle.linear.x, circle.angular.z = CIRCLE
    for pub in pubs:  # drive in circles: wheels, casters and contacts all busy
        pub.publish(circle)
    time.sleep(options.get("warmup", 3.0))
    if options.get("leave"):
        # Fast mode waits after each /clock tick for the nodes that publish its commands (~wait_for_nodes):
        # with its publishers kept, this probe would be measured, not the simulator. The simulator holds the
        # last command (cmd_vel_timeout 0, as Gazebo), so the robot keeps driving its circle.
        for pub in pubs:
            pub.unregister()
        time.sleep(1.0)
    pid = _sim_pid()
    cpu0, n0 = _cpu_seconds(pid), len(clock)
    time.sleep(options["seconds"])
    cpu1, n1 = _cpu_seconds(pid), len(clock)
    (w0, s0), (w1, s1) = clock[n0 - 1], clock[n1 - 1]
    result = {"rtf": (s1 - s0) / (w1 - w0), "cpu_percent": 100.0 * (cpu1 - cpu0) / (w1 - w0),
              "wall_s": w1 - w0, "sim_s": s1 - s0}
    if options.get("odom_jitter"):
        window = [(t, s) for t, s in odom if w0 <= t <= w1]
        periods = [1000.0 * (b[0] - a[0]) for a, b in zip(window, window[1:])]
        # Delivery jitter: how far each message's arrival strays from where its sim stamp puts it. The
        # stamps themselves alternate 8.33/12.5 ms (a 100 Hz rate on a 240 Hz step), which is not jitter.
        offsets = [t - s for t, s in window]
        middle = statistics.median(offsets)
        result.update({"odom_period_p50_ms": percentile(periods, 50), "odom_period_p99_ms": percentile(periods, 99),
                       "odom_jitter_p99_ms": percentile([1000.0 * abs(o - middle) for o in offsets], 99),
                       "odom_messages": len(window)})
    print(json.dumps(result), flush=True)


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
    _wait(lambda: pub.get_num_connections() > 0, 30, "the simulator to subscribe /cmd_vel")
    time.sleep(1.0)
    sent = {}
    for i in range(options["count"]):
        value = round(0.05 + 0.0001 * i, 6)  # distinct, small: the robot creeps forward
        msg = Twist()
        msg.linear.x = value
        sent[value] = time.time()
        pub.publish(msg)
        time.sleep(1.0 / options["rate"])
    _wait(lambda: len(applied) >= len(sent) - 2, 10, "the last commands to be applied")
    lat = [1000.0 * (applied[v] - t) for v, t in sent.items() if v in applied]
    print(json.dumps({"p50_ms": percentile(lat, 50), "p99_ms": percentile(lat, 99), "max_ms": max(lat),
                      "commands": len(sent), "applied": len(lat)}), flush=True)


def probe_first_odom(options):
    """Wall time (epoch) of the first /odom message; started before the master exists."""
    import rosgraph
    master = rosgraph.Master("/bench_first_odom")
    _wait(master.is_online, 60, "the master")
    import rospy
    from nav_msgs.msg import Odometry
    rospy.init_node("bench_first_odom", disable_signals=True)
    first = []
    rospy.Subscriber(options.get("odom", "/odom"), Odometry, lambda m: first or first.append(time.time()),
                     queue_size=1)
    _wait(lambda: first, 60, "the first /odom")
    print(json.dumps({"first_odom_epoch": first[0]}), flush=True)


def probe_world_api(options):
    """Spawn latency (spawn_urdf_model call -> first odom of the new robot, wall) and set_model_state round
    trips, through the /gazebo services and gazebo_msgs' types, against a simulator started empty."""
    import rospy
    from gazebo_msgs.msg import ModelState
    from gazebo_msgs.srv import SetModelState, SpawnModel
    from geometry_msgs.msg import Pose, Twist
    from nav_msgs.msg import Odometry
    rospy.init_node("bench_world_api", disable_signals=True)
    rospy.wait_for_service("/gazebo/spawn_urdf_model", 60)
    spawn = rospy.ServiceProxy("/gazebo/spawn_urdf_model", SpawnModel, persistent=True)
    set_state = rospy.ServiceProxy("/gazebo/set_model_state", SetModelState, persistent=True)
    with open(options["model"]) as f:
        urdf = f.read()
    spawns = []
    for i in range(options["spawns"]):
        first = []
        sub = rospy.Subscriber(f"/b{i}/odom", Odometry, lambda m, first=first: first or first.append(time.time()),
                               queue_size=1)
        pose = Pose()
        pose.position.x, pose.position.y, pose.orientation.w = 2.0 * i, 0.0, 1.0
        t0 = time.time()
        resp = spawn(f"b{i}", urdf, f"/b{i}", pose, "world")
        if not resp.success:
            raise RuntimeError(resp.status_message)
        _wait(lambda: first, 30, f"the first /b{i}/odom")
        spawns.append(first[0] - t0)
        sub.unregister()
    trips = []
    for i in range(options["round_trips"]):
        state = ModelState("b0", Pose(), Twist(), "world")
        state.pose.position.x, state.pose.position.y, state.pose.orientation.w = 0.0, 0.001 * (i % 100), 1.0
        t0 = time.perf_counter()
        resp = set_state(state)
        trips.append(1000.0 * (time.perf_counter() - t0))
        if not resp.success:
            raise RuntimeError(resp.status_message)
    print(json.dumps({"spawn_to_first_odom_s": spawns, "spawn_median_s": statistics.median(spawns),
                      "set_model_state_p50_ms": percentile(trips, 50), "set_model_state_p99_ms": percentile(trips, 99),
                      "round_trips": len(trips)}), flush=True)


PROBES = {"count": probe_count, "rtf": probe_rtf, "latency": probe_latency, "first_odom": probe_first_odom,
          "world_api": probe_world_api}


def _wave():
    """tools/bench_wave.py (the manipulator, loop and fleet items), imported late: it imports this module."""
    sys.path.insert(0, HERE)
    import bench_wave

    return bench_wave


# -------------------------------------------------------------------------------------------------- items

def bench_world_api(spawns, round_trips):
    """The simulator as empty_world.launch starts it (real time, no robot); robots spawned one by one."""
    args = ["gazebo_ros", "empty_world.launch", "gui:=false"]
    with Launch(args, "world_api") as launch:
        return launch.probe("world_api", model=os.path.join(ROOT, "tests", "data", "robots", "fixed_caster.urdf"),
                            spawns=spawns, round_trips=round_trips)


def check_upright(robot, what, limit_deg=30.0):
    """Raise unless ``robot``'s root link is within ``limit_deg`` of upright: a bare-PyBullet reference whose
    robot fell over steps fewer contacts (2 against 10 for the arm) and would flatter itself."""
    import math

    from diffbot_sim.check import drive_check
    position, quaternion = robot.base_pose()
    tilt = math.degrees(drive_check.body_sample(0.0, position, quaternion).tilt)
    if tilt > limit_deg:
        raise RuntimeError(f"bare PyBullet's {what} fell over (tilted {tilt:.0f} deg): its figure would be wrong")


def bench_bare(seconds):
    """The same model (xacro'd, loaded the way bullet_sim loads it) stepped by PyBullet alone."""
    import pybullet
    sys.path.insert(0, os.path.join(ROOT, "src"))
    from diffbot_sim.description.model_files import load_file
    from diffbot_sim.description.urdf_model import parse_urdf
    from diffbot_sim.physics import World
    text = load_file(MODEL)
    model = parse_urdf(text, MODEL)
    world = World(STEP)
    try:
        robot = world.load_robot(text, model)
        wheels = robot.indices(["left_wheel_joint", "right_wheel_joint"])
        robot.set_velocities(wheels, [5.0, 8.0], [30.0, 30.0])
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


def bench_bare_paced(seconds):
    """The same model stepped by PyBullet alone but paced to the wall clock, waking every 10 ms (the
    simulator's publish period) to run the steps due: the floor under the simulator's real-time CPU."""
    import threading

    import pybullet
    sys.path.insert(0, os.path.join(ROOT, "src"))
    from diffbot_sim.description.model_files import load_file
    from diffbot_sim.description.urdf_model import parse_urdf
    from diffbot_sim.physics import World
    text = load_file(MODEL)
    world = World(STEP)
    try:
        robot = world.load_robot(text, parse_urdf(text, MODEL))
        robot.set_velocities(robot.indices(["left_wheel_joint", "right_wheel_joint"]), [5.0, 8.0], [30.0, 30.0])
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
        counts = launch.stop_children()
    result["subscriber_messages"] = {k: v for c in counts if c for k, v in c.items()}
    return result


def bench_fast(seconds, repeats):
    """Fast mode with and without robot_state_publisher, and bare PyBullet, interleaved; medians."""
    runs = {"bare": [], "fast": [], "fast_no_rsp": [], "fast_commander": []}
    for _ in range(repeats):
        runs["bare"].append(bench_bare(seconds / 2))
        runs["fast"].append(fast_trial(seconds, True))
        runs["fast_no_rsp"].append(fast_trial(seconds, False))
        runs["fast_commander"].append(fast_trial(seconds, False, leave=False))
    out = {}
    for key, trials in runs.items():
        rtfs = [t["rtf"] for t in trials]
        out[key] = dict(trials[rtfs.index(statistics.median_low(rtfs))], rtf=statistics.median(rtfs), rtf_runs=rtfs)
    return out


def realtime_trial(seconds, extra_subscribers):
    with Launch(sim_args(), "realtime") as launch:
        for topic in extra_subscribers:
            subscriber(launch, [topic])
        result = launch.probe("rtf", seconds=seconds, warmup=3.0, odom_jitter=True, timeout=seconds + 120)
    result["rtf_error_percent"] = 100.0 * abs(result["rtf"] - 1.0)
    return result


def bench_realtime(seconds):
    """sim.launch defaults (with robot_state_publisher; rosout and it follow /clock); the probe subscribes
    /clock and /odom. Then the same with /joint_states and /tf also subscribed by processes of their own."""
    return {"realtime": realtime_trial(seconds, ()),
            "realtime_all_topics": realtime_trial(seconds, ("/joint_states", "/tf")),
            "bare_paced": bench_bare_paced(min(seconds, 20.0))}


def bench_latency(count):
    with Launch(sim_args("debug_cmd_applied:=true"), "latency") as launch:
        return launch.probe("latency", count=count, rate=20.0, timeout=count / 20.0 + 120)


def bench_startup(runs, extra=(), ros_home=None, before_each=None):
    times = []
    for i in range(runs):
        if before_each is not None:
            before_each()
        port = free_port()
        env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{port}",
                   ROS_HOME=ros_home or os.path.join(RESULTS, "ros_home"))
        probe = subprocess.Popen([sys.executable, os.path.abspath(__file__), "--probe", "first_odom", "--options", "{}"],
                                 env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        time.sleep(0.5)  # the probe is up and polling for the master before the clock starts
        start = time.time()
        with open(os.path.join(RESULTS, f"startup{i}.log"), "w") as log:
            proc = subprocess.Popen(["roslaunch", "-p", str(port)] + sim_args(*extra), env=env, stdout=log,
                                    stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, start_new_session=True)
            try:
                out, _ = probe.communicate(timeout=90)
                times.append(json.loads(out.strip().splitlines()[-1])["first_odom_epoch"] - start)
            finally:
                proc.send_signal(signal.SIGINT)
                try:
                    proc.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    os.killpg(proc.pid, signal.SIGKILL)
                    proc.wait()
    return {"median_s": statistics.median(times), "runs_s": times}


def mesh_robot():
    """A two-wheel robot whose base is a 2 MB binary STL (collision and visual), written once into RESULTS."""
    sys.path.insert(0, HERE)
    from mesh_speed import sphere_stl
    folder = os.path.join(RESULTS, "mesh_robot")
    os.makedirs(folder, exist_ok=True)
    stl = os.path.join(folder, "base.stl")
    if not os.path.exists(stl):
        sphere_stl(stl)
    with open(os.path.join(ROOT, "tests", "data", "robots", "fixed_caster.urdf")) as f:
        text = f.read()
    mesh = '<geometry><mesh filename="base.stl" scale="0.001 0.001 0.001"/></geometry>'
    text = text.replace('<visual><geometry><box size="0.2 0.15 0.04"/></geometry></visual>',
                        f'<visual><origin xyz="0 0 0.2"/>{mesh}</visual>')
    text = text.replace('<collision><geometry><box size="0.2 0.15 0.04"/></geometry></collision>',
                        f'<collision><origin xyz="0 0 0.2"/>{mesh}</collision>', 1)
    path = os.path.join(folder, "mesh_robot.urdf")
    with open(path, "w") as f:
        f.write(text)
    return path, os.path.getsize(stl)


def bench_meshes(runs):
    """Start-up to first /odom with 2 MB of STL: every run with an empty mesh cache, then with it filled."""
    import shutil
    path, size = mesh_robot()
    home = os.path.join(RESULTS, "ros_home_meshes")
    cache = os.path.join(home, "diffbot_sim", "mesh_cache")
    cold = bench_startup(runs, (f"model:={path}", "robot_state_publisher:=false"), home,
                         lambda: shutil.rmtree(cache, ignore_errors=True))
    warm = bench_startup(runs, (f"model:={path}", "robot_state_publisher:=false"), home)
    return {"stl_bytes": size, "cold": cold, "cached": warm}


ROS_CONTROL_MODEL = os.path.join(ROOT, "tests", "data", "robots", "ros_control_4wd.urdf")
ROS_CONTROL_YAML = os.path.join(ROOT, "tests", "data", "robots", "ros_control_4wd.yaml")


def ros_control_trial(seconds):
    args = sim_args("real_time:=false", f"model:={ROS_CONTROL_MODEL}", f"controllers:={ROS_CONTROL_YAML}",
                    "robot_state_publisher:=false")
    with Launch(args, "ros_control") as launch:
        for topic in ("/mobile_base_controller/odom", "/joint_states", "/tf"):
            subscriber(launch, [topic])
        result = launch.probe("rtf", seconds=seconds, warmup=3.0, cmd_topics=["/mobile_base_controller/cmd_vel"],
                              leave=True)
        counts = launch.stop_children()
    result["subscriber_messages"] = {k: v for c in counts if c for k, v in c.items()}
    return result


def bench_ros_control(seconds, repeats):
    trials = [ros_control_trial(seconds) for _ in range(repeats)]
    rtfs = [t["rtf"] for t in trials]
    return dict(trials[rtfs.index(statistics.median_low(rtfs))], rtf=statistics.median(rtfs), rtf_runs=rtfs)


DAE = """<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit meter="0.001"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries><geometry id="g"><mesh>
    <source id="p"><float_array id="pa" count="{count}">{points}</float_array>
      <technique_common><accessor source="#pa" count="{vcount}" stride="3"><param name="X" type="float"/>
      <param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <triangles count="{tcount}"><input semantic="VERTEX" source="#v" offset="0"/><p>{indices}</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s"><node><instance_geometry url="#g"/></node></visual_scene>
  </library_visual_scenes><scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"""


def sensor_robot():
    """tests/data/robots/laser_robot.urdf with its IMU given libgazebo_ros_imu_sensor.so at 100 Hz."""
    with open(os.path.join(ROOT, "tests", "data", "robots", "laser_robot.urdf")) as f:
        text = f.read()
    plain = '<sensor type="imu" name="imu"><always_on>true</always_on><update_rate>100</update_rate></sensor>'
    if plain not in text:
        raise RuntimeError("laser_robot.urdf changed: its plugin-less imu sensor is gone")
    text = text.replace(plain, plain.replace("</sensor>", '<plugin name="imu_plugin" filename="libgazebo_ros_imu_sensor'
                                             '.so"><topicName>imu</topicName><frameName>imu_link</frameName>'
                                             "<updateRateHZ>100.0</updateRateHZ></plugin></sensor>"))
    os.makedirs(RESULTS, exist_ok=True)
    path = os.path.join(RESULTS, "sensor_robot.urdf")
    with open(path, "w") as f:
        f.write(text)
    return path


def bench_sensors(runs, seconds, realtime_seconds):
    """Laser (360 beams, 5 Hz) + IMU (100 Hz), both subscribed, in the example world."""
    model, world = sensor_robot(), os.path.join(ROOT, "worlds", "room.world")
    args = (f"model:={model}", f"world:={world}", "robot_state_publisher:=false", "x:=-1.0")
    topics = ["/scan", "/imu", "/odom", "/tf"]
    rtfs, trials = [], []
    for _ in range(runs):
        with Launch(sim_args("real_time:=false", *args), "sensors_fast") as launch:
            for topic in topics:
                subscriber(launch, [topic])
            trial = launch.probe("rtf", seconds=seconds, warmup=3.0, leave=True)
            trial["subscriber_messages"] = {k: v for c in launch.stop_children() if c for k, v in c.items()}
        rtfs.append(trial["rtf"])
        trials.append(trial)
    with Launch(sim_args(*args), "sensors_realtime") as launch:
        for topic in topics:
            subscriber(launch, [topic])
        realtime = launch.probe("rtf", seconds=realtime_seconds, warmup=3.0, timeout=realtime_seconds + 120)
    fast = dict(trials[rtfs.index(statistics.median_low(rtfs))], rtf=statistics.median(rtfs), rtf_runs=rtfs)
    return {"fast": fast, "realtime": realtime}


def mesh_world(models=30, segments=64):
    """A world of ``models`` static models, each a cylinder-ish COLLADA mesh (mm units) of its own file."""
    import math
    folder = os.path.join(RESULTS, "mesh_world")
    os.makedirs(folder, exist_ok=True)
    lines = ['<?xml version="1.0"?>', '<sdf version="1.6"><world name="mesh_world">',
             "<include><uri>model://ground_plane</uri></include><include><uri>model://sun</uri></include>"]
    for k in range(models):
        r = 150.0 + 5 * k
        points, tris = [], []
        for i in range(segments):
            a = 2 * math.pi * i / segments
            points += [(r * math.cos(a), r * math.sin(a), 0.0), (r * math.cos(a), r * math.sin(a), 800.0)]
        for i in range(segments):
            j = (i + 1) % segments
            tris += [(2 * i, 2 * j, 2 * j + 1), (2 * i, 2 * j + 1, 2 * i + 1)]
        name = os.path.join(folder, f"obstacle{k}.dae")
        with open(name, "w") as f:
            f.write(DAE.format(count=3 * len(points), vcount=len(points), tcount=len(tris),
                               points=" ".join(f"{c:g}" for pt in points for c in pt),
                               indices=" ".join(str(i) for t in tris for i in t)))
        x, y = 2.0 + 1.5 * (k % 6), -4.0 + 1.5 * (k // 6)
        lines.append(f'<model name="obstacle{k}"><static>true</static><pose>{x} {y} 0 0 0 0</pose><link name="l">'
                     f'<collision name="c"><geometry><mesh><uri>obstacle{k}.dae</uri></mesh></geometry></collision>'
                     f"</link></model>")
    lines.append("</world></sdf>")
    path = os.path.join(folder, "mesh_world.world")
    with open(path, "w") as f:
        f.write("\n".join(lines))
    return path


def bench_worlds(runs, seconds):
    """Load times of a mesh world and of 4000 x 4000 maps; RTF in the example world against none."""
    import shutil
    sys.path.insert(0, os.path.join(ROOT, "src"))
    from diffbot_sim.world import map_image as world_map
    out = {}
    home = os.path.join(RESULTS, "ros_home_worlds")
    cache = os.path.join(home, "diffbot_sim", "mesh_cache")
    world = mesh_world()
    out["mesh_world"] = bench_startup(runs, (f"world:={world}", "robot_state_publisher:=false"), home,
                                      lambda: shutil.rmtree(cache, ignore_errors=True))
    # The furnished house of meshes (tests/data/multi_way: 30 000 triangles in COLLADA, STL and OBJ, found as
    # model://house through tb3like_gazebo's gazebo_model_path export), with the mesh cache warm: one run fills it.
    from run_tests import MULTI_FIXTURES, add_package_path  # tools/: the fixture packages the test suites use
    add_package_path(MULTI_FIXTURES)
    house = (f"world:={os.path.join(MULTI_FIXTURES, 'tb3like_gazebo', 'worlds', 'house.world')}",
             "robot_state_publisher:=false")
    bench_startup(1, house, home)
    out["house_world"] = bench_startup(runs, house, home)
    out["empty_world"] = bench_startup(runs, ("robot_state_publisher:=false",), home)
    for key, noise in (("map_floor_plan", 0.0), ("map_speckled", 0.02)):
        path = world_map.synthetic_map(os.path.join(RESULTS, f"{key}.yaml"), size=4000, noise=noise)
        out[key] = bench_startup(runs, (f"world:={path}", "robot_state_publisher:=false"), home)
    rtf = {"room": [], "empty": []}
    for _ in range(runs):
        for key, extra in (("room", (f"world:={os.path.join(ROOT, 'worlds', 'room.world')}",)), ("empty", ())):
            with Launch(sim_args("real_time:=false", "robot_state_publisher:=false", *extra), f"world_{key}") as launch:
                for topic in TOPICS[1:]:
                    subscriber(launch, [topic])
                rtf[key].append(launch.probe("rtf", seconds=seconds, warmup=3.0, leave=True)["rtf"])
    out["rtf_room"], out["rtf_empty"] = statistics.median(rtf["room"]), statistics.median(rtf["empty"])
    out["rtf_runs"] = rtf
    return out


def scale_launch(count, rsp):
    """A real-time launch file for ``count`` namespaced seed robots on a 1 m grid (like multi.launch), each
    with its robot_state_publisher when ``rsp``."""
    root = ET.Element("launch")
    ET.SubElement(root, "param", name="use_sim_time", value="true")
    ET.SubElement(root, "param", name="robot_description", command=f"xacro '{MODEL}'")
    node = ET.SubElement(root, "node", name="bullet_sim", pkg="diffbot_sim", type="bullet_sim", required="true")
    robots = [{"name": f"robot{i + 1}", "x": float(i % 10), "y": float(i // 10)} for i in range(count)]
    ET.SubElement(node, "rosparam", param="robots").text = json.dumps(robots)
    for robot in robots if rsp else ():
        inc = ET.SubElement(root, "include", file=os.path.join(ROOT, "launch", "robot_state.launch"), ns=robot["name"])
        ET.SubElement(inc, "arg", name="tf_prefix", value=robot["name"])
    path = os.path.join(RESULTS, f"scale_{count}{'_rsp' if rsp else ''}.launch")
    ET.ElementTree(root).write(path)
    return path


def scale_trial(count, seconds, rsp):
    tag = f"scale_{count}{'_rsp' if rsp else ''}"
    with Launch([scale_launch(count, rsp)], tag) as launch:
        names = [f"/robot{i + 1}" for i in range(count)]
        for name in names:  # one consumer process per robot, as each robot would have its own nodes
            subscriber(launch, [f"{name}/odom", f"{name}/joint_states"])
        subscriber(launch, ["/tf"])
        return launch.probe("rtf", seconds=seconds, warmup=5.0, namespaces=names, timeout=seconds + 300)


def bench_scale(seconds, rsp):
    """Largest robot count the simulator keeps at RTF >= 0.99 in real-time mode (grow by 10, then bisect).

    Real-time mode is the one that counts: fast mode batches writes, which makes it cheaper per simulated
    second than pacing to the clock, so a fast-mode RTF >= 1 overstates the count."""
    trials = {}

    def ok(count):
        if count not in trials:
            trials[count] = scale_trial(count, seconds, rsp)
            print(f"[bench] scale{' +rsp' if rsp else ''}: {count} robots, real-time RTF "
                  f"{trials[count]['rtf']:.3f}, simulator CPU {trials[count]['cpu_percent']:.0f} %", flush=True)
        return trials[count]["rtf"] >= 0.99
    good, bad, count = 0, None, 10
    while count <= 100:
        if ok(count):
            good, count = count, count + 10
        else:
            bad = count
            break
    while bad is not None and bad - good > 1:
        mid = (good + bad) // 2
        if ok(mid):
            good = mid
        else:
            bad = mid
    best = trials.get(good)
    return {"realtime_rtf_by_count": {k: v["rtf"] for k, v in sorted(trials.items())},
            "max_robots_rtf_ge_1": good,
            "realtime_rtf_at_max": best["rtf"] if best else None,
            "sim_cpu_percent_at_max": best["cpu_percent"] if best else None}


# -------------------------------------------------------------------------------------------------- main

def _batch(spec, out, jobs):
    """Run `batch` on ``spec`` (fresh ``out``); its records and wall time."""
    shutil.rmtree(out, ignore_errors=True)
    t0 = time.monotonic()
    subprocess.run([sys.executable, "-m", "diffbot_sim.nodes.batch_cli", spec, "--out", out, "--jobs", str(jobs)],
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
    wall = time.monotonic() - t0
    from diffbot_sim.batch import results as batch_results

    return list(batch_results.load(os.path.join(out, "results.jsonl")).values()), wall


def bench_batch(runs):
    """`batch`: its overhead per run (the same rostest alone vs. through batch, median of ``runs``), and the
    drive example (examples/batch/drive.yaml, its diffbot x {empty, room} x seed 1 part) at --jobs 1 and 2:
    runs per hour per core and the speed-up."""
    import tempfile

    tmp = tempfile.mkdtemp(prefix="bench_batch_")
    test = os.path.join(ROOT, "tests", "rostest", "sleeper.test")
    alone = []
    for _ in range(runs):
        t0 = time.monotonic()
        subprocess.run(["rostest", "--results-base-dir", os.path.join(tmp, "alone"), test],
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
        alone.append(time.monotonic() - t0)
    spec = os.path.join(tmp, "one.yaml")
    with open(spec, "w") as f:
        f.write(f"scenarios:\n  - name: one\n    test: {test}\n")
    through = [_batch(spec, os.path.join(tmp, "one"), 1)[1] for _ in range(runs)]
    spec = os.path.join(tmp, "drive.yaml")
    with open(spec, "w") as f:
        f.write("scenarios:\n  - name: drive-{robot}-{world}-{seed}\n    test: diffbot_sim/tests/rostest/drive.test\n"
                "    matrix: {robot: [diffbot, 4wd], world: [empty.world, room.world], seed: [1]}\n")
    result = {"rostest_alone_s": statistics.median(alone), "through_batch_s": statistics.median(through)}
    for jobs in (1, 2):
        records, wall = _batch(spec, os.path.join(tmp, f"drive{jobs}"), jobs)
        result[f"jobs{jobs}"] = {"wall_s": wall, "runs": len(records),
                                 "passed": sum(r["status"] == "passed" for r in records),
                                 "runs_per_hour_per_core": len(records) / wall * 3600 / jobs,
                                 "median_rtf": statistics.median(r["rtf"] for r in records)}
    shutil.rmtree(tmp, ignore_errors=True)
    return result


def table(r):
    rows = []
    f, n, b = r.get("fast"), r.get("fast_no_rsp"), r.get("bare")
    if f and b:
        rows += [("bare PyBullet RTF, same model and step", f"{b['rtf']:.1f}", ""),
                 ("fast-mode RTF, sim.launch defaults (+RSP)", f"{f['rtf']:.1f}", ">= 40"),
                 ("  fast / bare", f"{f['rtf'] / b['rtf']:.2f}", ">= 0.5"),
                 ("fast-mode RTF, robot_state_publisher:=false", f"{n['rtf']:.1f}", ">= 40"),
                 ("  fast / bare", f"{n['rtf'] / b['rtf']:.2f}", ">= 0.5")]
        if r.get("fast_commander"):
            rows.append(("  the same, a rospy node publishing cmd_vel in the loop", f"{r['fast_commander']['rtf']:.1f}", ""))
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
        rows.append(("bare PyBullet paced to real time, CPU (the floor)", f"{r['bare_paced']['cpu_percent']:.1f} % of a core", ""))
    if r.get("latency"):
        lat = r["latency"]
        rows.append(("cmd_vel -> motor target p50 / p99", f"{lat['p50_ms']:.2f} / {lat['p99_ms']:.2f} ms",
                     f"p99 <= {1000 * STEP + 2:.2f} ms"))
    if r.get("startup"):
        rows.append(("roslaunch -> first /odom (median of 5)", f"{r['startup']['median_s']:.2f} s", "<= 3 s"))
    if r.get("meshes"):
        m = r["meshes"]
        rows += [(f"first /odom, {m['stl_bytes'] / 1e6:.1f} MB STL, empty mesh cache", f"{m['cold']['median_s']:.2f} s",
                  "<= 2 s"),
                 ("  same, mesh cache filled", f"{m['cached']['median_s']:.2f} s", "")]
    if r.get("sensors"):
        se = r["sensors"]
        rows += [("fast-mode RTF, laser 360 beams @5 Hz + IMU @100 Hz subscribed, room.world", f"{se['fast']['rtf']:.1f}",
                  ">= 30"),
                 ("  the same in real time: simulator CPU", f"{se['realtime']['cpu_percent']:.1f} % of a core", "<= 15 %")]
    if r.get("worlds"):
        w = r["worlds"]
        rows += [("first /odom, world of 30 COLLADA mesh models (empty cache)", f"{w['mesh_world']['median_s']:.2f} s",
                  "<= 3 s"),
                 ("first /odom, the furnished house of meshes (cache warm) / no world",
                  f"{w['house_world']['median_s']:.2f} s / {w['empty_world']['median_s']:.2f} s", "<= 2 s"),
                 ("first /odom, 4000 x 4000 map, floor plan", f"{w['map_floor_plan']['median_s']:.2f} s", "<= 3 s"),
                 ("first /odom, 4000 x 4000 map, 2 % speckle", f"{w['map_speckled']['median_s']:.2f} s", "<= 3 s"),
                 ("fast-mode RTF in worlds/room.world / empty world",
                  f"{w['rtf_room']:.1f} / {w['rtf_empty']:.1f} = {w['rtf_room'] / w['rtf_empty']:.2f}", ">= 0.8")]
    if r.get("ros_control"):
        rows.append(("fast-mode RTF, 4-wheel ros_control robot (DDC)", f"{r['ros_control']['rtf']:.1f}", ">= 30"))
    for key, label in (("scale", "robots at RTF >= 1 (all topics)"),
                       ("scale_rsp", "  same, + robot_state_publisher each")):
        if r.get(key):
            s = r[key]
            value = (f"{s['max_robots_rtf_ge_1']} (real-time RTF {s['realtime_rtf_at_max']:.3f})"
                     if s["realtime_rtf_at_max"] else "0")
            rows.append((label, value, ">= 10" if key == "scale" else ""))
    if r.get("world_api"):
        w = r["world_api"]
        rows += [("spawn_urdf_model -> first odom of the robot (median)", f"{w['spawn_median_s']:.3f} s", "<= 0.5 s"),
                 ("set_model_state round trip p50 / p99 (real time)",
                  f"{w['set_model_state_p50_ms']:.2f} / {w['set_model_state_p99_ms']:.2f} ms", "<= 5 ms")]
    if r.get("batch"):
        b = r["batch"]
        rows += [("batch: overhead per run over the same rostest alone (median)",
                  f"{b['through_batch_s'] - b['rostest_alone_s']:.2f} s", "< 1 s"),
                 ("batch: drive runs per hour per core, --jobs 1 / --jobs 2",
                  f"{b['jobs1']['runs_per_hour_per_core']:.0f} / {b['jobs2']['runs_per_hour_per_core']:.0f}", ""),
                 ("  speed-up of --jobs 2 over --jobs 1 (2 cores)",
                  f"{b['jobs1']['wall_s'] / b['jobs2']['wall_s']:.2f}", "")]
    rows += _wave().rows(r)
    width = max(len(name) for name, _, _ in rows)
    lines = [f"{'measure'.ljust(width)}  {'value':>28}  target", "-" * (width + 40)]
    lines += [f"{name.ljust(width)}  {value:>28}  {target}" for name, value, target in rows]
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--probe", help=argparse.SUPPRESS)
    parser.add_argument("--options", default="{}", help=argparse.SUPPRESS)
    parser.add_argument("--only", default="fast,realtime,latency,startup,scale,meshes,ros_control,worlds,sensors,"
                        "world_api,batch,arm,lockstep,gym,fleet",
                        help="comma-separated items to run (default: all)")
    parser.add_argument("--quick", action="store_true", help="shorter windows (smoke run, not for figures)")
    args = parser.parse_args()
    if args.probe:
        probes = dict(PROBES, **_wave().PROBES)
        probes[args.probe](json.loads(args.options))
        return 0
    os.makedirs(RESULTS, exist_ok=True)
    items = set(args.only.split(","))
    q = args.quick
    results = {"time_step": STEP, "date": time.strftime("%Y-%m-%d %H:%M:%S"), "cpus": os.cpu_count()}
    steps = [("fast", lambda: bench_fast(4 if q else 12, 1 if q else 3)),
             ("realtime", lambda: bench_realtime(10 if q else 60)), ("latency", lambda: bench_latency(100 if q else 600)),
             ("startup", lambda: bench_startup(2 if q else 5)), ("scale", lambda: bench_scale(4 if q else 8, False)),
             ("scale_rsp", lambda: bench_scale(4 if q else 8, True)),
             ("meshes", lambda: bench_meshes(1 if q else 3)),
             ("ros_control", lambda: bench_ros_control(4 if q else 12, 1 if q else 3)),
             ("worlds", lambda: bench_worlds(1 if q else 3, 4 if q else 10)),
             ("sensors", lambda: bench_sensors(1 if q else 3, 4 if q else 10, 10 if q else 30)),
             ("world_api", lambda: bench_world_api(3 if q else 7, 100 if q else 1000)),
             ("batch", lambda: bench_batch(2 if q else 5))]
    steps += [(name, lambda run=run: run(q)) for name, run in _wave().STEPS]
    for name, run in steps:
        wanted = name in items or (name == "scale_rsp" and "scale" in items)
        if not wanted:
            continue
        print(f"[bench] {name} ...", flush=True)
        if name in ("fast", "realtime"):
            results.update(run())
        else:
            results[name] = run()
        print(f"[bench] {name}: {json.dumps(results.get(name))}", flush=True)
    path = os.path.join(RESULTS, "bench.json")
    with open(path, "w") as f:
        json.dump(results, f, indent=2)
    print(table(results))
    print(f"[bench] written {path}")
    return 0


if __name__ == "__main__":
    from diffbot_sim import streams  # a closed pipe (`make test | head`) must not turn the status into 120

    try:
        STATUS = main()
    finally:
        streams.finish()
    sys.exit(STATUS)
