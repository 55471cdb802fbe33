#!/usr/bin/env python3
"""arm_commands suite: commands to arms through controller_manager, bad input, and Gazebo's joint API, each
judged by the body (ground truth: /gazebo/get_link_state). Robots: arm_commands.test.

- Controller switches asked for while paused wait for the unpause (upstream waits for its realtime loop).
- Gazebo's joint API: spawn_model -J with -unpause (a paused world, the configuration seen by ground truth),
  set_model_configuration (upstream's answers, limits clamp), get_joint_properties, apply_joint_effort (the
  joint gains the momentum F·T its inertia says, for the duration given) and clear_joint_forces,
  get_link_state of every link Gazebo keeps (where joint positions + the URDF put them).
- Group and single forward controllers (position, velocity, effort-PID, effort) move the arm as commanded; a
  command of the wrong size is ignored; two controllers on one joint are a resource conflict.
- Bad input: an effort JointTrajectoryController without gains loads, but starting it is refused with a
  message naming the gains and nothing moves; bad trajectories on the command topic are ignored.
"""
import os
import subprocess
import sys
import threading
import unittest

import rospy
import rostest
import yaml
from gazebo_msgs.srv import ApplyJointEffort, GetJointProperties, JointRequest, SetModelConfiguration
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64, Float64MultiArray
from std_srvs.srv import Empty
from trajectory_msgs.msg import JointTrajectory

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from armtest import trajectory
from simtest import Latest, wait_for
from traittest import Manager, Rosout, Truth, settled, sim_now, sim_sleep

from diffbot_sim.check.arm_check import pose_errors

ROBOTS = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "data", "robots")
ARMS = {"pos": "position_group", "vel": "velocity_group", "eff": "effort_position_group"}
JOINTS = ["joint_1", "joint_2", "joint_3"]
JCONF = (1.5, 2.0)  # where /jconf is spawned
EFF_INERTIA = 2.46667e-4  # kg m^2: jconf's eff_link about its joint axis (z through its centre of mass)


def kept_links(model):
    """The links Gazebo keeps: the root and the child of every joint that is not fixed."""
    return [model.root] + [j.child for j in model.joints.values() if j.type != "fixed"]


