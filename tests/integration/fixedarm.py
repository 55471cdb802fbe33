"""Shared helpers of the arm_way suites: arms bolted to the world by a URDF ``world`` link, launched from
published-style packages (tests/data/arm_way) and judged by the body.

- The base: where Gazebo holds the first real link (``/gazebo/get_link_state <model>::<link>``) against the
  spawn pose composed with the world joint's origin.
- Joint speeds: Gazebo enforces a URDF velocity limit only through the joint's own effort
  (``Joint::CheckAndTruncateForce``, and joint_limits_interface's saturation before it, zero an effort that
  pushes a joint further once it moves faster than its limit, judged at the start of each step); the other
  joints still push it through the mass matrix, gravity and the velocity-product terms, so a joint may pass
  its limit, by a few % at 1 ms when only its own effort drives it, and by more when a neighbour swings it.
  What must hold is Gazebo's rule, judged on the body: over every interval between two /joint_states messages
  (the physics' positions and velocities) that a joint began and ended faster than OVER_SHARE times its limit,
  the generalized force it received along its motion, from the inverse dynamics of the measured motion
  (``M(q) qdd + C(q, qd) qd + g(q)``, :class:`Dynamics`: PyBullet in a client of this node's own, from the
  URDF, base fixed), is no push: at most PUSH_SHARE of its effort limit (the rest is the finite difference's
  noise; its damping and friction pull the other way). Measured with the velocity rule taken out of the
  simulator, a step command pushes the WidowX-like waist with 9.5 N·m (its limit 8) at twice its speed limit.
- Tracking: the trajectory controller's own error (its ``state`` topic) from the goal's start to its end.

Figures are printed as ``FIGURE`` lines (simtest.figure), which the runner shows.
"""
import math
import os
import tempfile
import threading
import unittest

import rospy
from actionlib_msgs.msg import GoalStatus
from armtest import Arm, JointStates, trajectory
from control_msgs.msg import FollowJointTrajectoryResult as Result, JointTrajectoryControllerState
from controller_manager_msgs.srv import ListControllers
from gazebo_msgs.msg import ModelState
from gazebo_msgs.srv import GetLinkState, GetPhysicsProperties, SetModelState
from sensor_msgs.msg import JointState
from simtest import action_done, figure, wait_for
from std_srvs.srv import Empty
from traittest import sim_now, sim_sleep

from diffbot_sim.check.arm_check import pose_error, pose_errors
from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.transforms import compose, rpy_quaternion

#: m, rad: a base bolted to the world stays this close to where it was spawned
BASE_DISTANCE, BASE_ANGLE = 0.001, 0.002
#: s (wall) a suite that presses play waits for the spawner to have started the controllers while paused
START_WHILE_PAUSED = 10.0
#: Share of a joint's effort limit that the force along its motion may reach while it is over its velocity limit
PUSH_SHARE = 0.25
#: An interval counts as over the limit when the joint is this many times its limit at both ends (nearer the
#: limit it may have dipped under it between two messages, where its own effort rightly pushes again)
OVER_SHARE = 1.2


def _proxy(name, kind):
    rospy.wait_for_service(name, 60)
    return rospy.ServiceProxy(name, kind)


def physics_step():
    """The simulator's physics step [s] (get_physics_properties' time_step)."""
    return _proxy("/gazebo/get_physics_properties", GetPhysicsProperties)().time_step


