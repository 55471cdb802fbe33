"""How many laser robots could a simulator split over processes keep at real time on this machine?

A measurement for docs/fleet.md, not a simulator: ``bullet_sim`` runs physics, rays and ROS on one thread (PyBullet
holds Python's lock through ``stepSimulation`` and ``rayTestBatch``), which caps a laser fleet at about 0.7 of
what bare PyBullet steps and casts. This script runs the design that would lift the cap, with the fleet's real
robot and the simulator's own message builders, and reports whether its physics keeps real time:

* **physics** (this process, no rospy): ``count`` tb3like robots (as ``make bench`` item ``fleet`` loads
  them, wheels turning) stepped at real time; every 1/30 s of sim time their base poses and twists go to
  shared memory and a sixth of the robots are due a scan (each robot at 5 Hz).
* **rays** (a child, no rospy): a mirror PyBullet world holding the same robots; at each scan tick it puts
  every robot where the physics has it and casts the due robots' 360-beam, 3.5 m scans (from the laser's
  link) into shared memory. The physics waits for the previous tick's scans only when the next are due.
  With ``--rays-in-physics`` there is no ray process: the physics casts the scans itself between its steps
  (the smaller split: physics and rays in one process, ROS in another).
* **ros** (a child, a rospy node): publishes ``/clock`` at every step it sees, each robot's
  ``/rN/odom`` (``messages.common.odometry``) at 30 Hz and ``/rN/scan`` (``LaserScanBuilder``) when cast.
* **consumer** (a child, a rospy node): subscribes to every ``/rN/odom`` and ``/rN/scan``, as ``make bench``'s
  consumer does, and counts what arrives.

It starts its own rosmaster on a free port. Prints one JSON line per run: the physics' RTF, each
process's share of a core, and the messages per second received against those due.

    bash tools/rosenv.sh python3 tools/fleet_split.py 93 --seconds 20 --repeats 3
"""
import argparse
import json
import math
import multiprocessing
import os
import subprocess
import time
from multiprocessing import shared_memory

import numpy as np
from bench_items import fleet
from benchkit import bare
from benchkit.common import STEP  # s: the fleet's step, as make bench
from benchkit.launching import free_port

ODOM_EVERY = 8             # steps: odometry at 30 Hz
SCAN_GROUPS = 6            # scan ticks per scan period: each robot scans at 5 Hz
BEAMS, RANGE_MIN, RANGE_MAX = 360, 0.12, 3.5  # tb3like's <ray>, for the messages (the casting reads the model)


