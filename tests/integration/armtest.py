"""Shared helpers of the arm suites: FollowJointTrajectory goals, joint states, and the body judged by the
physics' ground truth (/gazebo/get_link_state) against joint_states + the URDF (check.arm_check)."""
import math
import threading

import actionlib
import rospy
from control_msgs.msg import FollowJointTrajectoryAction, FollowJointTrajectoryGoal, JointTolerance
from gazebo_msgs.srv import GetLinkState
from sensor_msgs.msg import JointState
from std_srvs.srv import Empty
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from diffbot_sim.check.arm_check import pose_errors
from diffbot_sim.description.urdf_model import parse_urdf
from simtest import action_done, wait_for


class JointStates:
    """The latest position of every joint on /joint_states (several publishers merge, as in TF)."""

    def __init__(self, topic="/joint_states"):
        self.lock = threading.Lock()
        self.positions, self.velocities, self.count = {}, {}, 0
        self.sub = rospy.Subscriber(topic, JointState, self._keep, queue_size=50)

    def _keep(self, msg):
        with self.lock:
            self.positions.update(zip(msg.name, msg.position))
            self.velocities.update(zip(msg.name, msg.velocity))
            self.count += 1

    def get(self, names=None):
        with self.lock:
            return dict(self.positions) if names is None else [self.positions.get(n) for n in names]

    def fresh(self, timeout=10.0):
        """Positions received after now."""
        start = self.count
        wait_for(lambda: self.count > start + 1, timeout, "fresh joint_states")
        return self.get()


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

    def at_rest(self, speed=0.02):
        with self.states.lock:
            return self.states.count > 0 and all(abs(v) < speed for v in self.states.velocities.values())

    def body_errors(self, settle_timeout=20.0):
        """{link: PoseError} of every kept link: ground truth against joint_states + the URDF, taken once the
        joints are at rest and with the physics paused while the links are read (one instant for all)."""
        wait_for(self.at_rest, settle_timeout, "the joints at rest (joint_states velocities < 0.02)")
        positions = self.states.fresh()
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
