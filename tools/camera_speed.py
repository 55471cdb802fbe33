#!/usr/bin/env python3
"""Camera figures for the README (run in the ROS environment: ``bash tools/rosenv.sh python3 tools/camera_speed.py``).

1. Bare PyBullet: ``getCameraImage`` of a 640x480 view (TinyRenderer) of tests/data/worlds/camera_room.world
   with the camera robot in it, in a loop: images per second.
2. bullet_sim in fast mode (``~real_time false``) with the same robot's camera made 640x480 at 30 Hz,
   subscribed: images per wall second received, as a ratio to (1).
3. CPU of bullet_sim at real time (1x) for ``--seconds``: the camera robot with nobody subscribed, the same
   robot with the image subscribed, and tests/data/robots/fixed_caster.urdf (no camera) as the baseline.

Prints one JSON line and a short table. Each trial has its own master (``roscore -p PORT``).
"""
import argparse
import json
import os
import re
import signal
import socket
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "src"))
WORLD = os.path.join(ROOT, "tests", "data", "worlds", "camera_room.world")
CAMERA_ROBOT = os.path.join(ROOT, "tests", "data", "robots", "camera_robot.urdf")
PLAIN_ROBOT = os.path.join(ROOT, "tests", "data", "robots", "fixed_caster.urdf")
W, H, HFOV, NEAR, FAR = 640, 480, 1.047, 0.05, 20.0

from diffbot_sim.waiting import wait_for


def robot_640(path):
    """camera_robot.urdf with its front camera at 640x480, 30 Hz (the depth camera stays, unsubscribed)."""
    text = open(CAMERA_ROBOT).read()
    text = text.replace("<update_rate>10</update_rate>", "<update_rate>30</update_rate>", 1)
    text = text.replace("<width>320</width><height>240</height>", f"<width>{W}</width><height>{H}</height>", 1)
    with open(path, "w") as out:
        out.write(text)
    return path


def bare(frames):
    """Images per second of pybullet.getCameraImage alone, the node's view of the same scene."""
    import pybullet

    from diffbot_sim.description.urdf_model import parse_urdf
    from diffbot_sim.physics import World
    from diffbot_sim.sensors import camera as cam
    from diffbot_sim.world.sdf_reader import read_world

    world = World(1.0 / 240.0)
    world.load_world(read_world(WORLD, model_paths=[]), tempfile.mkdtemp())
    text = open(CAMERA_ROBOT).read()
    robot = world.load_robot(text, parse_urdf(text, CAMERA_ROBOT))
    for _ in range(240):
        world.step()
    eye, target, up = cam.look_at(robot.link_pose("camera_link"))
    view = pybullet.computeViewMatrix(eye, target, up, physicsClientId=world.client)
    proj = pybullet.computeProjectionMatrixFOV(cam.vertical_fov_degrees(HFOV, W, H), W / H, NEAR, FAR,
                                               physicsClientId=world.client)
    pybullet.getCameraImage(W, H, view, proj, renderer=pybullet.ER_TINY_RENDERER, physicsClientId=world.client)
    start = time.perf_counter()
    for _ in range(frames):
        pybullet.getCameraImage(W, H, view, proj, renderer=pybullet.ER_TINY_RENDERER,
                                flags=pybullet.ER_NO_SEGMENTATION_MASK, physicsClientId=world.client)
    elapsed = time.perf_counter() - start
    world.close()
    return frames / elapsed


def free_port():
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


class Sim:
    """roscore + bullet_sim with private parameters, on their own port; stopped with SIGINT on exit."""

    def __init__(self, **params):
        self.port = free_port()
        self.env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{self.port}")
        self.params = params

    def __enter__(self):
        self.log = tempfile.TemporaryFile()
        self.core = subprocess.Popen(["roscore", "-p", str(self.port)], env=self.env, stdout=self.log,
                                     stderr=subprocess.STDOUT, start_new_session=True)
        time.sleep(2.0)
        args = [f"_{k}:={v}" for k, v in self.params.items()]
        self.node = subprocess.Popen(["rosrun", "diffbot_sim", "bullet_sim", "/use_sim_time:=false"] + args,
                                     env=self.env, stdout=self.log, stderr=subprocess.STDOUT,
                                     start_new_session=True)
        os.environ["ROS_MASTER_URI"] = self.env["ROS_MASTER_URI"]
        return self

    def pid(self):
        """The bullet_sim process (rosrun execs the script, so the child is the node)."""
        out = subprocess.run(["pgrep", "-P", str(self.node.pid)], stdout=subprocess.PIPE, text=True).stdout.split()
        return int(out[0]) if out else self.node.pid

    def __exit__(self, *exc):
        for proc in (self.node, self.core):
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGINT)
                try:
                    proc.wait(timeout=15)
                except subprocess.TimeoutExpired:
                    os.killpg(proc.pid, signal.SIGKILL)
                    proc.wait()