class Base:
    """The root link of ``model_name`` (a RobotModel ``model`` bolted to the world) against where Gazebo holds
    it: the spawn pose (spawn_model's -x -y -z -R -P -Y) composed with the world joint's origin."""

    def __init__(self, model_name, model, xyz=(0.0, 0.0, 0.0), rpy=(0.0, 0.0, 0.0)):
        joint = model.anchor
        assert joint is not None, f"{model.name}: no fixed joint from a 'world' link"
        self.name = f"{model_name}::{model.root}"
        self.expected = compose((tuple(xyz), rpy_quaternion(*rpy)), (tuple(joint.xyz), rpy_quaternion(*joint.rpy)))
        self.link_state = _proxy("/gazebo/get_link_state", GetLinkState)
        self.worst = 0.0  # the largest distance seen, m

    def pose(self):
        resp = self.link_state(self.name, "")
        assert resp.success, f"get_link_state {self.name}: {resp.status_message}"
        p, q = resp.link_state.pose.position, resp.link_state.pose.orientation
        return (p.x, p.y, p.z), (q.x, q.y, q.z, q.w)

    def drift(self):
        """PoseError of the base now against where it belongs (also kept in ``worst``)."""
        error = pose_error(self.expected, self.pose())
        self.worst = max(self.worst, error.distance)
        return error

    def assert_in_place(self, test, what):
        error = self.drift()
        test.assertLess(error.distance, BASE_DISTANCE, f"{what}: {self.name} is {error.distance * 1000:.2f} mm from "
                        f"its spawn pose {self.expected[0]}")
        test.assertLess(error.angle, BASE_ANGLE, f"{what}: {self.name} is turned {error.angle:.4f} rad from its "
                        "spawn pose")
        return error


class Motion:
    """Every /joint_states message (positions and velocities, by stamp) and every message of a trajectory
    controller's ``state`` topic, kept by the callbacks for the test thread to judge windows of sim time."""

    def __init__(self, joint_states="/joint_states", state=None):
        self.lock = threading.Lock()
        self.joints, self.states = [], []
        self.subs = [rospy.Subscriber(joint_states, JointState, self._joint_states, queue_size=2000)]
        if state:
            self.subs.append(rospy.Subscriber(state, JointTrajectoryControllerState, self._state, queue_size=2000))

    def _joint_states(self, msg):
        with self.lock:
            self.joints.append((msg.header.stamp.to_sec(), dict(zip(msg.name, msg.position)),
                                dict(zip(msg.name, msg.velocity))))

    def _state(self, msg):
        with self.lock:
            self.states.append(msg)

    def wait_states(self, timeout=30.0):
        wait_for(lambda: self.states, timeout, "the controller's state topic")

    def wait_joint_states(self, stamp, timeout=30.0):
        """Until a joint_states message stamped at or after ``stamp`` (sim time) has arrived."""
        wait_for(lambda: self.joints and self.joints[-1][0] >= stamp, timeout,
                 f"joint_states stamped at or after {stamp:.3f} s")

    def samples(self, start, end):
        """[(stamp, positions, velocities)] of the messages stamped in [start, end], oldest first."""
        with self.lock:
            return [m for m in self.joints if start <= m[0] <= end]

    def path_errors(self, start, end, names):
        """{joint: the largest |position error| the controller's state reported} over messages stamped in
        [start, end], and how many there were; waits until one stamped after ``end`` has arrived (a test node
        starved of CPU reads its queue late)."""
        wait_for(lambda: self.states and self.states[-1].header.stamp.to_sec() > end, 30,
                 f"the controller's state stamped after {end:.3f} s")
        with self.lock:
            window = [m for m in self.states if start <= m.header.stamp.to_sec() <= end]
        assert len(window) >= 5, f"{len(window)} state messages between {start:.3f} and {end:.3f} s"
        worst = {}
        for msg in window:
            for name, error in zip(msg.joint_names, msg.error.positions):
                if name in names:
                    worst[name] = max(worst.get(name, 0.0), abs(error))
        return worst, len(window)


