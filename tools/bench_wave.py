"""``make bench`` items of the manipulator, loop and fleet work (tools/bench.py runs them; probes register there).

Items:
  arm        fast-mode RTF of a base with a 6-joint arm (tests/data/robots/mobile_arm6) following a long position
             trajectory, /joint_states, /tf, /odom and the controller's state subscribed; bare PyBullet stepping
             the same model with the same joint targets; the ratio. Trajectory command -> first motion of the
             arm (sim time, /gazebo/link_states), median of 20, at real time.
  lockstep   a Gazebo-style step-and-wait learning environment (publish cmd_vel, rospy.wait_for_message
             /scan, 5 Hz laser) against fast mode: steps per second, the sim time each action was held
             (median and 95th percentile; one scan period is right).
  gym        tools/gym_speed.py: in-process env steps per second per core, its ratio to bare PyBullet, resets
             per second.
  fleet      TurtleBot3-class robots (tests/data/multi_way/tb3like: diff drive at 30 Hz, 360-beam laser at
             5 Hz; its IMU left out) in one simulator at real time, driving circles, every robot's /odom and
             /scan subscribed: the largest count at RTF >= 0.99 as the simulator starts by default (every ray
             cast in its own process) and with its rays in the ray process (~ray_process true), without
             lasers, and with a robot_state_publisher each;
             against bare PyBullet stepping the same robots (same model, step, wheel speeds and torque) and
             casting their lasers' scans as the simulator does, in pairs run back to back at the simulator's
             count (the reference), and physics only; the simulator's cost per robot (CPU us per sim second).
"""
import json
import os
import re
import statistics
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

import bench
from bench import CIRCLE, RESULTS, ROOT, STEP, Launch, check_upright, sim_args, subscriber