def cpu_seconds(pid):
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def wait_topic(topic, timeout=60.0):
    import rosgraph
    master = rosgraph.Master("/camera_speed")

    def published():
        try:
            return any(name == topic for name, _ in master.getPublishedTopics(""))
        except OSError:  # the master is not up yet
            return False
    wait_for(published, timeout, f"a publisher of {topic}", 0.2)


def node_trial(model, seconds, subscribe, real_time):
    """(images per wall second received or None, CPU % of one core of bullet_sim) over ``seconds``."""
    import rospy
    from rospy.msg import AnyMsg

    with Sim(model=model, world=WORLD, real_time=str(real_time).lower()) as sim:
        wait_topic("/odom")
        time.sleep(2.0)  # past start-up
        count = [0]
        sub = None
        if subscribe:
            rospy.init_node("camera_speed", anonymous=True, disable_signals=True)

            def keep(_msg):
                count[0] += 1
            sub = rospy.Subscriber("/front_camera/image_raw", AnyMsg, keep, queue_size=1, buff_size=2 ** 24)
            deadline = time.monotonic() + 20
            while count[0] == 0 and time.monotonic() < deadline:
                time.sleep(0.05)
        pid = sim.pid()
        c0, t0, n0 = cpu_seconds(pid), time.monotonic(), count[0]
        time.sleep(seconds)
        c1, t1, n1 = cpu_seconds(pid), time.monotonic(), count[0]
        if sub is not None:
            sub.unregister()
    rate = (n1 - n0) / (t1 - t0) if subscribe else None
    return rate, 100.0 * (c1 - c0) / (t1 - t0)


def one(kind, seconds):
    """One trial in a fresh process (rospy allows one init_node per process)."""
    model = robot_640(os.path.join(tempfile.gettempdir(), "camera_robot_640.urdf"))
    if kind == "fast_subscribed":
        return node_trial(model, seconds, True, False)
    if kind == "rt_unsubscribed":
        return node_trial(model, seconds, False, True)
    if kind == "rt_subscribed":
        return node_trial(model, seconds, True, True)
    if kind == "rt_no_camera":
        return node_trial(PLAIN_ROBOT, seconds, False, True)
    raise ValueError(kind)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--trial", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.trial:
        print(json.dumps(one(args.trial, args.seconds)))
        return
    results = {"bare_fps": bare(args.frames)}
    for kind in ("fast_subscribed", "rt_no_camera", "rt_unsubscribed", "rt_subscribed"):
        out = subprocess.run([sys.executable, os.path.abspath(__file__), "--trial", kind, "--seconds",
                              str(args.seconds)], stdout=subprocess.PIPE, text=True, timeout=300)
        lines = [line for line in out.stdout.splitlines() if re.match(r"^\[", line)]
        results[kind] = json.loads(lines[-1]) if lines else None
    fps = results["fast_subscribed"][0] if results["fast_subscribed"] else float("nan")
    results["ratio"] = fps / results["bare_fps"]
    print(json.dumps(results))
    print(f"640x480 TinyRenderer, bare getCameraImage: {results['bare_fps']:.1f} img/s; bullet_sim fast mode, "
          f"camera 30 Hz subscribed: {fps:.1f} img/s ({100 * results['ratio']:.0f} % of bare)")
    for kind in ("rt_no_camera", "rt_unsubscribed", "rt_subscribed"):
        if results[kind]:
            rate, cpu = results[kind]
            print(f"real time 1x, {kind}: CPU {cpu:.1f} % of one core" + (f", {rate:.1f} img/s" if rate else ""))


if __name__ == "__main__":
    main()