class Dynamics:
    """The arm's joint-space inertia and bias torques from its URDF, by PyBullet in a DIRECT client of this
    node's own with the base fixed: an independent reckoning of what one physics step can add to a joint's
    speed once Gazebo stops pushing it (see the module's docstring)."""

    def __init__(self, urdf_xml, gravity=-9.8):
        import pybullet

        self.pb = pybullet
        self.client = pybullet.connect(pybullet.DIRECT)
        with tempfile.NamedTemporaryFile("w", suffix=".urdf", delete=False) as out:
            out.write(urdf_xml)
        try:
            self.body = pybullet.loadURDF(out.name, useFixedBase=True, flags=pybullet.URDF_USE_INERTIA_FROM_FILE,
                                          physicsClientId=self.client)
        finally:
            os.unlink(out.name)
        pybullet.setGravity(0, 0, gravity, physicsClientId=self.client)
        self.dofs = []  # movable joint names in PyBullet's order
        for index in range(pybullet.getNumJoints(self.body, physicsClientId=self.client)):
            info = pybullet.getJointInfo(self.body, index, physicsClientId=self.client)
            if info[2] != pybullet.JOINT_FIXED:
                self.dofs.append(info[1].decode())

    def generalized_forces(self, positions, velocities, accelerations):
        """{joint: the force its joint received} for this motion (inverse dynamics: what the joints' motors,
        damping, friction and limits together applied)."""
        q, qd, qdd = ([values.get(n, 0.0) for n in self.dofs] for values in (positions, velocities, accelerations))
        forces = self.pb.calculateInverseDynamics(self.body, q, qd, qdd, physicsClientId=self.client)
        return dict(zip(self.dofs, forces))

    def gravity(self, positions):
        """{joint: the torque (or force) that holds it against gravity at these positions}."""
        q = [positions.get(n, 0.0) for n in self.dofs]
        zero = [0.0] * len(q)
        torques = self.pb.calculateInverseDynamics(self.body, q, zero, zero, physicsClientId=self.client)
        return dict(zip(self.dofs, torques))


def speed_report(test, model, dynamics, samples, names):
    """Judge ``names``' speeds over ``samples`` (Motion.samples) as Gazebo limits them (module docstring):
    assert that no joint got a push along its motion beyond PUSH_SHARE of its effort limit while it was over
    its velocity limit; returns FIGURE text: each joint's peak speed against its limit, and the largest such
    push."""
    peaks = {n: 0.0 for n in names}
    pushes = {n: (0.0, None) for n in names}
    for (t0, p0, v0), (t1, p1, v1) in zip(samples, samples[1:]):
        for name in names:
            peaks[name] = max(peaks[name], abs(v0.get(name, 0.0)), abs(v1.get(name, 0.0)))
        over = [n for n in names if v0[n] * v1[n] > 0
                and min(abs(v0[n]), abs(v1[n])) > OVER_SHARE * model.joints[n].velocity_limit]
        if not over or t1 <= t0:
            continue
        middle = {n: (p0[n] + p1[n]) / 2 for n in p0 if n in p1}
        speed = {n: (v0[n] + v1[n]) / 2 for n in v0 if n in v1}
        change = {n: (v1[n] - v0[n]) / (t1 - t0) for n in v0 if n in v1}
        forces = dynamics.generalized_forces(middle, speed, change)
        for name in over:
            push = forces[name] * math.copysign(1.0, speed[name])
            if push > pushes[name][0]:
                pushes[name] = (push, (t0, t1, v0[name], v1[name]))
    parts = []
    for name in names:
        joint = model.joints[name]
        push, when = pushes[name]
        parts.append(f"{name} {peaks[name]:.3f}/{joint.velocity_limit:g}" + (f" (push {push:.2f} N·m)" if when else ""))
        if when:
            test.assertLessEqual(push, PUSH_SHARE * joint.effort_limit,
                                 f"{name} was pushed along its motion with {push:.2f} N·m while faster than its "
                                 f"{joint.velocity_limit:g} rad/s limit (from {when[2]:.3f} to {when[3]:.3f} rad/s "
                                 f"between {when[0]:.3f} and {when[1]:.3f} s of sim time): Gazebo cuts its effort "
                                 "there")
    return "peak speed/limit (rad/s) " + ", ".join(parts)


