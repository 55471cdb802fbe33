#!/usr/bin/env python3
"""``make pictures``: the README's pictures from a scripted run, under Xvfb (docs/*.png).

1. ``view.launch`` (tests/data/robots/view_robot.urdf: laser + camera, in worlds/room.world, ground truth
   on), started three times: each time, wall seconds from ``roslaunch`` to the first rviz frame showing the
   robot (its yellow top in the 3-D view). The median goes to the README's Speed section.
2. The last of those runs drives a scripted path (forward, turn, forward, arc) while this process records
   odometry, ground truth, commands, the scan and TF; then ``docs/rviz.png`` (the rviz window) and
   ``docs/run.png`` (``plot_run``'s picture of the recording).
3. ``view.launch gui:=true rviz:=false``: ``docs/pybullet.png`` is PyBullet's window once the simulator has
   built the world and the robot and the window's 3-D view has stopped changing.
4. ``docs/manipulator.png`` (:func:`manipulator_picture`; also alone: ``tools/pictures.py manipulator``):
   diffbot_arm in worlds/pick_place.world holding the box above the pick table, the pose and the box placed
   as pick_place's lift step leaves them (no ROS, no display: PyBullet's TinyRenderer).
5. ``docs/fleet.png`` (:func:`fleet_picture`; also alone: ``tools/pictures.py fleet``): a hundred
   TurtleBot3-class robots and what their lasers hit.

Every process is started in its own session and stopped by its process group; each run has its own master
(``roslaunch -p PORT``). Prints one line per step, so a reader knows it is alive (about 1 min in all).
"""
import os
import signal
import socket
import statistics
import subprocess
import sys
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "src"))

from diffbot_sim.view import xscreen
from diffbot_sim.waiting import wait_for

DOCS = os.path.join(ROOT, "docs")
ROBOT = os.path.join(ROOT, "tests", "data", "robots", "view_robot.urdf")
WORLD = os.path.join(ROOT, "worlds", "room.world")
RUNS = 3
YELLOW_PIXELS = 100  # the robot's top (0.26 x 0.18 m) covers ~500 pixels in the fitted top view
MAX_WIDTH = 960  # px: pictures are scaled to this width (and palette-reduced) to stay under 200 KB
SETTLE_PERIOD = 0.5  # s wall between two screenshots of PyBullet's window compared
SETTLE_CHANGED = 20  # px: two frames differing in at most this many pixels show the same, finished scene


def say(text):
    print(f"[pictures] {text}", flush=True)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Launch:
    """``roslaunch -p PORT diffbot_sim view.launch ARGS`` on ``display``, in its own session."""

    def __init__(self, display, args, log):
        self.port = free_port()
        self.env = dict(os.environ, DISPLAY=display, ROS_MASTER_URI=f"http://localhost:{self.port}")
        self.log = open(log, "w")
        self.started = time.monotonic()
        self.proc = subprocess.Popen(["roslaunch", "-p", str(self.port), "diffbot_sim", "view.launch"] + args,
                                     env=self.env, stdout=self.log, stderr=subprocess.STDOUT,
                                     stdin=subprocess.DEVNULL, start_new_session=True)

    def check(self):
        if self.proc.poll() is not None:
            raise SystemExit(f"[pictures] roslaunch exited {self.proc.returncode}; see {self.log.name}")

    def stop(self):
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGINT)
            try:
                self.proc.wait(20)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait(5)
        self.log.close()


def rviz_view(display):
    """(rviz window, its 3-D view panel) once rviz has its configured size, else None."""
    windows = xscreen.list_windows(display)
    for top in windows:
        if top.name.endswith("RViz") and (top.width, top.height) == xscreen.SCREEN:
            panels = [w for w in xscreen.subtree(windows, top) if not w.name]
            if panels:
                return top, max(panels, key=lambda w: w.area)
    return None


def robot_drawn(display):
    """True once the 3-D view shows the robot's yellow top."""
    found = rviz_view(display)
    if found is None:
        return False
    frame = xscreen.crop(xscreen.screenshot(display), found[1].box()).astype(int)
    yellow = (frame[:, :, 0] > 200) & (frame[:, :, 1] > 150) & (frame[:, :, 2] < 80)
    return int(yellow.sum()) >= YELLOW_PIXELS


def first_frame(display, args, log):
    launch = Launch(display, args, log)

    def ready():
        launch.check()
        return robot_drawn(display)
    wait_for(ready, 120, "the first rviz frame with the robot", 0.05)
    return launch, time.monotonic() - launch.started