ARM_MODEL = os.path.join(ROOT, "tests", "data", "robots", "mobile_arm6.urdf.xacro")
ARM_YAML = os.path.join(ROOT, "tests", "data", "robots", "mobile_arm6.yaml")
ARM_JOINTS = [f"joint_{k}" for k in range(1, 7)]
#: (wheel radius, wheel separation) [m] of mobile_arm6, as its diff drive plugin reads them
ARM_WHEELS = (0.032, 0.2)
LASER_ROBOT = os.path.join(ROOT, "tests", "data", "robots", "laser_robot.urdf")
TB3LIKE = os.path.join(ROOT, "tests", "data", "multi_way", "tb3like_description", "urdf", "tb3like.urdf.xacro")
# the fleet's robot is a Gazebo user's package (package:// meshes, $(find tb3like_description)): findable by
# xacro here and by every launch started from here
os.environ["ROS_PACKAGE_PATH"] = os.pathsep.join(
    [p for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    + [os.path.join(ROOT, "tests", "data", "multi_way")])


# ---------------------------------------------------------------------------------------------------- arm

def arm_targets(t):
    """The arm's joint targets [rad] at time t [s]: slow sines, every joint moving."""
    import math
    return [0.6 * math.sin(0.5 * t + k) for k in range(6)]


def probe_arm_motion(options):
    """Send a long trajectory (``trajectory_s`` of sim time, points every 0.1 s) on /arm_controller/command, then
    measure RTF as probe_rtf. With ``leave``, the probe closes its command publishers once they were sent (fast
    mode waits after each /clock tick for nodes that publish commands: staying, the probe measured itself)."""
    import rospy
    from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint
    rospy.init_node("bench_arm", disable_signals=True)
    pub = rospy.Publisher("/arm_controller/command", JointTrajectory, queue_size=1, latch=True)
    msg = JointTrajectory(joint_names=ARM_JOINTS)
    for k in range(1, int(round(options.get("trajectory_s", 60.0) / 0.1)) + 1):
        msg.points.append(JointTrajectoryPoint(positions=arm_targets(k * 0.1),
                                               time_from_start=rospy.Duration.from_sec(k * 0.1)))
    bench._wait(lambda: pub.get_num_connections() > 0, 60, "the trajectory controller's command topic")
    pub.publish(msg)
    if options.get("leave"):
        time.sleep(0.5)  # written at once on the open connection; the controller keeps a trajectory it was sent
        pub.unregister()
    bench.probe_rtf(options)


def probe_arm_latency(options):
    """Trajectory command -> first motion: sim time from the command's start (the next control update after
    its receipt: stamp 0) to the first /gazebo/link_states where the arm's last link has moved 1 mm."""
    import math

    import rospy
    from gazebo_msgs.msg import LinkStates
    from rosgraph_msgs.msg import Clock
    from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint
    rospy.init_node("bench_arm_latency", disable_signals=True)
    states = []
    clock = []
    # link_states carry no stamp: each is stamped with the newest /clock (100 Hz: a 10 ms resolution)
    rospy.Subscriber("/gazebo/link_states", LinkStates, lambda m: states.append((clock[-1] if clock else 0.0, m)),
                     queue_size=2000)
    rospy.Subscriber("/clock", Clock, lambda m: clock.append(m.clock.to_sec()), queue_size=10)
    pub = rospy.Publisher("/arm_controller/command", JointTrajectory, queue_size=1)
    bench._wait(lambda: pub.get_num_connections() > 0 and clock and states, 60, "the arm and link_states")
    delays = []
    for trial in range(options["count"]):
        target = 0.3 if trial % 2 == 0 else -0.3
        time.sleep(0.5)
        before = _tip(states[-1][1])
        sent = clock[-1]
        msg = JointTrajectory(joint_names=ARM_JOINTS)
        msg.points.append(JointTrajectoryPoint(positions=[target] * 6, time_from_start=rospy.Duration(1.0)))
        pub.publish(msg)
        bench._wait(lambda: math.dist(_tip(states[-1][1]), before) > 0.001, 30, "the arm moving")
        moved = next(t for t, m in states if t >= sent and math.dist(_tip(m), before) > 0.001)
        delays.append(moved - sent)
    print(json.dumps({"command_to_motion_median_s": statistics.median(delays), "max_s": max(delays),
                      "trials": len(delays)}), flush=True)


def _tip(msg):
    for name, pose in zip(msg.name, msg.pose):
        if name.endswith("::link_6"):
            return (pose.position.x, pose.position.y, pose.position.z)
    raise RuntimeError("no link_6 in link_states")


def bare_arm(seconds):
    """mobile_arm6 loaded as bullet_sim loads it, joints as the position trajectory drives them (stiff position
    motors, targets renewed every 10 ms), wheels turning, stepped by PyBullet alone."""
    sys.path.insert(0, os.path.join(ROOT, "src"))
    from diffbot_sim.description.model_files import load_file
    from diffbot_sim.description.urdf_model import parse_urdf
    from diffbot_sim.physics import World
    text = load_file(ARM_MODEL)
    world = World(STEP)
    try:
        robot = world.load_robot(text, parse_urdf(text, ARM_MODEL))
        joints = robot.indices(ARM_JOINTS)
        wheels = robot.indices(["left_wheel_joint", "right_wheel_joint"])
        # Set going as the simulator does it, or the robot falls over (an earlier version of this reference did:
        # full wheel speed and the arm's first targets at once tipped it on its side within 2 s, and a robot on
        # its side steps at twice the speed): the circle's wheel speeds reached at the plugin's 1.8 m/s^2, the
        # arm blended in from rest over the first second, as its trajectory controller starts it.
        speeds = [(CIRCLE[0] - CIRCLE[1] * ARM_WHEELS[1] / 2) / ARM_WHEELS[0],
                  (CIRCLE[0] + CIRCLE[1] * ARM_WHEELS[1] / 2) / ARM_WHEELS[0]]
        ramp = CIRCLE[0] / 1.8

        def command(t):
            share = min(1.0, t / ramp)
            robot.set_velocities(wheels, [share * v for v in speeds], [30.0, 30.0])
            blend = min(1.0, t)
            robot.set_positions(joints, [blend * q for q in arm_targets(t)], [1e4] * 6, 1.0)
        for k in range(480):
            command(k * STEP)
            world.step()
        steps, start = 480, time.perf_counter()
        while time.perf_counter() - start < seconds:
            if steps % 2 == 0:
                command(steps * STEP)
            world.step()
            steps += 1
        elapsed = time.perf_counter() - start
        check_upright(robot, "mobile arm")
    finally:
        world.close()
    return {"rtf": (steps - 480) * STEP / elapsed}


def bench_arm(seconds, repeats):
    runs = {"sim": [], "bare": []}
    args = sim_args("real_time:=false", f"model:={ARM_MODEL}", f"controllers:={ARM_YAML}",
                    "robot_state_publisher:=false")
    for _ in range(repeats):
        runs["bare"].append(bare_arm(seconds / 2)["rtf"])
        with Launch(args, "arm") as launch:
            for topic in ("/joint_states", "/tf", "/odom", "/arm_controller/state"):
                subscriber(launch, [topic])
            # the trajectory outlasts the window (4 s of warm-up and leaving + the window, at up to RTF 60)
            runs["sim"].append(launch.probe("arm_motion", seconds=seconds, warmup=3.0, leave=True,
                                            trajectory_s=60.0 * (seconds + 4.0))["rtf"])
    with Launch(sim_args(f"model:={ARM_MODEL}", f"controllers:={ARM_YAML}", "robot_state_publisher:=false"),
                "arm_latency") as launch:
        latency = launch.probe("arm_latency", count=20, timeout=300)
    sim, bare = statistics.median(runs["sim"]), statistics.median(runs["bare"])
    return {"rtf": sim, "bare_rtf": bare, "ratio": sim / bare, "runs": runs, **latency}


# ----------------------------------------------------------------------------------------------- lockstep

def probe_lockstep(options):
    """TurtleBot3's learning environment's step (publish cmd_vel, wait_for_message scan) repeated."""
    import rospy
    from geometry_msgs.msg import Twist
    from sensor_msgs.msg import LaserScan
    rospy.init_node("bench_lockstep", disable_signals=True)
    pub = rospy.Publisher("/cmd_vel", Twist, queue_size=5)
    bench._wait(lambda: pub.get_num_connections() > 0, 60, "the simulator's cmd_vel")
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
                      "held_median_s": statistics.median(held), "held_p95_s": bench.percentile(held, 95),
                      "held_max_s": max(held)}), flush=True)


