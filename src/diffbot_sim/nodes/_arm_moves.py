"""robot_check's arm check (rospy side): every arm joint moved a small step and back by the controller that
commands it, as a user's client would (a FollowJointTrajectory goal, a GripperCommand goal, or a position
command topic), and the body judged after each move with the physics paused: every link Gazebo keeps
(/gazebo/get_link_state) against where joint_states + the URDF put it. What to move and how it is judged is
:mod:`diffbot_sim.check.arm_report` (pure)."""
import collections
import threading
import time

import rospy

from diffbot_sim.check import arm_report, stillness
from diffbot_sim.check.arm_check import pose_errors

SERVER_TIMEOUT = 20.0  # s (wall) for an action server or a command subscriber
MOVE_TIME = 1.0  # s (sim): a trajectory goal's one point
RESULT_TIMEOUT = 15.0  # s (sim) for a goal's result
SETTLE_TIMEOUT = 5.0  # s (sim) for the joints to come to rest after a move
#: The moved joints are at rest once their joint_states positions held within SETTLE_BAND (rad or m) over
#: SETTLE_WINDOW s of the messages' stamps (check.stillness): one message with low velocities is also an
#: oscillation's turnaround.
SETTLE_BAND, SETTLE_WINDOW = 1e-3, 0.3


def wait_for_goal(client, timeout):
    """Wait up to ``timeout`` s of sim time for the goal a SimpleActionClient just sent to end; True when it did.

    Instead of ``client.wait_for_result``: actionlib's SimpleActionClient drops the transitions of a goal that
    ends before ``send_goal`` has stored its handle, and then waits PENDING for ever; a goal already met (a
    gripper told to open when open) ends that fast in fast mode. The goal handle itself has them all, and
    ``get_state``/``get_result`` read it."""
    from actionlib import CommState

    deadline = rospy.get_time() + timeout
    while not rospy.is_shutdown():
        handle = client.gh
        if handle is not None and handle.get_comm_state() == CommState.DONE:
            return True
        if rospy.get_time() > deadline:
            return False
        time.sleep(0.002)  # wall: polling the handle, not waiting for sim time
    return False


class JointStates:
    """The latest position and velocity of every joint on one joint_states topic (callbacks only store)."""

    def __init__(self, topic):
        from sensor_msgs.msg import JointState

        self.lock = threading.Lock()
        self.positions, self.velocities, self.count = {}, {}, 0
        self.history = collections.deque(maxlen=2000)  # (stamp [s, sim], {joint: position}) as they came
        self.sub = rospy.Subscriber(topic, JointState, self._keep, queue_size=20)

    def _keep(self, msg):
        with self.lock:
            self.positions.update(zip(msg.name, msg.position))
            self.velocities.update(zip(msg.name, msg.velocity))
            self.history.append((msg.header.stamp.to_sec(), dict(self.positions)))
            self.count += 1

    def samples(self, joints, since):
        """[(stamp, [position of each joint])] of the messages stamped at or after sim time ``since``."""
        with self.lock:
            return [(stamp, [p.get(j, 0.0) for j in joints]) for stamp, p in self.history if stamp >= since]

    def get(self):
        with self.lock:
            return dict(self.positions), dict(self.velocities), self.count


def _name(ns, *parts):
    return "/".join([ns.rstrip("/")] + [p.strip("/") for p in parts])


class _Body:
    """Ground truth of the robot's kept links, read with the physics paused."""

    def __init__(self, model):
        from gazebo_msgs.srv import GetLinkState, GetWorldProperties
        from std_srvs.srv import Empty

        self.model = model
        rospy.wait_for_service("/gazebo/get_link_state", SERVER_TIMEOUT)
        self.link_state = rospy.ServiceProxy("/gazebo/get_link_state", GetLinkState)
        self.pause = rospy.ServiceProxy("/gazebo/pause_physics", Empty)
        self.unpause = rospy.ServiceProxy("/gazebo/unpause_physics", Empty)
        names = list(rospy.ServiceProxy("/gazebo/get_world_properties", GetWorldProperties)().model_names)
        self.entity = model.name if model.name in names else (names[-1] if names else model.name)
        self.links = [model.root] + [j.child for j in model.joints.values() if j.type != "fixed"]

    def errors(self, states):
        """{link: PoseError} with the physics paused; and the joint positions joint_states gave then."""
        self.pause()
        try:
            positions = states.get()[0]
            measured = {}
            for link in self.links:
                resp = self.link_state(f"{self.entity}::{link}", "")
                if resp.success:
                    p, q = resp.link_state.pose.position, resp.link_state.pose.orientation
                    measured[link] = ((p.x, p.y, p.z), (q.x, q.y, q.z, q.w))
        finally:
            self.unpause()
        if self.model.root not in measured:
            return {}, positions
        return pose_errors(self.model, positions, measured), positions