def pybullet_frame(display, launch):
    """PyBullet's window once it shows the world and the robot: its pixels.

    The window opens, and draws PyBullet's own grid, before the simulator has built the world and the robot:
    wait for the simulator to say it is built (``/bullet_sim/world_bodies``, set after loading the world and
    the robots), then until two frames of the 3-D view ``SETTLE_PERIOD`` s apart are nearly equal (the scene
    is drawn)."""
    import rosgraph

    master = rosgraph.Master("/pictures", master_uri=launch.env["ROS_MASTER_URI"])

    def built():
        launch.check()
        try:
            return master.hasParam("/bullet_sim/world_bodies")
        except Exception:  # the master is not up yet
            return False
    window = wait_for(lambda: launch.check() or xscreen.find_window(display, "Bullet Physics"), 60,
                      "PyBullet's window", 0.1)
    wait_for(built, 60, "the simulator to load the world and the robot (/bullet_sim/world_bodies)", 0.1)
    previous = [None]

    def settled():
        launch.check()
        frame = xscreen.crop(xscreen.screenshot(display), window.box())
        scene = xscreen.crop(frame, xscreen.PYBULLET_SCENE_BOX)
        same = previous[0] is not None and int(xscreen.changed(previous[0], scene).sum()) <= SETTLE_CHANGED
        previous[0] = scene
        return (frame,) if same and scene.std() > 20 else None
    return wait_for(settled, 60, "PyBullet to draw the scene (two equal frames)", SETTLE_PERIOD)[0]


class Recorder:
    """This process as a ROS node: records what plot_run reads and drives the robot."""

    def __init__(self, env):
        os.environ["ROS_MASTER_URI"] = env["ROS_MASTER_URI"]
        import rospy
        from geometry_msgs.msg import Twist
        from nav_msgs.msg import Odometry
        from sensor_msgs.msg import LaserScan
        from tf2_msgs.msg import TFMessage

        self.rospy, self.Twist = rospy, Twist
        rospy.init_node("pictures", anonymous=True, disable_signals=True)
        self.records, self.lock = [], threading.Lock()
        self.subs = [rospy.Subscriber(t, k, self._keep, callback_args=t, queue_size=1000) for t, k in (
            ("/odom", Odometry), ("/bullet_sim/ground_truth", Odometry), ("/cmd_vel", Twist),
            ("/scan", LaserScan), ("/tf", TFMessage), ("/tf_static", TFMessage))]
        self.cmd = rospy.Publisher("/cmd_vel", Twist, queue_size=1)

    def _keep(self, msg, topic):
        with self.lock:
            self.records.append((topic, msg, self.rospy.get_time()))

    def drive(self, plan):
        """``plan``: [(linear m/s, angular rad/s, sim seconds)], then a stop."""
        rospy = self.rospy
        wait_for(lambda: self.cmd.get_num_connections() > 0, 20, "the simulator to subscribe /cmd_vel")
        for linear, angular, seconds in plan:
            start = rospy.get_time()
            while rospy.get_time() - start < seconds:
                twist = self.Twist()
                twist.linear.x, twist.angular.z = linear, angular
                self.cmd.publish(twist)
                time.sleep(0.05)
        self.cmd.publish(self.Twist())
        time.sleep(1.0)  # let the stop show in the recording and in rviz (1 s of real time at RTF 1)

    def take(self):
        with self.lock:
            return list(self.records)


