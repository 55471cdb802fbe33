"""Items ``scale`` and ``fleet``: how many robots one simulator keeps at real time.

- ``scale``: namespaced seed robots one simulator keeps at RTF >= 0.99, every robot's topics subscribed (and,
  as ``scale_rsp``, the same with a robot_state_publisher each).
- ``fleet``: TurtleBot3-class robots (tests/data/multi_way/tb3like: diff drive at 30 Hz, 360-beam laser at 5 Hz;
  its IMU left out) in one simulator at real time, driving circles, every robot's /odom and /scan subscribed:
  the largest count at RTF >= 0.99 as the simulator starts by default (every ray cast in its own process) and
  with its rays in the ray process (``~ray_process`` true), without lasers, and with a robot_state_publisher
  each; against bare PyBullet stepping the same robots (same model, step, wheel speeds and torque) and casting
  their lasers' scans as the simulator does, in pairs run back to back at the simulator's count (the
  reference), and physics only; the simulator's cost per robot (CPU us per sim second).

Real-time mode is the one that counts: fast mode batches writes, which makes it cheaper per simulated second
than pacing to the clock, so a fast-mode RTF >= 1 overstates the count.
"""
import json
import os
import statistics
import time
import xml.etree.ElementTree as ET

from benchkit.bare import check_upright, load, wheel_speeds
from benchkit.common import CIRCLE, MODEL, RESULTS, ROOT, STEP
from benchkit.launching import Launch, subscriber
from benchkit.report import Item
from benchkit.stats import largest_count

