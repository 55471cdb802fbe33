"""Shared helpers for the rostest test nodes: record what the simulator publishes, wait with deadlines.

Callbacks only record; the test thread asserts. Waits poll a predicate against a wall-clock deadline.
"""
import math
import os
import threading
import time

import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_srvs.srv import Empty
from tf2_msgs.msg import TFMessage

from diffbot_sim import waiting

# HEIGHT_TOLERANCE, MAX_TILT (m, rad): a driving body stays this close to its rest height, and tilts less than
# this (drive_check's bounds)
from diffbot_sim.check.drive_check import HEIGHT_TOLERANCE, MAX_TILT

SIM = "/bullet_sim"


def yaw_of(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def finite_odom(msg):
    p, q = msg.pose.pose.position, msg.pose.pose.orientation
    v, w = msg.twist.twist.linear, msg.twist.twist.angular
    return all(math.isfinite(x) for x in (p.x, p.y, p.z, q.x, q.y, q.z, q.w, v.x, v.y, v.z, w.x, w.y, w.z))


def action_done(client):
    """Whether a SimpleActionClient's current goal has ended (its result is in). Judged on the goal handle:
    actionlib's SimpleActionClient drops the transitions of a goal that ends before ``send_goal`` has stored
    its handle ("Got a transition callback on a goal handle that we're not tracking"), leaving its own state
    PENDING for ever; a goal already met ends that fast in fast mode."""
    from actionlib import CommState
    handle = client.gh
    return handle is not None and handle.get_comm_state() == CommState.DONE


def ros_shut_down():
    """``wait_for``'s reason to give up early: this node's rospy has shut down (nothing more will arrive)."""
    return rospy.is_shutdown() and "ROS shut down"


def wait_for(predicate, timeout, what, poll=0.02):
    """``diffbot_sim.waiting.wait_for`` as a test waits: poll ``predicate`` until it returns something true
    (returned); fail (AssertionError naming ``what``) after ``timeout`` wall seconds or once ROS shuts down."""
    return waiting.wait_for(predicate, timeout, what, poll, error=AssertionError, give_up=ros_shut_down)


class Latest:
    """The newest message of one topic and how many arrived (the callback only stores)."""

    def __init__(self, topic, kind):
        self.lock = threading.Lock()
        self.msg, self.count = None, 0
        self.sub = rospy.Subscriber(topic, kind, self._keep, queue_size=10)

    def _keep(self, msg):
        with self.lock:
            self.msg, self.count = msg, self.count + 1

    def get(self):
        with self.lock:
            return self.msg


class Truth:
    """The ground truth of one robot's body (bullet_sim's ``~ground_truth``, published when
    ``~publish_ground_truth`` is set): every message kept as a drive_check.BodySample (the callback only
    stores). Drive checks judge the body by it: odometry is the robot's claim, this is where it is."""

    def __init__(self, topic=SIM + "/ground_truth"):
        from diffbot_sim.check import drive_check

        self._sample = drive_check.body_sample
        self.lock = threading.Lock()
        self.samples = []
        self.sub = rospy.Subscriber(topic, Odometry, self._keep, queue_size=1000)

    def _keep(self, msg):
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        sample = self._sample(msg.header.stamp.to_sec(), (p.x, p.y, p.z), (q.x, q.y, q.z, q.w))
        with self.lock:
            self.samples.append(sample)

    def last(self):
        with self.lock:
            return self.samples[-1] if self.samples else None

    def between(self, start, end):
        """Samples stamped in [start, end] (sim time)."""
        with self.lock:
            return [s for s in self.samples if start <= s.t <= end]

    def ride(self, start, end, height=0.0, what="driving"):
        """The body between two sim times, judged by drive_check.ride (at ``height``, upright); raises
        AssertionError naming what went wrong."""
        from diffbot_sim.check import drive_check

        body = self.between(start, end)
        result = drive_check.ride(body, height, what)
        if not result.passed:
            raise AssertionError("; ".join(result.failures))
        return body


class TfEdges:
    """Which nodes published each TF edge (parent, child) on /tf, and with ``static`` on /tf_static as well
    (callbacks only store): a consumer of the tree needs each edge from one node."""

    def __init__(self, static=False):
        self.lock = threading.Lock()
        self._publishers = {}  # (parent, child) -> set of caller ids
        rospy.Subscriber("/tf", TFMessage, self._keep, queue_size=1000)
        if static:
            rospy.Subscriber("/tf_static", TFMessage, self._keep, queue_size=100)

    def _keep(self, msg):
        caller = msg._connection_header.get("callerid", "?")
        with self.lock:
            for t in msg.transforms:
                self._publishers.setdefault((t.header.frame_id.lstrip("/"), t.child_frame_id.lstrip("/")),
                                            set()).add(caller)

    def edges(self):
        """{(parent, child): set of caller ids} so far (a copy)."""
        with self.lock:
            return {edge: set(who) for edge, who in self._publishers.items()}


def assert_upright(pose, height, what):
    """A geometry_msgs/Pose of a driven robot (from /gazebo/get_model_state) rests at ``height`` and upright."""
    from diffbot_sim.check import drive_check

    sample = drive_check.body_sample(0.0, (pose.position.x, pose.position.y, pose.position.z),
                                     (pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w))
    if not (abs(sample.z - height) < HEIGHT_TOLERANCE and sample.tilt < MAX_TILT):
        raise AssertionError(f"{what}: the body is at height {sample.z:.3f} m (rest height {height} m), tilted "
                             f"{sample.tilt:.3f} rad")


class Recorder:
    """Subscribes the standard topics and keeps every message with its receipt time."""

    def __init__(self, odom="/odom", joint_states="/joint_states", extra_odom=None):
        self.lock = threading.Lock()
        self.odom, self.joints, self.clock, self.tf, self.extra = [], [], [], [], []
        self.subs = [
            rospy.Subscriber(odom, Odometry, self._keep, callback_args=self.odom, queue_size=1000),
            rospy.Subscriber(joint_states, JointState, self._keep, callback_args=self.joints, queue_size=1000),
            rospy.Subscriber("/clock", Clock, self._keep, callback_args=self.clock, queue_size=1000),
            rospy.Subscriber("/tf", TFMessage, self._keep, callback_args=self.tf, queue_size=1000),
        ]
        if extra_odom:
            self.subs.append(rospy.Subscriber(extra_odom, Odometry, self._keep, callback_args=self.extra,
                                              queue_size=1000))
        self.cmd = rospy.Publisher("/cmd_vel", Twist, queue_size=10)

    def _keep(self, msg, store):
        with self.lock:
            store.append(msg)

    def last(self, store):
        with self.lock:
            return store[-1] if store else None

    def snapshot(self, store):
        with self.lock:
            return list(store)

    def clear(self):
        with self.lock:
            for store in (self.odom, self.joints, self.clock, self.tf, self.extra):
                del store[:]

    def wait(self, predicate, timeout, what):
        """``wait_for``, polling every 10 ms."""
        return wait_for(predicate, timeout, what, 0.01)

    def wait_connected(self, timeout=20.0):
        self.wait(lambda: self.cmd.get_num_connections() > 0, timeout, "the simulator to subscribe /cmd_vel")
        self.wait(lambda: self.last(self.odom) is not None, timeout, "a first odom message")

    def sim_time(self):
        """Sim time as seen on odom (not /clock: in fast mode the odom subscriber may lag the clock one)."""
        msg = self.last(self.odom)
        return msg.header.stamp.to_sec() if msg else 0.0

    def wait_sim(self, seconds, timeout=60.0):
        """Wait until odom stamped ``seconds`` after the simulator's sim time now (sim_now: the newest odom this
        node holds may be older on a busy machine, and counting from it would end the wait early) has arrived;
        returns the newest odom stamp."""
        start = sim_now()
        return self.wait(lambda: self.sim_time() >= start + seconds and self.sim_time(), timeout,
                         f"sim time to advance {seconds} s from {start:.3f}")

    def odom_after(self, sim_time, timeout=60.0, store=None):
        """The first odom message stamped at or after ``sim_time``."""
        store = self.odom if store is None else store

        def find():
            for msg in reversed(self.snapshot(store)):
                if msg.header.stamp.to_sec() < sim_time:
                    break
            for msg in self.snapshot(store):
                if msg.header.stamp.to_sec() >= sim_time:
                    return msg
            return None
        return self.wait(find, timeout, f"odom stamped after {sim_time:.3f}")

    def send(self, linear=0.0, angular=0.0, **fields):
        msg = Twist()
        msg.linear.x, msg.angular.z = linear, angular
        for name, value in fields.items():
            part, axis = name.split("_")
            setattr(getattr(msg, part), axis, value)
        self.cmd.publish(msg)
        return msg

    def send_until_seen(self, linear, angular, timeout=10.0):
        """Publish a command and wait until odom shows the robot responding to it."""
        self.send(linear, angular)

        def moving():
            msg = self.last(self.odom)
            if msg is None:
                return False
            twist = msg.twist.twist
            return ((linear == 0 or twist.linear.x * linear > 0.2 * linear * linear) and
                    (angular == 0 or twist.angular.z * angular > 0.2 * angular * angular))
        return self.wait(moving, timeout, f"the robot to respond to ({linear}, {angular})")


def call(service):
    rospy.wait_for_service(service, timeout=20.0)
    rospy.ServiceProxy(service, Empty)()


def sim_now(gazebo="/gazebo"):
    """The simulator's own sim time now (gazebo_ros's get_world_properties). What this node last received
    lags it on a loaded machine (its /clock and odom queue up behind a starved thread): "stamped after the
    service returned" must be measured against this, not against the newest message seen."""
    from gazebo_msgs.srv import GetWorldProperties

    rospy.wait_for_service(gazebo + "/get_world_properties", timeout=20.0)
    return rospy.ServiceProxy(gazebo + "/get_world_properties", GetWorldProperties)().sim_time


def reset_robot(rec):
    """Zero the command, reset the world (models to their start; sim time goes on), and wait until odom shows the
    robot back at rest."""
    rec.send(0.0, 0.0)
    call(SIM + "/reset_world")  # time goes on (reset_simulation would send it back to 0)
    after = sim_now()  # the service returned: anything stamped later follows the reset, whatever this node holds

    def at_rest():
        msg = rec.last(rec.odom)
        p = msg.pose.pose.position
        return (msg.header.stamp.to_sec() > after and abs(p.x) < 0.01 and abs(p.y) < 0.01
                and abs(msg.twist.twist.linear.x) < 0.01 and abs(msg.twist.twist.angular.z) < 0.01)
    rec.wait(at_rest, 20.0, "the robot at rest at the origin after reset")


# -- helpers for the reliability suites (flood, soak, signals) -------------------------------------------

def node_pid(node, caller="/simtest_pid"):
    """The pid of a registered node, asked over its own XML-RPC API (getPid), never by process name."""
    import xmlrpc.client

    import rosgraph
    uri = rosgraph.Master(caller).lookupNode(node)
    code, msg, pid = xmlrpc.client.ServerProxy(uri).getPid(caller)
    if code != 1:
        raise AssertionError(f"getPid of {node} failed: {msg}")
    return pid


def rss_kib(pid):
    """Resident set size of ``pid`` in KiB (VmRSS of /proc/<pid>/status); raises if the process is gone."""
    with open(f"/proc/{pid}/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise AssertionError(f"no VmRSS for pid {pid} (a zombie?)")


def alive(pid):
    """True while ``pid`` exists and is not a zombie."""
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def figure(text):
    """A measured figure: one ``FIGURE`` line in the test's log (rosout) and on its stdout."""
    rospy.loginfo("FIGURE " + text)
    print("FIGURE " + text, flush=True)


def session_pids(sid):
    """Pids of the live (non-zombie) processes in session ``sid`` (a process started with
    ``start_new_session=True`` leads the session numbered by its pid; its children stay in it)."""
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as stat:
                fields = stat.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if fields[0] != "Z" and int(fields[3]) == sid:  # state, ppid, pgrp, session
            found.append(int(entry))
    return found


# -- the time a process waited for a CPU (wall-clock bounds of the reliability suites) ----------------------

#: The goal marker a Gazebo learning environment respawns every episode (TurtleBot3's machine-learning chapter):
#: a static model with one visual and no collision.
GOAL_MARKER_SDF = ('<?xml version="1.0"?><sdf version="1.6"><model name="goal"><static>true</static>'
                   '<link name="goal"><visual name="v"><geometry><cylinder><radius>0.1</radius><length>0.05'
                   '</length></cylinder></geometry></visual></link></model></sdf>')


def agent_work(seconds):
    """A learning agent's work between two steps: CPU, not sleep (a network's forward pass)."""
    import numpy as np
    end = time.monotonic() + seconds
    a = np.ones((64, 64))
    while time.monotonic() < end:
        a = np.tanh(a @ a.T * 1e-3)


def run_delay(pid):
    """Seconds the main thread of ``pid`` has spent runnable but not running: waiting for a CPU while other
    processes had the cores or its cgroup's CPU quota was spent (the kernel's ``/proc/<pid>/schedstat``; a
    zombie still has it). None when the process is gone."""
    try:
        with open(f"/proc/{pid}/schedstat") as f:
            return int(f.read().split()[1]) / 1e9
    except (OSError, IndexError, ValueError):
        return None


def descendants(root):
    """``root`` and its live or zombie descendants (by parent pid)."""
    children = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as stat:
                    children.setdefault(int(stat.read().rsplit(")", 1)[1].split()[1]), []).append(int(entry))
            except (OSError, IndexError, ValueError):
                continue
    found, todo = [], [root]
    while todo:
        pid = todo.pop()
        found.append(pid)
        todo.extend(children.get(pid, []))
    return found


def exited(pid):
    """True once the child ``pid`` has ended, without reaping it (its /proc entry and figures stay)."""
    return os.waitid(os.P_PID, pid, os.WEXITED | os.WNOHANG | os.WNOWAIT) is not None


class CpuWait:
    """How long a process and its descendants waited for a CPU since this was made (``from_start``: since
    each was started), summed over their main threads (a child runs while its parent waits for it). Only for
    a process whose main thread does the work being timed, and children that run one after another: the
    waits of processes working side by side (a simulator polling while its client computes) would add up
    past the wall time.

    A wall-clock bound of ours ("exits within 2 s") is about what the process does, not about the machine: on
    a loaded one (two hogs on two cores, a cgroup at a quarter of a core) most of the wall time is spent
    waiting for a CPU. ``own(wall)`` is the wall time less that wait: the time it computed or blocked. On an
    idle machine the two are the same. Call ``sample()`` while polling (a short-lived child is seen only
    then) and once after the process ends, before reaping it."""

    def __init__(self, root, from_start=False):
        self.root = root
        self.first = {pid: 0.0 if from_start else run_delay(pid) for pid in descendants(root)}
        self.first = {pid: delay for pid, delay in self.first.items() if delay is not None}
        self.last = dict(self.first)

    def sample(self, rescan=True):
        """Read the figures of the known processes (``rescan``: also look for new descendants, born after
        this was made, counted from 0)."""
        for pid in (descendants(self.root) if rescan else list(self.last)):
            delay = run_delay(pid)
            if delay is not None:
                self.first.setdefault(pid, 0.0)
                self.last[pid] = delay

    def waited(self):
        return sum(self.last[pid] - self.first[pid] for pid in self.last)

    def own(self, wall):
        return wall - self.waited()