def manipulator_picture(path):
    """docs/manipulator.png: diffbot_arm at the pick table (base_link 0.16 m before the box, as
    control.pick_place plans it) with the box lifted 10 cm between its closed fingers."""
    import pybullet

    from diffbot_sim.check.arm_check import forward_kinematics
    from diffbot_sim.control import pick_place
    from diffbot_sim.description import meshes
    from diffbot_sim.description.model_files import load_file
    from diffbot_sim.description.urdf_model import parse_urdf
    from diffbot_sim.physics import World
    from diffbot_sim.world.loading import load_world

    world = World(1.0 / 240.0)
    try:
        world.load_world(load_world(os.path.join(ROOT, "worlds", "pick_place.world"), 1.0), meshes.default_cache_dir())
        text = load_file(os.path.join(ROOT, "urdf", "diffbot_arm.urdf.xacro"))
        model = parse_urdf(text)
        scene = pick_place.Scene()
        arm = pick_place.arm_geometry({k: v[0] for k, v in forward_kinematics(model, {}).items()})
        robot = world.load_robot(text, model, (scene.pick[0] - scene.standoff, 0.0, 0.0))
        lift = pick_place.top_down(arm, scene.standoff, scene.pick[2] + scene.grasp_above + scene.carry_lift)
        joints = dict(zip(pick_place.ARM_JOINTS, (0.0,) + lift),
                      left_finger_joint=scene.object_size / 2, right_finger_joint=scene.object_size / 2)
        robot.set_joint_positions(robot.indices(list(joints)), list(joints.values()))
        tcp = robot.link_pose("gripper_tcp_link")[0]
        box = next(uid for uid, body in world.world_bodies if body.top_model == "pick_box")
        pybullet.resetBasePositionAndOrientation(box, (tcp[0], tcp[1], tcp[2] - scene.grasp_above), (0, 0, 0, 1),
                                                 physicsClientId=world.client)
        view = pybullet.computeViewMatrixFromYawPitchRoll((0.45, 0.0, 0.16), 0.9, 55.0, -28.0, 0.0, 2,
                                                          physicsClientId=world.client)
        projection = pybullet.computeProjectionMatrixFOV(45.0, 1.5, 0.05, 10.0, physicsClientId=world.client)
        width, height = 1200, 800
        _, _, rgba, _, _ = pybullet.getCameraImage(width, height, view, projection, shadow=1,
                                                   lightDirection=(1.0, -1.0, 2.0),
                                                   renderer=pybullet.ER_TINY_RENDERER, physicsClientId=world.client)
    finally:
        world.close()
    import numpy as np

    image = np.reshape(np.asarray(rgba, dtype=np.uint8), (height, width, 4))[:, :, :3]
    xscreen.save_png(image, path, MAX_WIDTH)