class _Sender:
    """Sends a move the way its controller takes commands; answers what the controller said."""

    def __init__(self, ns, controllers, joints, wait):
        self.ns, self.controllers, self.wait = ns, controllers, wait
        self.infos = {j.name: j for j in joints}
        self.clients, self.publishers = {}, {}

    def _params(self, controller):
        return next((p for n, p in self.controllers.items() if n.rstrip("/").endswith("/" + controller)), {})

    def send(self, move, targets):
        if move.how == arm_report.TRAJECTORY:
            return self._trajectory(move, targets)
        if move.how == arm_report.GRIPPER:
            return self._gripper(move, targets)
        return self._topic(move, targets)

    def _client(self, move, action, kind):
        import actionlib

        if move.controller not in self.clients:
            client = actionlib.SimpleActionClient(_name(self.ns, move.controller, action), kind)
            if not client.wait_for_server(rospy.Duration(SERVER_TIMEOUT)):
                return None
            self.clients[move.controller] = client
        return self.clients[move.controller]

    def _finish(self, client):
        from actionlib_msgs.msg import GoalStatus

        if not wait_for_goal(client, RESULT_TIMEOUT):
            client.cancel_goal()
            return "no result"
        result = client.get_result()
        code = getattr(result, "error_code", None)
        return GoalStatus.to_string(client.get_state()) + (f" (error_code {code})" if code else "")

    def _trajectory(self, move, targets):
        from control_msgs.msg import FollowJointTrajectoryAction, FollowJointTrajectoryGoal
        from trajectory_msgs.msg import JointTrajectoryPoint

        client = self._client(move, "follow_joint_trajectory", FollowJointTrajectoryAction)
        if client is None:
            return "no follow_joint_trajectory action server"
        goal = FollowJointTrajectoryGoal()
        goal.trajectory.joint_names = list(move.joints)
        goal.trajectory.points = [JointTrajectoryPoint(positions=list(targets),
                                                       time_from_start=rospy.Duration.from_sec(MOVE_TIME))]
        client.send_goal(goal)
        return self._finish(client)

    def _gripper(self, move, targets):
        from control_msgs.msg import GripperCommandAction, GripperCommandGoal

        client = self._client(move, "gripper_cmd", GripperCommandAction)
        if client is None:
            return "no gripper_cmd action server"
        goal = GripperCommandGoal()
        goal.command.position = targets[0]
        goal.command.max_effort = arm_report.max_effort_for(self.infos.get(move.joints[0]),
                                                            self._params(move.controller))
        client.send_goal(goal)
        return self._finish(client)

    def _topic(self, move, targets):
        from std_msgs.msg import Float64, Float64MultiArray

        single = isinstance(self._params(move.controller).get("joint"), str)
        if move.controller not in self.publishers:
            pub = rospy.Publisher(_name(self.ns, move.controller, "command"), Float64 if single else Float64MultiArray,
                                  queue_size=1, latch=True)
            self.wait(lambda: pub.get_num_connections() > 0, SERVER_TIMEOUT, f"{move.controller}/command subscribed")
            self.publishers[move.controller] = pub
        self.publishers[move.controller].publish(Float64(targets[0]) if single else Float64MultiArray(data=targets))
        rospy.sleep(MOVE_TIME)
        return ""


def settle(states, joints, band=SETTLE_BAND, window=SETTLE_WINDOW, timeout=SETTLE_TIMEOUT, since=None):
    """Wait (sim time, at most ``timeout``) until ``joints`` held within ``band`` over ``window`` s, judged by the
    stamps of the joint_states messages stamped at or after sim time ``since`` (default: now, i.e. after the move
    just made; check.stillness.held_still). Returns (True, None), or (False, why) at the deadline."""
    since = rospy.get_time() if since is None else since
    deadline, why = rospy.get_time() + timeout, "shut down"
    while not rospy.is_shutdown():
        still, why = stillness.held_still(states.samples(joints, since), band, window)
        if still:
            return True, None
        if rospy.get_time() >= deadline:
            break
        rospy.sleep(0.05)
    return False, why


def check_arm(report, wait):
    """Move every arm joint of ``report`` (a robot_report.Report) and judge the body: (passed, lines, moved
    any): nothing to move is a failure the caller excuses for a robot that drives (a holonomic base's wheels have
    transmissions and no controller we simulate).

    ``wait(predicate, timeout, what)``: the caller's wait, which raises when the simulator dies.
    """
    ns = report.control_ns
    states = JointStates(_name(ns, "joint_states"))
    wait(lambda: states.get()[2] > 0, SERVER_TIMEOUT, f"{_name(ns, 'joint_states')}")
    settle(states, [j.name for j in report.joints])  # the controllers have started and hold the joints
    positions = states.get()[0]
    moves, skipped = arm_report.plan_moves(report.joints, positions,
                                           arm_report.controller_joints(report.controllers, ns))
    lines = [f"arm joints ({sum(len(m.moved) for m in moves)} moved by {len(moves)} controller(s), "
             "judged by ground truth against joint_states + the URDF):"]
    body = _Body(report.model)
    sender = _Sender(ns, report.controllers, report.joints, wait)
    slides = {j.name: j.slide for j in report.joints}
    results = []
    for move in moves:
        start = [positions[j] for j in move.joints]
        for phase, targets in (("out", move.targets), ("back", start)):
            answer = sender.send(move, targets)
            settle(states, move.moved)
            errors, reached = body.errors(states)
            results.append(arm_report.judge_move(move, phase, dict(zip(move.joints, targets)), reached, slides,
                                                 errors, answer))
    lines += arm_report.format_moves(results, skipped)
    passed = bool(results) and all(r.passed for r in results)
    if not results:
        lines.append("  no arm joint has a controller robot_check can move (a trajectory, gripper or position "
                     "controller in the YAMLs given)")
    return passed, lines, bool(results)