def run_goal(arm, msg, base, timeout=60.0, **kwargs):
    """Send ``msg`` as a FollowJointTrajectory goal and wait for its result (at most ``timeout`` wall s),
    reading the base's ground truth all the while: (goal status, result, sim time just before it was sent)."""
    start = sim_now()
    arm.client.send_goal(arm.goal(msg, **kwargs))

    def ended():
        base.drift()
        return action_done(arm.client)
    wait_for(ended, timeout, "the goal's result", poll=0.05)
    return arm.client.get_state(), arm.client.get_result(), start


def set_model_pose(model_name, xyz, yaw):
    """/gazebo/set_model_state on the whole model (world frame); the service's success."""
    state = ModelState(model_name=model_name, reference_frame="world")
    state.pose.position.x, state.pose.position.y, state.pose.position.z = xyz
    q = rpy_quaternion(0.0, 0.0, yaw)
    state.pose.orientation.x, state.pose.orientation.y, state.pose.orientation.z, state.pose.orientation.w = q
    return _proxy("/gazebo/set_model_state", SetModelState)(state).success


def reset_world_paused(arm):
    """/gazebo/reset_world with the physics paused, then every kept link's pose (the instant after the
    reset, before any step), then the physics unpaused."""
    pause = _proxy("/gazebo/pause_physics", Empty)
    unpause = _proxy("/gazebo/unpause_physics", Empty)
    pause()
    try:
        _proxy("/gazebo/reset_world", Empty)()
        return {link: arm.world_pose(link) for link in arm.links()}
    finally:
        unpause()


def worst(errors):
    """(link, PoseError) of the largest distance."""
    return max(errors.items(), key=lambda item: item[1].distance)


class CommandedArm(Arm):
    """armtest.Arm's body (model, ground truth, joint states, body_errors) for an arm driven through per-joint
    command topics: no trajectory action to wait for."""

    def __init__(self, model_name, description="/robot_description", joint_states="/joint_states"):
        self.client = None
        self.model_name = model_name
        self.model = parse_urdf(rospy.get_param(description))
        self.link_state = _proxy("/gazebo/get_link_state", GetLinkState)
        self.states = JointStates(joint_states)