def fleet_picture(path, side=10, spacing=1.0):
    """docs/fleet.png: ``side`` x ``side`` TurtleBot3-class robots (tests/data/multi_way's tb3like, as ``make
    bench``'s fleet item loads them) on a grid ``spacing`` m apart, seen from above, with every robot's
    360-beam scan (3.5 m, cast as the simulator casts it, ``World.ray_batch``) drawn where its rays hit: each
    scan finds its neighbours (a line from the laser to each hit, the hit a red dot). No ROS, no display:
    PyBullet's TinyRenderer."""
    import numpy as np
    import pybullet
    from bench_items import fleet  # tools/bench_items: the fleet item's model
    from benchkit import bare

    from diffbot_sim.physics import World

    text, parsed = bare.load(fleet.fleet_model(True))
    world = World(1.0 / 240.0)
    width = height = 1400
    try:
        rng = np.random.default_rng(0)
        robots = [world.load_robot(text, parsed, (spacing * (i % side), spacing * (i // side), 0.0),
                                   yaw=float(rng.uniform(-np.pi, np.pi))) for i in range(side * side)]
        for _ in range(240):  # settle on the wheels
            world.step()
        angles = np.linspace(0.0, 2.0 * np.pi, 360, endpoint=False)
        starts, ends = [], []
        for robot in robots:
            (x, y, z), q = robot.link_pose("base_scan")
            yaw = pybullet.getEulerFromQuaternion(q)[2]
            for a in angles:
                starts.append((x, y, z))
                ends.append((x + 3.5 * np.cos(yaw + a), y + 3.5 * np.sin(yaw + a), z))
        starts, ends = np.asarray(starts), np.asarray(ends)
        fractions, bodies, _ = world.ray_batch(starts, ends)
        hit = (bodies >= 0) & (fractions * 3.5 >= 0.12)  # the laser's <min>: its own body is not drawn
        points = starts[hit] + (ends[hit] - starts[hit]) * fractions[hit, None]
        centre = (spacing * (side - 1) / 2.0, spacing * (side - 1) / 2.0)
        view = pybullet.computeViewMatrix((centre[0], centre[1], 14.0), (centre[0], centre[1], 0.0), (0, 1, 0))
        projection = pybullet.computeProjectionMatrixFOV(42.0, 1.0, 1.0, 20.0)
        _, _, rgba, _, _ = pybullet.getCameraImage(width, height, view, projection, shadow=0,
                                                   lightDirection=(0.3, -0.5, 2.0),
                                                   renderer=pybullet.ER_TINY_RENDERER, physicsClientId=world.client)
    finally:
        world.close()
    image = np.array(np.reshape(np.asarray(rgba, dtype=np.uint8), (height, width, 4))[:, :, :3])
    # Project with the camera's own matrices (column-major): each ray that hit, a thin line from its laser to
    # the hit, and the hit a red dot on the robot it found.
    v, p = np.asarray(view).reshape(4, 4).T, np.asarray(projection).reshape(4, 4).T

    def pixels(xyz):
        clip = (p @ v @ np.c_[xyz, np.ones(len(xyz))].T).T
        ndc = clip[:, :2] / clip[:, 3:4]
        return (np.clip(np.round((ndc[:, 0] + 1.0) / 2.0 * (width - 1)).astype(int), 0, width - 1),
                np.clip(np.round((1.0 - ndc[:, 1]) / 2.0 * (height - 1)).astype(int), 0, height - 1))
    along = np.linspace(0.0, 1.0, 60)[:, None, None]
    u, w = pixels((starts[hit][None] + (points - starts[hit])[None] * along).reshape(-1, 3))
    image[w, u] = (60, 170, 60)
    u, w = pixels(points)
    for du in (-1, 0, 1):
        for dv in (-1, 0, 1):
            image[np.clip(w + dv, 0, height - 1), np.clip(u + du, 0, width - 1)] = (220, 30, 30)
    xscreen.save_png(image, path, MAX_WIDTH)
    return len(robots), int(hit.sum())


def main():
    if sys.argv[1:] == ["manipulator"]:
        manipulator_picture(os.path.join(DOCS, "manipulator.png"))
        say("docs/manipulator.png")
        return 0
    if sys.argv[1:] == ["fleet"]:
        robots, hits = fleet_picture(os.path.join(DOCS, "fleet.png"))
        say(f"docs/fleet.png: {robots} robots, {hits} laser hits drawn")
        return 0
    from diffbot_sim.nodes import plot_run
    from diffbot_sim.view import plot_data

    os.makedirs(DOCS, exist_ok=True)
    logs = os.path.join(ROOT, "test-results", "pictures")
    os.makedirs(logs, exist_ok=True)
    args = [f"model:={ROBOT}", f"world:={WORLD}", "publish_ground_truth:=true"]
    times = []
    with xscreen.Xvfb() as x:
        say(f"Xvfb on {x.display}; {RUNS} starts of view.launch, timing roslaunch -> first rviz frame with the robot")
        launch = None
        for i in range(RUNS):
            launch, seconds = first_frame(x.display, args, os.path.join(logs, f"view{i}.log"))
            times.append(seconds)
            say(f"run {i + 1}: first frame with the robot after {seconds:.2f} s")
            if i < RUNS - 1:
                launch.stop()
        try:
            say("driving the scripted path (about 15 s)")
            recorder = Recorder(launch.env)
            wait_for(lambda: recorder.subs[0].get_num_connections() > 0, 20, "/odom to connect")
            recorder.drive([(0.4, 0.0, 3.0), (0.0, 0.8, 2.0), (0.3, 0.0, 2.5), (0.3, -0.6, 4.0)])
            top, _ = rviz_view(x.display)
            xscreen.save_png(xscreen.crop(xscreen.screenshot(x.display), top.box()), os.path.join(DOCS, "rviz.png"),
                             MAX_WIDTH)
            data = plot_data.collect(recorder.take())
            drawn = plot_run.plot(data, os.path.join(DOCS, "run.png"), "make pictures")
            say(f"docs/rviz.png, docs/run.png ({drawn['summary'].distance:.2f} m driven)")
        finally:
            launch.stop()
        say("PyBullet's window: view.launch gui:=true rviz:=false")
        gui = Launch(x.display, args + ["gui:=true", "rviz:=false"], os.path.join(logs, "gui.log"))
        try:
            frame = pybullet_frame(x.display, gui)
            xscreen.save_png(frame, os.path.join(DOCS, "pybullet.png"), MAX_WIDTH)
            say("docs/pybullet.png")
        finally:
            gui.stop()
    manipulator_picture(os.path.join(DOCS, "manipulator.png"))
    say("docs/manipulator.png")
    robots, hits = fleet_picture(os.path.join(DOCS, "fleet.png"))
    say(f"docs/fleet.png: {robots} robots, {hits} laser hits drawn")
    median = statistics.median(times)
    say(f"roslaunch -> first rviz frame with the robot, under Xvfb: median {median:.2f} s of {RUNS} "
        f"({', '.join(f'{t:.2f}' for t in times)})")
    for name in ("rviz.png", "run.png", "pybullet.png", "manipulator.png"):
        size = os.path.getsize(os.path.join(DOCS, name))
        say(f"docs/{name}: {size // 1024} KB" + (" (over 200 KB!)" if size > 200 * 1024 else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
