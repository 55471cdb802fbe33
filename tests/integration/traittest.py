"""Shared helpers of the trait suites (arm_traits, arm_commands): several robots in one simulator, each in its
own namespace (bullet_sim's ``~robots``), judged by the physics' ground truth.

A joint's true position comes from the two link poses Gazebo keeps (/gazebo/get_link_state of the child link
with the parent link as reference_frame, one call: one instant), undone through the URDF joint's origin: the
angle about its axis (revolute, continuous) or the slide along it (prismatic). Objects are spawned with
/gazebo/spawn_sdf_model; controllers are loaded and switched through the robot's controller_manager services;
what the simulator logs is read on /rosout.
"""
import math
import threading

import rospy
from controller_manager_msgs.srv import ListControllers, LoadController, SwitchController
from gazebo_msgs.srv import GetLinkState, GetModelState, GetWorldProperties, SpawnModel
from geometry_msgs.msg import Pose
from rosgraph_msgs.msg import Log
from simtest import wait_for
from std_srvs.srv import Empty

from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.transforms import compose, inverse, rpy_quaternion

STRICT = 2


def _proxy(name, kind):
    rospy.wait_for_service(name, 60)
    return rospy.ServiceProxy(name, kind)


class Truth:
    """Ground truth of the robots' links and of spawned objects."""

    def __init__(self):
        self.link_state = _proxy("/gazebo/get_link_state", GetLinkState)
        self.model_state = _proxy("/gazebo/get_model_state", GetModelState)
        self.models = {}

    def model(self, ns):
        if ns not in self.models:
            self.models[ns] = parse_urdf(rospy.get_param(f"/{ns}/robot_description"))
        return self.models[ns]

    def link(self, name, frame=""):
        """(position, quaternion) of ``model::link`` in ``frame`` (world when empty)."""
        resp = self.link_state(name, frame)
        if not resp.success:
            raise AssertionError(f"get_link_state {name} in '{frame}': {resp.status_message}")
        p, q = resp.link_state.pose.position, resp.link_state.pose.orientation
        return (p.x, p.y, p.z), (q.x, q.y, q.z, q.w)

    def object(self, name):
        resp = self.model_state(name, "")
        if not resp.success:
            raise AssertionError(f"get_model_state {name}: {resp.status_message}")
        p, q = resp.pose.position, resp.pose.orientation
        return (p.x, p.y, p.z), (q.x, q.y, q.z, q.w)

    def joint(self, ns, name):
        """The joint's position (rad or m) from its child link's pose in its parent link."""
        joint = self.model(ns).joints[name]
        relative = self.link(f"{ns}::{joint.child}", f"{ns}::{joint.parent}")
        motion = compose(inverse((tuple(joint.xyz), rpy_quaternion(*joint.rpy))), relative)
        norm = math.sqrt(sum(a * a for a in joint.axis)) or 1.0
        axis = [a / norm for a in joint.axis]
        if joint.type == "prismatic":
            return sum(p * a for p, a in zip(motion[0], axis))
        q = motion[1]
        return 2.0 * math.atan2(sum(v * a for v, a in zip(q[:3], axis)), q[3])

    def joints(self, ns, names):
        return [self.joint(ns, n) for n in names]


def spawn_box(name, size, mass, xyz, mu=1.0):
    """A dynamic box of ``size`` (x, y, z) m and ``mass`` kg with friction ``mu``, centred at ``xyz``."""
    sx, sy, sz = size
    ixx, iyy, izz = (mass * (sy * sy + sz * sz) / 12, mass * (sx * sx + sz * sz) / 12,
                     mass * (sx * sx + sy * sy) / 12)
    geometry = f"<geometry><box><size>{sx} {sy} {sz}</size></box></geometry>"
    sdf = (f"<?xml version='1.0'?><sdf version='1.6'><model name='{name}'><link name='link'>"
           f"<inertial><mass>{mass}</mass><inertia><ixx>{ixx}</ixx><ixy>0</ixy><ixz>0</ixz><iyy>{iyy}</iyy>"
           f"<iyz>0</iyz><izz>{izz}</izz></inertia></inertial>"
           f"<collision name='collision'>{geometry}<surface><friction><ode><mu>{mu}</mu><mu2>{mu}</mu2></ode>"
           f"</friction></surface></collision><visual name='visual'>{geometry}</visual></link></model></sdf>")
    pose = Pose()
    pose.position.x, pose.position.y, pose.position.z = xyz
    pose.orientation.w = 1.0
    resp = _proxy("/gazebo/spawn_sdf_model", SpawnModel)(name, sdf, "", pose, "")
    if not resp.success:
        raise AssertionError(f"spawn {name}: {resp.status_message}")