def load_fleet(count):
    """``(World, robots, (laser link, RayConfig), parsed model)``: ``count`` tb3like robots with their lasers on
    make bench's 1 m grid, the laser as ``bench_items.fleet.fleet_laser`` reads it."""
    from diffbot_sim.physics import World
    model = fleet.fleet_model(True)
    text, parsed = bare.load(model)
    world = World(STEP)
    robots = [world.load_robot(text, parsed, (float(i % 10), float(i // 10), 0.0)) for i in range(count)]
    return world, robots, fleet.fleet_laser(model), parsed


class Shared:
    """The shared memory: the step counter, poses ``(count, 13)`` (position, quaternion, linear and angular
    velocity), ranges ``(count, BEAMS)``, and per robot its scan's sequence number and step."""

    def __init__(self, count, name=None):
        sizes = [8, count * 13 * 8, count * BEAMS * 8, count * 8, count * 8]
        self.memory = shared_memory.SharedMemory(name=name, create=name is None, size=sum(sizes))
        views, at = [], 0
        for size, shape in zip(sizes, [(1,), (count, 13), (count, BEAMS), (count,), (count,)]):
            dtype = np.float64 if len(shape) == 2 else np.int64
            views.append(np.ndarray(shape, dtype, self.memory.buf[at:at + size]))
            at += size
        self.step, self.poses, self.ranges, self.scan_seq, self.scan_step = views


class Scanner:
    """Casts the due robots' scans in ``world`` into the shared ranges, from where its robots are now: the
    model's rays from the laser's link (``Robot.link_pose``: PyBullet's base pose is the inertial frame, not
    the link's), as the simulator and ``bench_items.fleet.bare_fleet`` cast them."""

    def __init__(self, world, robots, laser, parsed, shared, threads):
        from diffbot_sim.sensors import ray as ray_sensor
        self.link, self.cfg = laser
        self.pose, _ = ray_sensor.mounted_pose(self.cfg, parsed, self.link)
        self.directions = ray_sensor.ray_directions(self.cfg)
        self.world, self.robots, self.shared, self.threads = world, robots, shared, threads

    def cast(self, step, due):
        import pybullet

        from diffbot_sim.sensors import ray as ray_sensor
        cfg = self.cfg
        for i in due:
            origin, rotation = ray_sensor.sensor_pose(*self.robots[i].link_pose(self.link), self.pose)
            starts, ends = ray_sensor.world_rays(origin, rotation, self.directions, cfg.range_min, cfg.range_max)
            hits = pybullet.rayTestBatch(starts, ends, numThreads=self.threads, physicsClientId=self.world.client)
            self.shared.ranges[i] = ray_sensor.raw_ranges([hit[2] for hit in hits], cfg.range_min, cfg.range_max)
            self.shared.scan_step[i] = step
            self.shared.scan_seq[i] += 1


def rays(count, name, pipe, threads):
    """The ray process: a mirror world, scans cast on request."""
    import pybullet
    world, robots, laser, parsed = load_fleet(count)
    shared = Shared(count, name)
    scanner = Scanner(world, robots, laser, parsed, shared, threads)
    pipe.send("ready")
    cpu0 = None
    while (request := pipe.recv()) is not None:
        if cpu0 is None:
            cpu0 = time.process_time()
        step, due, poses = request
        for robot, pose in zip(robots, poses):
            pybullet.resetBasePositionAndOrientation(robot.body, pose[:3], pose[3:7], physicsClientId=world.client)
        scanner.cast(step, due)
        pipe.send(True)
    pipe.send(time.process_time() - cpu0 if cpu0 is not None else 0.0)


def ros_side(count, name, result, connected):
    """The ROS process: /clock, odometry and scans built with the simulator's builders, published."""
    import rospy
    from nav_msgs.msg import Odometry
    from rosgraph_msgs.msg import Clock
    from sensor_msgs.msg import LaserScan

    from diffbot_sim.messages import common as messages
    rospy.init_node("fleet_split_ros", disable_signals=True)
    shared = Shared(count, name)
    clock = rospy.Publisher("/clock", Clock, queue_size=10)
    odom = [rospy.Publisher(f"/r{i}/odom", Odometry, queue_size=10) for i in range(count)]
    scan = [rospy.Publisher(f"/r{i}/scan", LaserScan, queue_size=10) for i in range(count)]
    builders = [messages.LaserScanBuilder(f"r{i}/base_scan", -math.pi, math.pi, 2 * math.pi / BEAMS, RANGE_MIN,
                                          RANGE_MAX) for i in range(count)]
    intensities = np.zeros(BEAMS, np.float32)
    covariance = (1e-5,) * 6
    deadline = time.monotonic() + 120.0
    while any(p.get_num_connections() < 1 for p in odom + scan):
        if time.monotonic() > deadline:
            raise RuntimeError("the consumer did not subscribe to every topic within 120 s")
        time.sleep(0.1)
    connected.set()
    last, seen, cpu0, wall0 = 0, np.zeros(count, np.int64), None, None
    while (step := int(shared.step[0])) >= 0:
        if step == last:
            time.sleep(0.0005)
            continue
        if cpu0 is None:
            cpu0, wall0 = time.process_time(), time.perf_counter()
        stamp = rospy.Time.from_sec(step * STEP)
        clock.publish(messages.clock(stamp))
        if step // ODOM_EVERY != last // ODOM_EVERY:
            poses = shared.poses.copy()
            for i in range(count):
                odom[i].publish(messages.odometry(stamp, f"r{i}/odom", f"r{i}/base_footprint", poses[i, :3],
                                                  poses[i, 3:7], poses[i, 7:10], poses[i, 10:13], covariance,
                                                  covariance))
        for i in np.nonzero(shared.scan_seq != seen)[0]:
            seen[i] = shared.scan_seq[i]
            scan[i].publish(builders[i].build(rospy.Time.from_sec(shared.scan_step[i] * STEP),
                                              shared.ranges[i].astype(np.float32), intensities))
        last = step
    result.put(("ros_core_share", round((time.process_time() - cpu0) / (time.perf_counter() - wall0), 3)))
    rospy.signal_shutdown("done")


def consumer(count, name, connected, seconds, result):
    """Every /rN/odom and /rN/scan subscribed; messages per second over ``seconds`` once connected."""
    import rospy
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import LaserScan
    rospy.init_node("fleet_split_consumer", disable_signals=True)
    received = {"odom": 0, "scan": 0}

    def counter(kind):
        def count_one(_):
            received[kind] += 1
        return count_one
    keep = [rospy.Subscriber(f"/r{i}/odom", Odometry, counter("odom"), queue_size=10) for i in range(count)]
    keep += [rospy.Subscriber(f"/r{i}/scan", LaserScan, counter("scan"), queue_size=10) for i in range(count)]
    shared = Shared(count, name)
    deadline = time.monotonic() + 180.0
    while int(shared.step[0]) < 240:  # counted from the physics' second sim second on
        if time.monotonic() > deadline:
            raise RuntimeError("the physics did not step within 180 s")
        time.sleep(0.01)
    received.update(odom=0, scan=0)
    cpu0, wall0 = time.process_time(), time.perf_counter()
    time.sleep(seconds)
    wall = time.perf_counter() - wall0
    result.put(("consumer", {"core_share": round((time.process_time() - cpu0) / wall, 3),
                             "odom_per_s": round(received["odom"] / wall), "scan_per_s": round(received["scan"] / wall),
                             "subscriptions": len(keep)}))
    rospy.signal_shutdown("done")


def run(count, seconds, rays_in_physics=False, ray_threads=0):
    """One run: the physics steps ``seconds`` of sim time at real time with the others running. With
    ``rays_in_physics`` the physics process casts the scans itself (no ray process: the two-process split)."""
    import pybullet
    world, robots, laser, parsed = load_fleet(count)
    for robot in robots:
        robot.set_velocities(robot.indices(["wheel_left_joint", "wheel_right_joint"]), [2.0, 3.0], [1.0, 1.0])
    for _ in range(240):
        world.step()
    shared = Shared(count)
    shared.step[0] = 0
    context = multiprocessing.get_context("fork")
    pipe, child_pipe = context.Pipe()
    result, connected = context.Queue(), context.Event()
    children = []
    if rays_in_physics:
        scanner = Scanner(world, robots, laser, parsed, shared, ray_threads)
    else:
        children.append(context.Process(target=rays, args=(count, shared.memory.name, child_pipe, ray_threads)))
        children[0].start()
        if pipe.recv() != "ready":
            raise RuntimeError("the ray process did not start")
    children += [context.Process(target=ros_side, args=(count, shared.memory.name, result, connected)),
                 context.Process(target=consumer, args=(count, shared.memory.name, connected, seconds - 2.0, result))]
    for child in children[-2:]:
        child.start()
    if not connected.wait(timeout=180.0):
        raise RuntimeError("the consumer's subscriptions did not connect within 180 s")
    steps, pending = 0, False
    cpu0, start = time.process_time(), time.perf_counter()
    while steps * STEP < seconds:
        world.step()
        steps += 1
        if steps % ODOM_EVERY:
            shared.step[0] = steps
        else:
            for i, robot in enumerate(robots):
                position, orientation = pybullet.getBasePositionAndOrientation(robot.body, physicsClientId=world.client)
                linear, angular = pybullet.getBaseVelocity(robot.body, physicsClientId=world.client)
                shared.poses[i] = (*position, *orientation, *linear, *angular)
            shared.step[0] = steps
            group = (steps // ODOM_EVERY) % SCAN_GROUPS
            due = [i for i in range(count) if i % SCAN_GROUPS == group]
            if rays_in_physics:
                scanner.cast(steps, due)
            else:
                if pending:
                    pipe.recv()
                pipe.send((steps, due, shared.poses[:, :7].copy()))
                pending = True
        ahead = start + steps * STEP - time.perf_counter()
        if ahead > 0:
            time.sleep(ahead)
    wall = time.perf_counter() - start
    physics_cpu = time.process_time() - cpu0
    ray_cpu = 0.0
    if not rays_in_physics:
        if pending:
            pipe.recv()
        pipe.send(None)
        ray_cpu = pipe.recv()
    shared.step[0] = -1
    out = {"robots": count, "rays": "in the physics process" if rays_in_physics else "in a ray process",
           "ray_threads": ray_threads, "physics_rtf": round(seconds / wall, 3),
           "physics_core_share": round(physics_cpu / wall, 3), "ray_core_share": round(ray_cpu / wall, 3),
           "due_per_s": {"odom": count / (ODOM_EVERY * STEP), "scan": count / (ODOM_EVERY * SCAN_GROUPS * STEP)}}
    for _ in range(2):
        key, value = result.get(timeout=60)
        out[key] = value
    for child in children:
        child.join(timeout=30)
    shared.memory.close()
    shared.memory.unlink()
    world.close()
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("counts", type=int, nargs="+", help="robots per run")
    parser.add_argument("--seconds", type=float, default=20.0, help="sim seconds stepped per run")
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--rays-in-physics", action="store_true",
                        help="cast the scans in the physics process (two processes: physics and rays, ROS)")
    parser.add_argument("--ray-threads", type=int, default=0,
                        help="rayTestBatch's numThreads (0: Bullet's pool, as the simulator casts; 1: one thread)")
    options = parser.parse_args()
    port = free_port()
    os.environ["ROS_MASTER_URI"] = f"http://localhost:{port}"
    master = subprocess.Popen(["rosmaster", "--core", "-p", str(port)], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        import rosgraph
        deadline = time.monotonic() + 30.0
        while not rosgraph.Master("/fleet_split").is_online():
            if time.monotonic() > deadline:
                raise RuntimeError(f"rosmaster on port {port} did not come up within 30 s")
            time.sleep(0.05)
        for count in options.counts:
            for _ in range(options.repeats):
                print(json.dumps(run(count, options.seconds, options.rays_in_physics, options.ray_threads)),
                      flush=True)
    finally:
        master.terminate()
        master.wait(timeout=10)


if __name__ == "__main__":
    main()