class FixedArmCase(unittest.TestCase):
    """The checks every arm_way suite makes of its arm; a suite's setUpClass calls ``start_arm``, its tests call
    the ``check_*`` methods. Tolerances are the controller's own, read from its parameters."""

    LABEL = "arm"  # the FIGURE lines' prefix

    @classmethod
    def start_arm(cls, ns, model_name, joints, controller=None, running=(), stopped=(), unpause=False,
                  spawn=((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))):
        """Wait for the launch's controllers (``running`` and ``stopped``: loaded, and in that state), with
        ``unpause`` calling /gazebo/unpause_physics once they are loaded (a launch that leaves Gazebo paused
        for its user to press play); then the arm (``ns``: "" or "/<robot namespace>") and its base."""
        cls.ns, cls.joints, cls.controller = ns, list(joints), controller
        cls.mode = "real time" if rospy.get_param("/gazebo/real_time", True) else "fast"
        listing = _proxy(f"{ns}/controller_manager/list_controllers", ListControllers)
        wanted = set(running) | set(stopped)
        wait_for(lambda: {c.name for c in listing().controller} >= wanted, 90, f"{sorted(wanted)} loaded")
        states = dict.fromkeys(running, "running")
        states.update(dict.fromkeys(stopped, "stopped"))

        def in_their_states():
            return {c.name: c.state for c in listing().controller} == states
        if unpause:
            # Play is pressed once the spawner has started the controllers, so that the arm never hangs limp:
            # they are running at once where a switch is served while paused; where it waits for the first
            # step after play (as gazebo_ros_control's controller manager does), after this deadline.
            try:
                wait_for(in_their_states, START_WHILE_PAUSED, "the controllers started while paused")
            except AssertionError:
                pass
            _proxy("/gazebo/unpause_physics", Empty)()
        wait_for(in_their_states, 90, f"the controllers in their states {states}")
        description, joint_states = f"{ns}/robot_description", f"{ns}/joint_states"
        if controller:
            cls.arm = Arm(f"{ns}/{controller}", model_name, description=description, joint_states=joint_states)
        else:
            cls.arm = CommandedArm(model_name, description=description, joint_states=joint_states)
        cls.base = Base(model_name, cls.arm.model, *spawn)
        cls.motion = Motion(joint_states, f"{ns}/{controller}/state" if controller else None)
        cls.dynamics = Dynamics(rospy.get_param(description))
        cls.dt = physics_step()

    def say(self, text):
        figure(f"{self.LABEL} [{self.mode}] {text}")

    def constraint(self, joint, kind):
        """The trajectory controller's ``constraints/<joint>/<kind>`` (0: not checked), as it reads them."""
        return rospy.get_param(f"{self.ns}/{self.controller}/constraints/{joint}/{kind}", 0.0)

    def check_base_at_rest(self):
        """At rest after the spawn: the base where it was spawned, named as Gazebo names it, no link called
        world, and the step Gazebo would run this world at (1 ms: it states none)."""
        self.assertAlmostEqual(self.dt, 0.001, delta=1e-9, msg="a world that states no step runs at SDF's 1 ms")
        self.arm.states.settled(self.joints, band=0.002)
        error = self.base.assert_in_place(self, "at rest after the spawn")
        self.say(f"base {self.base.name} at rest after the spawn: {error.distance * 1000:.3f} mm, "
                 f"{error.angle:.5f} rad from the spawn pose; step {self.dt * 1000:g} ms")
        lumped = self.base.link_state(f"{self.arm.model_name}::world", "")
        self.assertFalse(lumped.success, "a link named world: Gazebo joins the model to the world instead")

    def run_to(self, goal, speed=0.8, minimum=2.0):
        """A goal straight to ``goal`` at ``speed`` rad/s for the joint with the longest way (at least
        ``minimum`` s), which must SUCCEED: a way to a start pose, not judged further."""
        start = self.arm.states.settled(self.joints, band=0.002)
        seconds = max(minimum, max(abs(g - s) for g, s in zip(goal, start)) / speed)
        state, result, _ = run_goal(self.arm, trajectory(self.joints, (seconds, goal)), self.base)
        self.assertEqual((state, result.error_code), (GoalStatus.SUCCEEDED, Result.SUCCESSFUL),
                         f"to {goal} from {start}: {result.error_string}")

    def check_goal(self, *points, hold_link):
        """A FollowJointTrajectory goal through ``points`` ((time_from_start, positions), ...), judged: SUCCEEDED;
        the controller's error along the way (its state topic) inside each joint's path tolerance; at rest
        within the goal tolerance; no joint faster than Gazebo lets it; the base unmoved; every link where
        joint_states + the URDF put it; ``hold_link`` still for 1 s of sim time."""
        self.motion.wait_states()
        self.arm.states.settled(self.joints, band=0.002)
        self.base.worst = 0.0
        duration, target = points[-1][0], points[-1][1]
        state, result, start = run_goal(self.arm, trajectory(self.joints, *points), self.base)
        path, count = self.motion.path_errors(start, start + duration, self.joints)
        widest = max(path, key=path.get)
        self.say(f"path error {path[widest]:.4f} rad ({widest}; path tolerance "
                 f"{self.constraint(widest, 'trajectory'):g}; {count} state messages); goal "
                 f"{GoalStatus.to_string(state)} {result.error_code} {result.error_string}")
        self.assertEqual((state, result.error_code), (GoalStatus.SUCCEEDED, Result.SUCCESSFUL), result.error_string)
        for joint in self.joints:
            tolerance = self.constraint(joint, "trajectory")
            if tolerance > 0:
                self.assertLess(path[joint], tolerance, f"{joint} strayed {path[joint]:.4f} rad from its path")
        goal_time = rospy.get_param(f"{self.ns}/{self.controller}/constraints/goal_time", 0.0)
        self.check_rest(target, start, start + duration + goal_time, hold_link,
                        {j: self.constraint(j, "goal") for j in self.joints})

    def check_rest(self, target, start, end, hold_link, tolerances):
        """The arm at rest at ``target`` within ``tolerances`` ({joint: rad}; 0: not checked), its joints' peak
        speeds over [start, end] of sim time (``end`` None: until it came to rest) within what Gazebo allows,
        the base unmoved all along, every link where joint_states + the URDF put it, and ``hold_link`` still for
        1 s of sim time."""
        rest = dict(zip(self.joints, self.arm.states.settled(self.joints)))
        end = sim_now() if end is None else end
        final = {j: abs(rest[j] - t) for j, t in zip(self.joints, target)}
        off = max(final, key=final.get)
        self.motion.wait_joint_states(end)
        speeds = speed_report(self, self.arm.model, self.dynamics, self.motion.samples(start, end), self.joints)
        link, body = worst(self.arm.body_errors())
        self.say(f"final error {final[off]:.4f} rad ({off}; goal tolerance {tolerances[off]:g}); worst link "
                 f"{body.distance * 1000:.3f} mm ({link}); base drift while moving {self.base.worst * 1000:.3f} mm")
        self.say(speeds)
        for joint in self.joints:
            if tolerances[joint] > 0:
                self.assertLess(final[joint], tolerances[joint], f"{joint} came to rest at {rest[joint]:.4f}")
        self.assertLess(self.base.worst, BASE_DISTANCE,
                        f"the base moved {self.base.worst * 1000:.2f} mm while the arm moved")
        self.base.assert_in_place(self, "after the move")
        self.arm.assert_body_agrees(self, distance=0.003, angle=0.01)
        held = self.arm.world_pose(hold_link)[0]
        sim_sleep(1.0)
        moved = math.dist(held, self.arm.world_pose(hold_link)[0])
        self.say(f"{hold_link} moved {moved * 1000:.3f} mm over 1 s of holding")
        self.assertLess(moved, 0.002, "the arm did not hold its goal")

    def check_set_model_state(self, xyz=(0.5, 0.3, 0.6), yaw=0.8):
        """/gazebo/set_model_state on the arm: accepted, and the base stays where it was spawned."""
        self.assertTrue(set_model_pose(self.arm.model_name, xyz, yaw), "set_model_state refused")
        self.arm.states.settled(self.joints, band=0.002)
        error = self.base.assert_in_place(self, "after set_model_state")
        self.say(f"base after set_model_state to {xyz}: {error.distance * 1000:.3f} mm from the spawn pose")
        self.arm.assert_body_agrees(self, distance=0.003, angle=0.01)

    def check_reset_world(self):
        """/gazebo/reset_world: the instant after it every joint at zero (Gazebo's Model::Reset) and the base
        at the spawn pose; the base still there once the arm has settled."""
        measured = reset_world_paused(self.arm)
        zero = {j.name: 0.0 for j in self.arm.model.joints.values() if j.movable}
        link, error = worst(pose_errors(self.arm.model, zero, measured))
        self.assertLess(error.distance, 0.001, f"after reset_world {link} is {error.distance * 1000:.2f} mm from "
                        "where the URDF puts it with every joint at zero")
        self.base.assert_in_place(self, "right after reset_world")
        self.arm.states.settled(self.joints, band=0.002)
        after = self.base.assert_in_place(self, "once the arm settled after reset_world")
        self.say(f"reset_world: links {error.distance * 1000:.3f} mm from the zero configuration ({link}); base "
                 f"{after.distance * 1000:.3f} mm from the spawn pose once settled")
        self.arm.assert_body_agrees(self, distance=0.003, angle=0.01)
