"""Shared helpers of the arm suites: FollowJointTrajectory goals, joint states, and the body judged by the
physics' ground truth (/gazebo/get_link_state) against joint_states + the URDF (check.arm_check)."""
import collections
import math
import threading

import actionlib
import rospy
from control_msgs.msg import FollowJointTrajectoryAction, FollowJointTrajectoryGoal, JointTolerance
from gazebo_msgs.srv import GetLinkState
from sensor_msgs.msg import JointState
from simtest import action_done, wait_for
from std_srvs.srv import Empty
from traittest import sim_now
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from diffbot_sim.check.arm_check import pose_errors
from diffbot_sim.check.stillness import held_still
from diffbot_sim.description.urdf_model import parse_urdf


class JointStates:
    """Every joint's positions on /joint_states, each value with the stamp (sim time) of the message that carried
    it (several publishers merge, as in TF), and the recent messages themselves: a sample of "now" is a message
    stamped now or later, and "at rest" is positions held within a band over a window of their stamps.

    Why stamps and not counts or receipt: a test node starved of CPU (a busy machine) works through its queue of
    joint_states late; the newest message it holds can be half a second of sim time old, and "two more callbacks
    ran" still hands out positions from before the command. ``now`` gives the simulator's own sim time
    (traittest.sim_now by default: /gazebo/get_world_properties, not this node's lagging /clock); ``topic`` None
    subscribes nothing (messages are then fed to ``_keep`` by hand, as a check of this class does)."""

    #: messages kept for ``settled`` (50 Hz: 100 s of sim time)
    KEPT = 5000

    def __init__(self, topic="/joint_states", now=None):
        self.lock = threading.Lock()
        self.positions, self.velocities, self.stamps, self.count = {}, {}, {}, 0
        self.history = collections.deque(maxlen=self.KEPT)  # (stamp, {name: position}) per message
        self.now = now or sim_now
        # every message kept, however late this node reads them: a dropped message would be a gap in a window
        self.sub = rospy.Subscriber(topic, JointState, self._keep, queue_size=1000) if topic else None

    def _keep(self, msg):
        stamp = msg.header.stamp.to_sec()
        with self.lock:
            if self.history and stamp < self.history[-1][0]:  # sim time went back (reset_simulation)
                self.history.clear()
            self.positions.update(zip(msg.name, msg.position))
            self.velocities.update(zip(msg.name, msg.velocity))
            self.stamps.update((name, stamp) for name in msg.name)
            self.history.append((stamp, dict(zip(msg.name, msg.position))))
            self.count += 1

    def get(self, names=None):
        with self.lock:
            return dict(self.positions) if names is None else [self.positions.get(n) for n in names]

    def fresh(self, names=None, since=None, timeout=10.0):
        """Positions (a dict, or a list in the order of ``names``) from messages stamped at or after ``since``
        (sim time; default the simulator's sim time when this is called): what the joints were at or after that
        moment, the message after the command. Fails after ``timeout`` wall seconds."""
        since = self.now() if since is None else since

        def stamped_after():
            with self.lock:
                wanted = list(self.stamps) if names is None else list(names)
                if wanted and all(self.stamps.get(n, -math.inf) >= since for n in wanted):
                    return dict(self.positions) if names is None else [self.positions[n] for n in names]
            return None
        return wait_for(stamped_after, timeout, f"joint_states stamped at or after {since:.3f} s of sim time")

    def settled(self, names=None, band=0.001, window=0.3, timeout=20.0, since=None):
        """Positions (as ``fresh``) once every joint of ``names`` (default: all) has stayed within ``band`` (rad
        or m, max - min) over the last ``window`` s of sim time, judged by the stamps of messages stamped at or
        after ``since`` (default: the sim time when this is called), and the window covered (a message at or
        before its start). One message with low velocities is an instant, which an oscillation's turnaround also
        passes; this is the arm holding still. Fails after ``timeout`` wall seconds, naming the widest joint."""
        since = self.now() if since is None else since
        worst = ["no joint_states stamped after the call yet"]

        def still():
            with self.lock:
                messages = [(t, p) for t, p in self.history if t >= since]
                latest = dict(self.positions)
            wanted = names if names is not None else sorted({n for _, p in messages for n in p})
            if not wanted:
                return None
            for name in wanted:  # each joint on the messages that carry it (several publishers may merge)
                ok, why = held_still([(t, [p[name]]) for t, p in messages if name in p], band, window)
                if not ok:
                    worst[0] = f"{name}: {why}"
                    return None
            return latest if names is None else [latest[n] for n in names]
        try:
            return wait_for(still, timeout, f"the joints settled (within {band} over {window} s of sim time)")
        except AssertionError as failure:
            raise AssertionError(f"{failure}: {worst[0]}") from None