TB3LIKE = os.path.join(ROOT, "tests", "data", "multi_way", "tb3like_description", "urdf", "tb3like.urdf.xacro")
# the fleet's robot is a Gazebo user's package (package:// meshes, $(find tb3like_description)): findable by
# xacro here and by every launch started from here
os.environ["ROS_PACKAGE_PATH"] = os.pathsep.join(
    [p for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    + [os.path.join(ROOT, "tests", "data", "multi_way")])


def robots_launch(path, robot_description, names, rsp, sim_params=()):
    """Write a real-time launch file: ``robot_description`` (attributes of its ``<param>``), one bullet_sim with
    ``~robots`` named ``names`` on a 1 m grid (ten to a row), ``sim_params`` (name, value) and, with ``rsp``, a
    robot_state_publisher per robot (multi.launch's way). Returns ``path``."""
    root = ET.Element("launch")
    ET.SubElement(root, "param", name="use_sim_time", value="true")
    ET.SubElement(root, "param", name="robot_description", **robot_description)
    node = ET.SubElement(root, "node", name="bullet_sim", pkg="diffbot_sim", type="bullet_sim", required="true")
    for name, value in sim_params:
        ET.SubElement(node, "param", name=name, value=value)
    robots = [{"name": name, "x": float(i % 10), "y": float(i // 10)} for i, name in enumerate(names)]
    ET.SubElement(node, "rosparam", param="robots").text = json.dumps(robots)
    for robot in robots if rsp else ():
        inc = ET.SubElement(root, "include", file=os.path.join(ROOT, "launch", "robot_state.launch"), ns=robot["name"])
        ET.SubElement(inc, "arg", name="tf_prefix", value=robot["name"])
    ET.ElementTree(root).write(path)
    return path


# ------------------------------------------------------------------------------------------- seed robots

def scale_trial(count, seconds, rsp):
    tag = f"scale_{count}{'_rsp' if rsp else ''}"
    names = [f"robot{i + 1}" for i in range(count)]
    path = robots_launch(os.path.join(RESULTS, f"{tag}.launch"), {"command": f"xacro '{MODEL}'"}, names, rsp)
    with Launch([path], tag) as launch:
        for name in names:  # one consumer process per robot, as each robot would have its own nodes
            subscriber(launch, [f"/{name}/odom", f"/{name}/joint_states"])
        subscriber(launch, ["/tf"])
        return launch.probe("rtf", seconds=seconds, warmup=5.0, namespaces=[f"/{n}" for n in names],
                            timeout=seconds + 300)


def scale(seconds, rsp):
    """Largest seed-robot count the simulator keeps at RTF >= 0.99 in real-time mode (grow by 10, then bisect)."""
    def say(count, trial):
        print(f"[bench] scale{' +rsp' if rsp else ''}: {count} robots, real-time RTF {trial['rtf']:.3f}, "
              f"simulator CPU {trial['cpu_percent']:.0f} %", flush=True)
    good, trials = largest_count(lambda n: scale_trial(n, seconds, rsp), 10, 100, say)
    best = trials.get(good)
    return {"realtime_rtf_by_count": {k: v["rtf"] for k, v in sorted(trials.items())},
            "max_robots_rtf_ge_1": good,
            "realtime_rtf_at_max": best["rtf"] if best else None,
            "sim_cpu_percent_at_max": best["cpu_percent"] if best else None}


# ------------------------------------------------------------------------------------- TurtleBot3-class

def fleet_model(laser):
    """tb3like's URDF (xacro'd) without its IMU, and without its laser unless ``laser``; written to a file."""
    from diffbot_sim.description.model_files import load_file
    root = ET.fromstring(load_file(TB3LIKE))
    for gazebo in root.findall("gazebo"):
        for sensor in list(gazebo.findall("sensor")):
            if sensor.get("type") == "imu" or (sensor.get("type") == "ray" and not laser):
                gazebo.remove(sensor)
        for plugin in list(gazebo.findall("plugin")):
            if "imu" in (plugin.get("filename") or ""):
                gazebo.remove(plugin)
    os.makedirs(RESULTS, exist_ok=True)
    path = os.path.join(RESULTS, f"tb3like{'_laser' if laser else ''}.urdf")
    ET.ElementTree(root).write(path)
    return path


def fleet_trial(count, seconds, model, rsp, laser, ray_process=None):
    """The simulator with ``count`` of ``model`` at real time; ``ray_process`` None: the simulator's default."""
    variant = ("_rsp" if rsp else "") + ("" if ray_process is None else f"_rp_{ray_process}")
    names = [f"tb3_{i}" for i in range(count)]
    params = () if ray_process is None else (("ray_process", str(ray_process).lower()),)
    path = robots_launch(os.path.join(RESULTS, f"fleet_{count}{variant}.launch"), {"textfile": model}, names, rsp,
                         params)
    with Launch([path], f"fleet_{count}") as launch:
        topics = [f"/{n}/odom" for n in names] + ([f"/{n}/scan" for n in names] if laser else [])
        subscriber(launch, topics)  # one consumer for all: the machine's second core is not a neighbour's
        result = launch.probe("rtf", seconds=seconds, warmup=8.0, namespaces=[f"/{n}" for n in names],
                              timeout=seconds + 600)
    result["us_per_robot_per_sim_s"] = 1e6 * result["cpu_percent"] / 100.0 / result["rtf"] / count
    return result


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
            left, right = wheel_speeds(CIRCLE, float(plugin.findtext("wheelSeparation")),
                                       float(plugin.findtext("wheelDiameter")) / 2.0)
            return left, right, float(plugin.findtext("wheelTorque"))
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
    text, parsed = load(model)
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


def fleet(seconds):
    """The fleet item. This VM's speed drifts by tens of percent within minutes (bare PyBullet stepping the
    same 66 robots: RTF 0.97-1.18 in one quarter of an hour), so every comparison with bare PyBullet is made of
    pairs run back to back at the same count: the simulator's count is bisected first; then bare and the
    simulator run three times each, alternately, at that count, and the ratio is the median of the pairs'."""
    laser_model, bare_model = fleet_model(True), fleet_model(False)
    guess = bare_fleet(60, 5.0, laser_model, True) * 60  # where to start looking: about 0.6-0.8 of this
    out = {}

    def say(count, trial):
        print(f"[bench] fleet: {count} robots, RTF {trial['rtf']:.3f}", flush=True)
    # The simulator as it starts by default (every ray cast in its own process), and with its rays cast in the
    # ray process (~ray_process true).
    for key, model, rsp, laser, ray_process in (("laser", laser_model, False, True, None),
                                                ("laser_ray_process", laser_model, False, True, True),
                                                ("no_laser", bare_model, False, False, None),
                                                ("laser_rsp", laser_model, True, True, None)):
        def trial(n, model=model, rsp=rsp, laser=laser, ray_process=ray_process):
            return fleet_trial(n, seconds, model, rsp, laser, ray_process)
        count, trials = largest_count(trial, 10 if rsp else max(10, int(guess * 0.6) // 10 * 10), 200, say)
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
    out.update({"pairs": pairs, "bare_physics_only_rtf": physics,
                "bare_physics_only_robots_at_real_time": physics_count})
    return out


def scale_rows(r):
    rows = []
    for key, label in (("scale", "robots at RTF >= 1 (all topics)"),
                       ("scale_rsp", "  same, + robot_state_publisher each")):
        if r.get(key):
            s = r[key]
            value = (f"{s['max_robots_rtf_ge_1']} (real-time RTF {s['realtime_rtf_at_max']:.3f})"
                     if s["realtime_rtf_at_max"] else "0")
            rows.append((label, value, ">= 10" if key == "scale" else ""))
    return rows


def fleet_rows(r):
    if not r.get("fleet"):
        return []
    f = r["fleet"]
    laser, helper = f["laser"], f["laser_ray_process"]
    return [("robots at RTF >= 1, 360-beam lasers @5 Hz, odom+scan subscribed",
             f"{laser['robots_at_real_time']} ({laser['ratio_to_bare']:.2f} of bare, in pairs)",
             ">= 100 or >= 0.8 of bare"),
            ("  bare PyBullet at real time, their lasers cast (paired runs, median)",
             f"{laser['bare_robots_at_real_time']:.0f}", ""),
            ("  the same with the rays cast in the ray process (~ray_process true)",
             f"{helper['robots_at_real_time']} ({helper['ratio_to_bare']:.2f} of bare, in pairs)", ""),
            ("  the same without lasers", f"{f['no_laser']['robots_at_real_time']}", ""),
            ("  with lasers + a robot_state_publisher each", f"{f['laser_rsp']['robots_at_real_time']}", ""),
            ("  bare PyBullet, physics only (no rays)", f"{f['bare_physics_only_robots_at_real_time']:.0f}", ""),
            ("  simulator cost per robot (lasers), CPU us per sim s", f"{laser['us_per_robot_per_sim_s'] or 0:.0f}",
             "")]


# scale_rsp's rows are scale_rows' second line
ITEMS = [Item("scale", lambda q: scale(4 if q else 8, False), scale_rows),
         Item("scale_rsp", lambda q: scale(4 if q else 8, True), lambda r: [], part_of="scale"),
         Item("fleet", lambda q: fleet(4 if q else 8), fleet_rows)]
PROBES = {}