class ArmCommands(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_arm_commands")
        cls.truth = Truth()
        cls.rosout = Rosout()
        with open(os.path.join(ROBOTS, "arm_group_controllers.yaml")) as text:
            cls.group_params = yaml.safe_load(text)
        cls.managers = {ns: Manager(ns) for ns in ARMS}
        clocks = []  # /clock goes on while paused (as Gazebo's): its messages count the simulator's loop going round
        clock_sub = rospy.Subscriber("/clock", Clock, lambda msg: clocks.append(msg.clock.to_sec()), queue_size=100)
        paused_at = sim_now()
        switched = {}  # ns: the switch service's answer, once it came
        def start(ns, group):
            switched[ns] = cls.managers[ns].switch(start=["joint_state_controller", group])
        switches = []
        for ns, group in ARMS.items():
            manager = cls.managers[ns]
            for name in ("joint_state_controller", group):
                assert manager.load(name, cls.group_params[name]), f"/{ns}: {name} did not load"
            # as a spawner's: upstream's switch waits for its realtime loop, which runs only once physics does
            switches.append(threading.Thread(target=start, args=(ns, group), daemon=True))
            switches[-1].start()
        # a look at a paused world: five /clock messages after the switches were asked for (the paused loop sends
        # one every 0.1 s of its own time), however slowly this node runs; unpaused, fast mode would race ahead
        seen = len(clocks)
        wait_for(lambda: len(clocks) >= seen + 5, 30, "five /clock messages while paused")
        clock_sub.unregister()
        cls.was_paused = (paused_at, sim_now())
        cls.answered_while_paused = dict(switched)
        cls.states = {ns: Latest(f"/{ns}/joint_states", JointState) for ns in ARMS}
        cls.spawn = subprocess.run(
            ["rosrun", "gazebo_ros", "spawn_model", "-urdf", "-param", "/jconf/robot_description", "-model", "jconf",
             "-robot_namespace", "jconf", "-x", str(JCONF[0]), "-y", str(JCONF[1]),
             "-J", "vel_joint", "0.4", "-J", "eff_joint", "-0.3", "-J", "pos_joint", "0.6", "-unpause"],
            capture_output=True, text=True, timeout=60)
        for thread in switches:
            thread.join(30)
        assert switched == {ns: True for ns in ARMS}, f"switches after -unpause answered {switched}"
        cls.configuration = rospy.ServiceProxy("/gazebo/set_model_configuration", SetModelConfiguration)
        cls.properties = rospy.ServiceProxy("/gazebo/get_joint_properties", GetJointProperties)
        cls.effort = rospy.ServiceProxy("/gazebo/apply_joint_effort", ApplyJointEffort)
        cls.clear = rospy.ServiceProxy("/gazebo/clear_joint_forces", JointRequest)
        cls.pause = rospy.ServiceProxy("/gazebo/pause_physics", Empty)
        cls.unpause = rospy.ServiceProxy("/gazebo/unpause_physics", Empty)

    # -- helpers -------------------------------------------------------------------------------------------
    def publisher(self, topic, kind):
        pub = rospy.Publisher(topic, kind, queue_size=1, latch=True)
        wait_for(lambda: pub.get_num_connections() > 0, 20, f"a subscriber of {topic}")
        return pub

    def arm(self, ns):
        return self.truth.joints(ns, JOINTS)

    def wait_arm(self, ns, target, tolerance=0.02, timeout=30):
        wait_for(lambda: all(abs(a - b) < tolerance for a, b in zip(self.arm(ns), target)), timeout,
                 f"/{ns} joints at {target} (at {self.arm(ns)})")

    def settled_arm(self, ns, seconds=0.3, tolerance=0.001, timeout=30):
        """The arm's joints (ground truth) once they have stopped moving: every reading within ``tolerance`` rad
        or m over ``seconds`` of sim time (traittest.settled): a PID-held arm goes on settling after it first
        reaches its target."""
        return settled(lambda: self.arm(ns), tolerance, window=seconds, timeout=timeout, what=f"/{ns}'s arm")

    def assert_still(self, ns, before, what, seconds=0.5, tolerance=0.005):
        sim_sleep(seconds)
        after = self.arm(ns)
        self.assertTrue(all(abs(a - b) < tolerance for a, b in zip(after, before)),
                        f"/{ns}: {what} moved the arm: {before} -> {after}")

    def body_agrees(self, ns, positions, distance=0.005, angle=0.01):
        """Every kept link of ``ns`` where ``positions`` ({joint: value}, or a function giving them, called with
        the physics paused) + the URDF put it, the physics paused while the links are read."""
        model = self.truth.model(ns)
        self.pause()
        try:
            measured = {link: self.truth.link(f"{ns}::{link}") for link in kept_links(model)}
            if callable(positions):
                positions = positions()
        finally:
            self.unpause()
        errors = pose_errors(model, positions, measured)
        worst = max(errors.items(), key=lambda item: item[1].distance)
        turned = max(errors.items(), key=lambda item: item[1].angle)
        self.assertLess(worst[1].distance, distance, f"/{ns}: link {worst[0]} is {worst[1].distance * 1000:.1f} mm off")
        self.assertLess(turned[1].angle, angle, f"/{ns}: link {turned[0]} is turned {turned[1].angle:.4f} rad off")

    def paused_until(self, done, what, timeout=30):
        """With the physics paused: run it in unpause-pause round trips until ``done()`` (asked while paused)."""
        def round_trip():
            if done():
                return True
            self.unpause()
            self.pause()
            return False
        wait_for(round_trip, timeout, what)

    def joint_states(self, ns):
        """{joint: position} from a /<ns>/joint_states message stamped at or after the simulator's sim time now
        (the newest this node holds may be older on a busy machine)."""
        since = sim_now()
        msg = wait_for(lambda: (m := self.states[ns].get()) is not None and m.header.stamp.to_sec() >= since and m,
                       10, f"/{ns}/joint_states stamped at or after {since:.3f}")
        return dict(zip(msg.name, msg.position))

    def rate(self, joint):
        resp = self.properties(joint)
        self.assertTrue(resp.success, resp.status_message)
        return resp.rate[0]

    # -- Gazebo's joint API ----------------------------------------------------------------------------------
    def test_a_spawn_model_J_then_unpause(self):
        self.assertEqual(self.spawn.returncode, 0, self.spawn.stdout + self.spawn.stderr)
        before, after_wait = self.was_paused
        self.assertEqual(before, after_wait, "sim time ran before spawn_model's -unpause (the world was not paused)")
        self.assertEqual(self.answered_while_paused, {}, "a controller switch was done while physics was paused")
        wait_for(lambda: sim_now() > after_wait + 0.5, 30, "sim time running after -unpause")
        vel, eff = self.truth.joints("jconf", ["vel_joint", "eff_joint"])
        self.assertAlmostEqual(vel, 0.4, delta=0.005, msg="-J vel_joint 0.4 not where the body is")
        self.assertAlmostEqual(eff, -0.3, delta=0.005, msg="-J eff_joint -0.3 not where the body is")
        # a position joint without a running controller is driven back to DefaultRobotHWSim's initial command
        # (0) once time runs, as in Gazebo (gazebo_ros_pkgs issue 93)
        self.assertAlmostEqual(self.truth.joint("jconf", "pos_joint"), 0.0, delta=0.01)

    def test_b_set_model_configuration(self):
        resp = self.configuration("jconf", "", ["eff_joint", "vel_joint"], [0.5, -0.2])
        self.assertEqual((resp.success, resp.status_message), (True, "SetModelConfiguration: success"))
        sim_sleep(0.2)
        eff, vel = self.truth.joints("jconf", ["eff_joint", "vel_joint"])
        self.assertAlmostEqual(eff, 0.5, delta=0.005)
        self.assertAlmostEqual(vel, -0.2, delta=0.005)
        resp = self.configuration("jconf", "", ["eff_joint"], [2.5])  # beyond its upper limit 1.0: clamped
        self.assertTrue(resp.success, resp.status_message)
        sim_sleep(0.2)
        self.assertAlmostEqual(self.truth.joint("jconf", "eff_joint"), 1.0, delta=0.01)
        resp = self.configuration("no_such_model", "", ["eff_joint"], [0.0])
        self.assertEqual((resp.success, resp.status_message), (False, "SetModelConfiguration: model does not exist"))
        resp = self.configuration("jconf", "", ["eff_joint", "vel_joint"], [0.0])
        self.assertFalse(resp.success)
        self.assertEqual(resp.status_message,
                         "SetModelConfiguration: joint name and position list have different lengths")

    def test_c_get_joint_properties(self):
        self.configuration("jconf", "", ["eff_joint"], [-0.25])
        sim_sleep(0.2)
        resp = self.properties("eff_joint")
        self.assertEqual((resp.success, resp.status_message), (True, "GetJointProperties: got properties"))
        self.assertEqual(resp.type, 0)  # REVOLUTE
        self.assertAlmostEqual(resp.position[0], self.truth.joint("jconf", "eff_joint"), delta=1e-4)
        self.assertAlmostEqual(resp.position[0], -0.25, delta=0.005)
        self.assertAlmostEqual(resp.rate[0], 0.0, delta=0.01)
        self.assertEqual(list(resp.damping), [])
        resp = self.properties("no_such_joint")
        self.assertEqual((resp.success, resp.status_message), (False, "GetJointProperties: joint not found"))

    def test_d_apply_joint_effort_for_its_duration_then_clear_joint_forces(self):
        self.configuration("jconf", "", ["eff_joint"], [-0.8])
        sim_sleep(0.2)
        torque, seconds = 0.001, 0.2  # N·m for s: the bar gains tau T / I = 0.81 rad/s and keeps it (no damping)
        self.pause()
        try:  # read right after the impulse: run the physics in unpause-pause round trips, read while paused
            start = sim_now()
            resp = self.effort("eff_joint", torque, rospy.Time(0), rospy.Duration.from_sec(seconds))
            self.paused_until(lambda: sim_now() >= start + seconds + 0.05, "the effort's duration to pass")
            t1, first = sim_now(), self.rate("eff_joint")
            self.paused_until(lambda: sim_now() >= t1 + 0.2, "0.2 s more")
            t2, second = sim_now(), self.rate("eff_joint")
        finally:
            self.unpause()
        self.assertEqual((resp.success, resp.status_message), (True, "ApplyJointEffort: effort set"))
        expected = torque * seconds / EFF_INERTIA
        print(f"arm_commands: eff_joint at {first:.4f} rad/s {t1 - start - seconds:.3f} s after a {torque} N·m x "
              f"{seconds} s effort (tau T / I = {expected:.4f}), {second:.4f} rad/s {t2 - t1:.3f} s later", flush=True)
        self.assertAlmostEqual(first, expected, delta=0.1 * expected, msg=f"rate {first:.3f} after the effort")
        # (PyBullet's link damping takes a few % a second off; the effort left on would add 0.8 rad/s)
        self.assertLess(second, first + 0.05, f"the effort went on after its duration: {first:.3f} -> {second:.3f}")
        resp = self.effort("no_such_joint", 1.0, rospy.Time(0), rospy.Duration(1))
        self.assertEqual((resp.success, resp.status_message), (False, "ApplyJointEffort: joint not found"))
        # an endless effort, cleared: the joint keeps the speed it had
        self.configuration("jconf", "", ["eff_joint"], [-0.8])
        self.pause()
        try:
            self.effort("eff_joint", 0.0005, rospy.Time(0), rospy.Duration(-1))
            self.paused_until(lambda: self.rate("eff_joint") > 0.1, "eff_joint speeding up")
            self.clear("eff_joint")
            cleared = self.rate("eff_joint")
        finally:
            self.unpause()
        sim_sleep(0.3)
        self.assertLess(self.rate("eff_joint"), cleared + 0.05, "clear_joint_forces left the effort on")

    def test_e_get_link_state_of_every_kept_link(self):
        model = self.truth.model("jconf")

        def positions():
            found = {}
            for joint in model.joints.values():
                if joint.type != "fixed":
                    resp = self.properties(joint.name)
                    self.assertTrue(resp.success, f"{joint.name}: {resp.status_message}")
                    found[joint.name] = resp.position[0]
            return found
        self.body_agrees("jconf", positions)
        for ns in ARMS:
            self.body_agrees(ns, self.joint_states(ns))
        resp = self.truth.link_state("pos::tool_link", "")  # lumped into link_3 by Gazebo's URDF reader
        self.assertFalse(resp.success)
        self.assertFalse(self.truth.link_state("nobody::base_link", "").success)

    # -- forward and group controllers --------------------------------------------------------------------
    def test_f_position_group_single_and_a_resource_conflict(self):
        ns, manager = "pos", self.managers["pos"]
        group = self.publisher(f"/{ns}/position_group/command", Float64MultiArray)
        target = [0.5, 0.4, 0.3]
        group.publish(Float64MultiArray(data=target))
        self.wait_arm(ns, target)
        self.settled_arm(ns)
        self.body_agrees(ns, self.joint_states(ns))
        before, mark = self.settled_arm(ns), self.rosout.mark()
        group.publish(Float64MultiArray(data=[0.1, 0.1]))
        self.rosout.wait_line(mark, "position_group", "2")
        self.assert_still(ns, before, "a 2-value command to a 3-joint group")
        # a second controller on joint_1 while the group runs: refused, nothing changes
        self.assertTrue(manager.load("joint_1_position", self.group_params["joint_1_position"]))
        mark = self.rosout.mark()
        self.assertFalse(manager.switch(start=["joint_1_position"]), "a resource conflict was accepted")
        self.rosout.wait_line(mark, "onflict", "joint_1")
        self.assertEqual(manager.running() & {"position_group", "joint_1_position"}, {"position_group"})
        # the single one in its place moves joint_1 alone
        self.assertTrue(manager.switch(start=["joint_1_position"], stop=["position_group"]))
        single = self.publisher(f"/{ns}/joint_1_position/command", Float64)
        single.publish(Float64(-0.4))
        self.wait_arm(ns, [-0.4, 0.4, 0.3])
        self.assertTrue(manager.switch(start=["position_group"], stop=["joint_1_position"]))

    def test_g_velocity_group_and_single(self):
        ns, manager = "vel", self.managers["vel"]
        group = self.publisher(f"/{ns}/velocity_group/command", Float64MultiArray)
        link = "vel::link_1"
        group.publish(Float64MultiArray(data=[0.5, 0.0, 0.0]))
        wait_for(lambda: abs(self.truth.link_state(link, "").link_state.twist.angular.z - 0.5) < 0.02, 30,
                 "joint_1 turning at 0.5 rad/s")
        before, mark = self.arm(ns), self.rosout.mark()
        group.publish(Float64MultiArray(data=[0.0]))  # wrong size: ignored, joint_1 turns on
        self.rosout.wait_line(mark, "velocity_group", "1")
        sim_sleep(0.3)
        self.assertAlmostEqual(self.truth.link_state(link, "").link_state.twist.angular.z, 0.5, delta=0.02,
                               msg="a 1-value command changed the 3-joint group's velocities")
        group.publish(Float64MultiArray(data=[0.0, 0.0, 0.0]))
        wait_for(lambda: abs(self.truth.link_state(link, "").link_state.twist.angular.z) < 0.01, 30, "joint_1 stopped")
        self.assertGreater(self.arm(ns)[0], before[0], "joint_1 did not turn on")
        self.assertTrue(manager.load("joint_1_velocity", self.group_params["joint_1_velocity"]))
        self.assertTrue(manager.switch(start=["joint_1_velocity"], stop=["velocity_group"]))
        single = self.publisher(f"/{ns}/joint_1_velocity/command", Float64)
        single.publish(Float64(-0.3))
        wait_for(lambda: abs(self.truth.link_state(link, "").link_state.twist.angular.z + 0.3) < 0.02, 30,
                 "joint_1 turning at -0.3 rad/s")
        single.publish(Float64(0.0))
        self.assertTrue(manager.switch(start=["velocity_group"], stop=["joint_1_velocity"]))

    def test_h_effort_trajectory_controller_without_gains_is_refused_and_nothing_moves(self):
        ns, manager = "eff", self.managers["eff"]
        before = self.settled_arm(ns)
        params = {"type": "effort_controllers/JointTrajectoryController", "joints": JOINTS}
        self.assertTrue(manager.load("arm_nogains", params), "upstream loads it (and logs the missing gains)")
        mark = self.rosout.mark()
        try:
            self.assertFalse(manager.switch(start=["arm_nogains"], stop=["effort_position_group"]),
                             "starting an effort trajectory controller without gains was accepted")
            line = self.rosout.wait_line(mark, "arm_nogains", "gains")
            self.assertNotIn("arm_nogains", manager.running())
            self.assertIn("effort_position_group", manager.running(),
                          f"the refused switch left the holding controller stopped ({line})")
            self.assert_still(ns, before, "the refused switch", seconds=1.0)
        finally:
            if "effort_position_group" not in manager.running():  # for the tests after this one
                manager.switch(start=["effort_position_group"], stop=list(manager.running() & {"arm_nogains"}))

    def test_i_effort_group_and_single(self):
        ns, manager = "eff", self.managers["eff"]
        group = self.publisher(f"/{ns}/effort_position_group/command", Float64MultiArray)
        target = [0.3, 0.5, 0.4]
        group.publish(Float64MultiArray(data=target))
        self.wait_arm(ns, target)
        self.settled_arm(ns)
        self.body_agrees(ns, self.joint_states(ns))
        before, mark = self.settled_arm(ns), self.rosout.mark()
        group.publish(Float64MultiArray(data=[0.0, 0.0, 0.0, 0.0]))
        self.rosout.wait_line(mark, "effort_position_group", "4")
        self.assert_still(ns, before, "a 4-value command to a 3-joint group")
        # raw effort on the turntable (no gravity about z): it turns the way it is pushed, once in its place
        self.assertTrue(manager.load("joint_1_effort", self.group_params["joint_1_effort"]))
        self.assertTrue(manager.load("joint_2_effort_position", self.group_params["joint_2_effort_position"]))
        pos_group = dict(self.group_params["effort_position_group"], joints=["joint_3"])
        self.assertTrue(manager.load("joint_3_group", pos_group))
        self.assertTrue(manager.switch(start=["joint_1_effort", "joint_2_effort_position", "joint_3_group"],
                                       stop=["effort_position_group"]))
        self.publisher(f"/{ns}/joint_3_group/command", Float64MultiArray).publish(Float64MultiArray(data=[0.4]))
        self.publisher(f"/{ns}/joint_2_effort_position/command", Float64).publish(Float64(0.2))
        self.publisher(f"/{ns}/joint_1_effort/command", Float64).publish(Float64(0.3))
        wait_for(lambda: self.arm(ns)[0] > before[0] + 0.3, 30, "joint_1 pushed round")
        self.publisher(f"/{ns}/joint_1_effort/command", Float64).publish(Float64(0.0))  # it coasts on
        wait_for(lambda: all(abs(a - b) < 0.03 for a, b in zip(self.arm(ns)[1:], [0.2, 0.4])), 30,
                 f"/{ns} joint_2, joint_3 at 0.2, 0.4 (at {self.arm(ns)})")

    # -- bad trajectories on a trajectory controller's command topic -------------------------------------------
    def test_j_bad_trajectories_on_the_command_topic_are_ignored(self):
        ns, manager = "pos", self.managers["pos"]
        params = rospy.get_param(f"/{ns}/arm_controller")
        self.assertTrue(manager.load("arm_controller", params))
        self.assertTrue(manager.switch(start=["arm_controller"], stop=["position_group"]))
        command = self.publisher(f"/{ns}/arm_controller/command", JointTrajectory)
        command.publish(trajectory(JOINTS, (1.0, [0.2, 0.3, 0.4])))
        self.wait_arm(ns, [0.2, 0.3, 0.4])
        cases = [
            ("NaN", trajectory(JOINTS, (1.0, [0.1, float("nan"), 0.0]))),
            ("Inf", trajectory(JOINTS, (1.0, [0.1, 0.0, float("inf")]))),
            ("unknown joint", trajectory(JOINTS[:2] + ["no_such_joint"], (1.0, [0.1, 0.1, 0.1]))),
            ("duplicate joint", trajectory(JOINTS[:2] + [JOINTS[0]], (1.0, [0.1, 0.1, 0.1]))),
            ("times not increasing", trajectory(JOINTS, (1.0, [0.1] * 3), (1.0, [0.0] * 3))),
            ("outside the limits", trajectory(JOINTS, (1.0, [0.1, 9.0, 0.0]))),
            ("empty", JointTrajectory(joint_names=JOINTS)),
        ]
        for what, msg in cases:
            before = self.settled_arm(ns)
            command.publish(msg)
            self.assert_still(ns, before, f"a command with {what}", seconds=1.5)
        command.publish(trajectory(JOINTS, (1.0, [0.0, 0.0, 0.0])))
        self.wait_arm(ns, [0.0, 0.0, 0.0])


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "arm_commands", ArmCommands, sys.argv)