def trajectory(joints, *points, stamp=None):
    """A JointTrajectory through ``points``: (time_from_start s, positions[, velocities])."""
    msg = JointTrajectory(joint_names=list(joints))
    if stamp is not None:
        msg.header.stamp = stamp
    for point in points:
        p = JointTrajectoryPoint(positions=list(point[1]), time_from_start=rospy.Duration.from_sec(point[0]))
        if len(point) > 2:
            p.velocities = list(point[2])
        msg.points.append(p)
    return msg


class Arm:
    """One trajectory controller's action client and the robot's body."""

    def __init__(self, controller, model_name, description="/robot_description", joint_states="/joint_states"):
        self.client = actionlib.SimpleActionClient(f"{controller}/follow_joint_trajectory",
                                                   FollowJointTrajectoryAction)
        assert self.client.wait_for_server(rospy.Duration(60)), f"no action server {controller}"
        self.model_name = model_name
        self.model = parse_urdf(rospy.get_param(description))
        rospy.wait_for_service("/gazebo/get_link_state", 30)
        self.link_state = rospy.ServiceProxy("/gazebo/get_link_state", GetLinkState)
        self.states = JointStates(joint_states)

    def goal(self, msg, goal_tolerance=(), path_tolerance=(), goal_time=0.0):
        goal = FollowJointTrajectoryGoal(trajectory=msg)
        goal.goal_tolerance = [JointTolerance(name=n, position=p) for n, p in goal_tolerance]
        goal.path_tolerance = [JointTolerance(name=n, position=p) for n, p in path_tolerance]
        goal.goal_time_tolerance = rospy.Duration.from_sec(goal_time)
        return goal

    def run(self, msg, timeout=30.0, **kwargs):
        """Send a goal and wait for its end, at most ``timeout`` wall seconds (actionlib's own wait counts sim
        time, which fast mode spends in a fraction of a second while a busy machine delays the result):
        (goal status, result)."""
        self.client.send_goal(self.goal(msg, **kwargs))
        wait_for(lambda: action_done(self.client), timeout, "the goal's result")
        return self.client.get_state(), self.client.get_result()

    def world_pose(self, link):
        resp = self.link_state(f"{self.model_name}::{link}", "")
        assert resp.success, resp.status_message
        p, q = resp.link_state.pose.position, resp.link_state.pose.orientation
        return (p.x, p.y, p.z), (q.x, q.y, q.z, q.w)

    def links(self):
        """The links Gazebo keeps (the root and every child of a moving joint)."""
        return [self.model.root] + [j.child for j in self.model.joints.values() if j.type != "fixed"]

    def body_errors(self, settle_timeout=20.0):
        """{link: PoseError} of every kept link: ground truth against joint_states + the URDF, taken once the
        joints have settled (``JointStates.settled``: within 1 mrad over 0.3 s of sim time) and with the physics
        paused while the links are read (one instant for all)."""
        positions = self.states.settled(timeout=settle_timeout)
        rospy.ServiceProxy("/gazebo/pause_physics", Empty)()
        try:
            measured = {link: self.world_pose(link) for link in self.links()}
        finally:
            rospy.ServiceProxy("/gazebo/unpause_physics", Empty)()
        return pose_errors(self.model, positions, measured)

    def assert_body_agrees(self, test, distance=0.005, angle=0.01):
        errors = self.body_errors()
        worst = max(errors.items(), key=lambda item: item[1].distance)
        test.assertLess(worst[1].distance, distance, f"link {worst[0]} is {worst[1].distance * 1000:.1f} mm from "
                        "where joint_states and the URDF put it")
        turned = max(errors.items(), key=lambda item: item[1].angle)
        test.assertLess(turned[1].angle, angle, f"link {turned[0]} is turned {turned[1].angle:.4f} rad from where "
                        "joint_states and the URDF put it")


def close(values, wanted, tol):
    return all(v is not None and abs(v - w) <= tol for v, w in zip(values, wanted))


def angle_diff(a, b):
    return math.atan2(math.sin(a - b), math.cos(a - b))