def bench_lockstep(steps, repeats):
    trials = []
    for _ in range(repeats):
        with Launch(sim_args("real_time:=false", f"model:={LASER_ROBOT}", "robot_state_publisher:=false",
                             f"world:={os.path.join(ROOT, 'tests', 'data', 'worlds', 'laser_room.world')}"),
                    "lockstep") as launch:
            trials.append(launch.probe("lockstep", steps=steps, timeout=600))
    best = sorted(trials, key=lambda t: t["steps_per_s"])[len(trials) // 2]
    return dict(best, steps_per_s_runs=[t["steps_per_s"] for t in trials])


def bench_gym():
    out = subprocess.run([sys.executable, os.path.join(ROOT, "tools", "gym_speed.py")],
                         capture_output=True, text=True, timeout=1200)
    lines = [line for line in out.stdout.splitlines() if line.startswith("{")]
    if not lines:
        raise RuntimeError(f"gym_speed.py printed no figures: {out.stderr.strip()[-300:]}")
    return json.loads(lines[-1])


# -------------------------------------------------------------------------------------------------- fleet

def fleet_model(laser):
    """tb3like's URDF (xacro'd) without its IMU, and without its laser unless ``laser``; written to a file."""
    sys.path.insert(0, os.path.join(ROOT, "src"))
    from diffbot_sim.description.model_files import load_file
    root = ET.fromstring(load_file(TB3LIKE))
    for gazebo in root.findall("gazebo"):
        for sensor in list(gazebo.findall("sensor")):
            if sensor.get("type") == "imu" or (sensor.get("type") == "ray" and not laser):
                gazebo.remove(sensor)
        for plugin in list(gazebo.findall("plugin")):
            if "imu" in (plugin.get("filename") or ""):
                gazebo.remove(plugin)
    path = os.path.join(RESULTS, f"tb3like{'_laser' if laser else ''}.urdf")
    ET.ElementTree(root).write(path)
    return path


def fleet_launch(count, model, rsp, ray_process=None):
    root = ET.Element("launch")
    ET.SubElement(root, "param", name="use_sim_time", value="true")
    ET.SubElement(root, "param", name="robot_description", textfile=model)
    node = ET.SubElement(root, "node", name="bullet_sim", pkg="diffbot_sim", type="bullet_sim", required="true")
    if ray_process is not None:  # else the simulator's default (false)
        ET.SubElement(node, "param", name="ray_process", value=str(ray_process).lower())
    robots = [{"name": f"tb3_{i}", "x": float(i % 10), "y": float(i // 10)} for i in range(count)]
    ET.SubElement(node, "rosparam", param="robots").text = json.dumps(robots)
    for robot in robots if rsp else ():
        inc = ET.SubElement(root, "include", file=os.path.join(ROOT, "launch", "robot_state.launch"), ns=robot["name"])
        ET.SubElement(inc, "arg", name="tf_prefix", value=robot["name"])
    variant = ("_rsp" if rsp else "") + ("" if ray_process is None else f"_rp_{ray_process}")
    path = os.path.join(RESULTS, f"fleet_{count}{variant}.launch")
    ET.ElementTree(root).write(path)
    return path


def fleet_trial(count, seconds, model, rsp, laser, ray_process=None):
    with Launch([fleet_launch(count, model, rsp, ray_process)], f"fleet_{count}") as launch:
        names = [f"/tb3_{i}" for i in range(count)]
        topics = [f"{n}/odom" for n in names] + ([f"{n}/scan" for n in names] if laser else [])
        subscriber(launch, topics)  # one consumer for all: the machine's second core is not a neighbour's
        result = launch.probe("rtf", seconds=seconds, warmup=8.0, namespaces=names, timeout=seconds + 600)
    result["us_per_robot_per_sim_s"] = 1e6 * result["cpu_percent"] / 100.0 / result["rtf"] / count
    return result


def loadable(model):
    """``(urdf_text, parsed)`` of the model file as the simulator loads it (package:// meshes resolved and
    cached), for ``World.load_robot`` without ROS."""
    sys.path.insert(0, os.path.join(ROOT, "src"))
    from diffbot_sim.description import meshes
    from diffbot_sim.description.model_files import package_path
    from diffbot_sim.description.urdf_model import parse_urdf
    with open(model) as f:
        text = f.read()
    parsed = parse_urdf(text, model)
    text, _ = meshes.prepare_meshes(text, model, os.path.dirname(model), meshes.default_cache_dir(), package_path)
    return text, parsed


def fleet_laser(model):
    """``(link, RayConfig)`` of the model's ray sensor, read as the simulator reads it (``parse_sensor``)."""
    from diffbot_sim.sensors.ray import parse_sensor
    for gazebo in ET.parse(model).getroot().findall("gazebo"):
        for sensor in gazebo.findall("sensor"):
            if sensor.get("type") == "ray":
                link = gazebo.get("reference")
                return link, parse_sensor(sensor, f"{model}: <gazebo reference=\"{link}\"><sensor>")
    raise ValueError(f"{model}: no <sensor type=\"ray\">")


def fleet_wheels(model):
    """(left, right) wheel speeds [rad/s] of the fleet's robots driving the rtf probe's CIRCLE, and their motors'
    force limit [N m], from the model's diff drive tags (<wheelSeparation>, <wheelDiameter>, <wheelTorque>), as
    the simulator's diff drive sets them."""
    for plugin in ET.parse(model).getroot().iter("plugin"):
        if "diff_drive" in (plugin.get("filename") or ""):
            separation = float(plugin.findtext("wheelSeparation"))
            radius = float(plugin.findtext("wheelDiameter")) / 2.0
            v, w = CIRCLE
            return ((v - w * separation / 2.0) / radius, (v + w * separation / 2.0) / radius,
                    float(plugin.findtext("wheelTorque")))
    raise ValueError(f"{model}: no diff drive plugin")


def bare_fleet(count, seconds, model, lasers):
    """``count`` of the same robots stepped by PyBullet alone (same step), their wheels turning as the
    simulator turns them for the rtf probe's circle (same speeds, same motor force): their RTF.

    With ``lasers``, bare PyBullet also casts every robot's scan as the simulator casts it: the model's
    rays (``ray_directions``) from the laser's link, at its ``<update_rate>``, all robots on the same step
    (the simulator's lasers share one schedule), through ``World.ray_batch``. Nothing is made of the hits:
    no noise, no message, no ROS."""
    from diffbot_sim.physics import World
    from diffbot_sim.sensors import ray as ray_sensor
    text, parsed = loadable(model)
    left, right, torque = fleet_wheels(model)
    if lasers:
        link, cfg = fleet_laser(model)
        pose, _ = ray_sensor.mounted_pose(cfg, parsed, link)
        directions = ray_sensor.ray_directions(cfg)
        every = max(1, round(1.0 / cfg.update_rate / STEP))
    world = World(STEP)
    try:
        for i in range(count):
            robot = world.load_robot(text, parsed, (float(i % 10), float(i // 10), 0.0))
            robot.set_velocities(robot.indices(["wheel_left_joint", "wheel_right_joint"]), [left, right],
                                 [torque, torque])
        for _ in range(240):
            world.step()
        steps, start = 0, time.perf_counter()
        while time.perf_counter() - start < seconds:
            world.step()
            steps += 1
            if lasers and steps % every == 0:
                for robot in world.robots:
                    origin, rotation = ray_sensor.sensor_pose(*robot.link_pose(link), pose)
                    world.ray_batch(*ray_sensor.world_rays(origin, rotation, directions, cfg.range_min,
                                                           cfg.range_max))
        elapsed = time.perf_counter() - start
        for robot in world.robots:
            check_upright(robot, "fleet robot")
        return steps * STEP / elapsed
    finally:
        world.close()


def largest(trial, start):
    """The largest count whose trial holds RTF >= 0.99 (grow by 10s from ``start``, then bisect)."""
    trials = {}

    def ok(count):
        if count not in trials:
            trials[count] = trial(count)
            print(f"[bench] fleet: {count} robots, RTF {trials[count]['rtf']:.3f}", flush=True)
        return trials[count]["rtf"] >= 0.99
    good, bad, count = 0, None, start
    while count <= 200:
        if ok(count):
            good, count = count, count + 10
        else:
            bad = count
            break
    while bad is not None and bad - good > 1:
        mid = (good + bad) // 2
        good, bad = (mid, bad) if ok(mid) else (good, mid)
    return good, trials


def bench_fleet(seconds):
    """The fleet item. This VM's speed drifts by tens of percent within minutes (bare PyBullet stepping the
    same 66 robots: RTF 0.97-1.18 in one quarter of an hour), so every comparison with bare PyBullet is made of
    pairs run back to back at the same count: the simulator's count is bisected first; then bare and the
    simulator run three times each, alternately, at that count, and the ratio is the median of the pairs'."""
    laser_model, bare_model = fleet_model(True), fleet_model(False)
    guess = bare_fleet(60, 5.0, laser_model, True) * 60  # where to start looking: about 0.6-0.8 of this
    out = {}
    # The simulator as it starts by default (every ray cast in its own process), and with its rays cast in the
    # ray process (~ray_process true).
    for key, model, rsp, laser, ray_process in (("laser", laser_model, False, True, None),
                                                ("laser_ray_process", laser_model, False, True, True),
                                                ("no_laser", bare_model, False, False, None),
                                                ("laser_rsp", laser_model, True, True, None)):
        count, trials = largest(lambda n: fleet_trial(n, seconds, model, rsp, laser, ray_process),
                                10 if rsp else max(10, int(guess * 0.6) // 10 * 10))
        out[key] = {"robots_at_real_time": count, "rtf_by_count": {k: v["rtf"] for k, v in sorted(trials.items())},
                    "us_per_robot_per_sim_s": trials[count]["us_per_robot_per_sim_s"] if count in trials else None}
    pairs = []
    for key, ray_process in (("laser", None), ("laser_ray_process", True)):
        count = out[key]["robots_at_real_time"]
        for _ in range(3):
            bare_rtf = bare_fleet(count, 5.0, laser_model, True)
            sim_rtf = fleet_trial(count, seconds, laser_model, False, True, ray_process)["rtf"]
            pairs.append({"simulator": key, "robots": count, "bare_rtf": bare_rtf, "simulator_rtf": sim_rtf,
                          "ratio": sim_rtf / bare_rtf})
            print(f"[bench] fleet pair ({key}): {count} robots, bare RTF {bare_rtf:.3f}, simulator {sim_rtf:.3f}",
                  flush=True)
        runs = [p for p in pairs if p["simulator"] == key]
        out[key]["bare_robots_at_real_time"] = round(statistics.median([count * p["bare_rtf"] for p in runs]), 1)
        out[key]["ratio_to_bare"] = round(statistics.median([p["ratio"] for p in runs]), 3)
    physics = {n: bare_fleet(n, 5.0, laser_model, False) for n in (40, 60)}
    physics_count = round(statistics.median([n * r for n, r in physics.items()]), 1)
    out.update({"pairs": pairs, "bare_physics_only_rtf": physics, "bare_physics_only_robots_at_real_time": physics_count})
    return out


PROBES = {"arm_motion": probe_arm_motion, "arm_latency": probe_arm_latency, "lockstep": probe_lockstep}


def rows(r):
    """Table rows of these items, for bench.table."""
    out = []
    if r.get("arm"):
        a = r["arm"]
        out += [("fast-mode RTF, base + 6-joint arm on a trajectory", f"{a['rtf']:.1f}", ">= 30"),
                ("  / bare PyBullet, same model and targets", f"{a['ratio']:.2f}", ">= 0.5"),
                ("  trajectory command -> first motion (sim, median)", f"{a['command_to_motion_median_s'] * 1000:.1f} ms",
                 "<= 10 ms (one control period)")]
    if r.get("lockstep"):
        s = r["lockstep"]
        out += [("Gazebo-style step-and-wait env (fast mode)", f"{s['steps_per_s']:.1f} steps/s", ">= 50"),
                ("  sim time each action held, median / p95", f"{s['held_median_s']:.3f} / {s['held_p95_s']:.3f} s",
                 "0.2 / 0.2 (one scan)")]
    if r.get("gym"):
        g = r["gym"]
        out += [("gym env steps/s per core (24 beams, 0.2 s period)", f"{g['env_steps_per_s_cpu']:.0f}", ""),
                ("  / bare PyBullet, same sim time (CPU)", f"{g['ratio_to_bare_cpu']:.2f}", ">= 0.7"),
                ("  resets per second per core", f"{g['resets_per_s_cpu']:.0f}", "")]
    if r.get("fleet"):
        f = r["fleet"]
        laser, helper = f["laser"], f["laser_ray_process"]
        out += [("robots at RTF >= 1, 360-beam lasers @5 Hz, odom+scan subscribed",
                 f"{laser['robots_at_real_time']} ({laser['ratio_to_bare']:.2f} of bare, in pairs)",
                 ">= 100 or >= 0.8 of bare"),
                ("  bare PyBullet at real time, their lasers cast (paired runs, median)",
                 f"{laser['bare_robots_at_real_time']:.0f}", ""),
                ("  the same with the rays cast in the ray process (~ray_process true)",
                 f"{helper['robots_at_real_time']} ({helper['ratio_to_bare']:.2f} of bare, in pairs)", ""),
                ("  the same without lasers", f"{f['no_laser']['robots_at_real_time']}", ""),
                ("  with lasers + a robot_state_publisher each", f"{f['laser_rsp']['robots_at_real_time']}", ""),
                ("  bare PyBullet, physics only (no rays)", f"{f['bare_physics_only_robots_at_real_time']:.0f}", ""),
                ("  simulator cost per robot (lasers), CPU us per sim s",
                 f"{laser['us_per_robot_per_sim_s'] or 0:.0f}", "")]
    return out


STEPS = [("arm", lambda q: bench_arm(4 if q else 10, 1 if q else 3)),
         ("lockstep", lambda q: bench_lockstep(50 if q else 300, 1 if q else 3)),
         ("gym", lambda q: bench_gym()),
         ("fleet", lambda q: bench_fleet(4 if q else 8))]


if __name__ == "__main__":
    print(re.sub(r"\n{2,}", "\n", __doc__))