class Manager:
    """One robot's controller_manager services."""

    def __init__(self, ns):
        base = f"/{ns}/controller_manager"
        self.ns = ns
        self.load_srv = _proxy(f"{base}/load_controller", LoadController)
        self.switch_srv = _proxy(f"{base}/switch_controller", SwitchController)
        self.list_srv = _proxy(f"{base}/list_controllers", ListControllers)

    def load(self, name, params=None):
        """Load ``name`` (its parameters set first when given); the service's ``ok``."""
        if params is not None:
            rospy.set_param(f"/{self.ns}/{name}", params)
        return self.load_srv(name).ok

    def switch(self, start=(), stop=(), strictness=STRICT):
        return self.switch_srv(start_controllers=list(start), stop_controllers=list(stop), strictness=strictness,
                               start_asap=False, timeout=0.0).ok

    def running(self):
        return {c.name for c in self.list_srv().controller if c.state == "running"}

    def wait_running(self, names, timeout=60):
        wait_for(lambda: self.running() >= set(names), timeout, f"/{self.ns} controllers {sorted(names)} running")


class Rosout:
    """Every line logged on /rosout by any node (not /rosout_agg: rostest's master may run without the rosout
    node that republishes there); the callback only stores."""

    def __init__(self):
        self.lock = threading.Lock()
        self.lines = []
        self.sub = rospy.Subscriber("/rosout", Log, self._keep, queue_size=200)

    def _keep(self, msg):
        with self.lock:
            self.lines.append(msg.msg)

    def mark(self):
        with self.lock:
            return len(self.lines)

    def since(self, mark):
        with self.lock:
            return list(self.lines[mark:])

    def wait_line(self, mark, *words, timeout=10.0):
        """The first line logged after ``mark`` holding every one of ``words``."""
        def found():
            return next((line for line in self.since(mark) if all(w in line for w in words)), None)
        return wait_for(found, timeout, f"a logged line with {words}")


_world = []


def sim_now():
    """The simulator's sim time now (get_world_properties: what the loop has reached, not this node's /clock,
    which lags it in fast mode)."""
    if not _world:
        _world.append(_proxy("/gazebo/get_world_properties", GetWorldProperties))
    return _world[0]().sim_time


def sim_sleep(seconds, timeout=60.0):
    """Wait ``seconds`` of the simulator's sim time."""
    start = sim_now()
    wait_for(lambda: sim_now() >= start + seconds, timeout, f"{seconds} s of sim time")


def settled(read, band, window=0.3, timeout=30.0, what="the readings"):
    """The last of ``read()``'s readings (a list of numbers: ground truth, read through services) once every one
    of them has stayed within ``band`` (max - min) over at least ``window`` s of the simulator's sim time; fails
    after ``timeout`` wall seconds naming the widest. Read again and again, each reading bracketed by sim_now()
    before and after it: the window counts from the first reading's latest possible moment to the last one's
    earliest, so a starved test node that reads seldom still spans the window. Two readings ``window`` apart
    that agree are not enough: an oscillation's two ends can."""
    samples = []  # (sim time before the read, sim time after it, reading), oldest first
    moved = ["never out of the band: the window of sim time not yet covered"]

    def spread():
        return [max(r[i] for _, _, r in samples) - min(r[i] for _, _, r in samples) for i in range(len(samples[0][2]))]

    def still():
        before = sim_now()
        reading = list(read())
        samples.append((before, sim_now(), reading))
        widths = spread()
        if max(widths, default=0.0) > band:
            widest = max(range(len(widths)), key=widths.__getitem__)
            moved[0] = f"the last move: reading {widest} by {widths[widest]:.5f} (now {reading})"
        while len(samples) > 1 and max(spread(), default=0.0) > band:
            del samples[0]  # the window starts after the last reading out of the band
        while len(samples) > 2 and samples[-1][0] - samples[1][1] >= window:
            del samples[0]  # the window is covered without the oldest
        return reading if samples[-1][0] - samples[0][1] >= window else None

    try:
        return wait_for(still, timeout, f"{what} settled (within {band} over {window} s of sim time)")
    except AssertionError as failure:
        raise AssertionError(f"{failure}: {moved[0]}") from None


def paused(action):
    """Run ``action`` with the physics paused (one instant for several ground-truth calls)."""
    _proxy("/gazebo/pause_physics", Empty)()
    try:
        return action()
    finally:
        _proxy("/gazebo/unpause_physics", Empty)()
