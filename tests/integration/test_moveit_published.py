#!/usr/bin/env python3
"""moveit_published suite (`make test-moveit`): a published mobile manipulator's own Gazebo launch and its own
MoveIt config (tests/data/manipulator_way: mobile_manipulator_gazebo, mobile_manipulator_moveit_config), both
unchanged, driven as a MoveIt user drives them: move_group finds the Gazebo launch's controllers
(FollowJointTrajectory), joint_states and TF arrive in sim time; moveit_commander plans and executes a joint
goal, then a position goal for the end effector, reached within 1.5 cm by ground truth; compute_ik (KDL,
position only) and compute_fk answer; and moveit_commander works under Debian's /usr/bin/python3 as under the
project's venv, its Eigen results (get_jacobian_matrix) converted to numpy by eigenpy."""
import json
import math
import os
import subprocess
import sys
import time
import unittest

import rospy
import rostest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from moveittest import Body, fk, settled_pose, tf_pose, wait_for_move_group
from simtest import figure

ARM = ["joint1", "joint2", "joint3", "joint4"]
TOOL = "end_effector_link"
MODEL = "robot"  # spawn_model -model robot
FRAME = "odom"
WITHIN = 0.015  # m: the bar for a published arm's position goal

#: What a user's script does with moveit_commander, run under another interpreter: the current joints, a plan to a
#: named pose of the SRDF, and the Jacobian (Eigen::MatrixXd, returned through eigenpy as a numpy array).
SCRIPT = r"""
import json, sys
import moveit_commander, rospy
moveit_commander.roscpp_initialize(sys.argv[:1])
rospy.init_node("moveit_commander_check", anonymous=True)
group = moveit_commander.MoveGroupCommander("arm", wait_for_servers=30.0)
joints = group.get_current_joint_values()
group.set_named_target("home")
ok, plan, seconds, error = group.plan()
jacobian = group.get_jacobian_matrix(joints)
import numpy
print("RESULT " + json.dumps({"python": sys.executable, "joints": joints, "planned": bool(ok),
      "points": len(plan.joint_trajectory.points), "jacobian_type": type(jacobian).__name__,
      "jacobian_shape": list(numpy.shape(jacobian)), "jacobian": numpy.asarray(jacobian).tolist()}))
"""


class MoveItPublished(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        import moveit_commander
        import tf2_ros

        rospy.init_node("test_moveit_published")
        moveit_commander.roscpp_initialize(sys.argv[:1])
        wait_for_move_group()
        cls.group = moveit_commander.MoveGroupCommander("arm", wait_for_servers=60.0)
        cls.group.set_planning_time(5.0)
        cls.body = Body(MODEL)
        cls.tf = tf2_ros.Buffer()
        cls.tf_listener = tf2_ros.TransformListener(cls.tf)

    def go(self, what):
        ok, plan, seconds, error = self.group.plan()
        self.assertTrue(ok, f"{what}: no plan (error code {error.val})")
        sim0 = rospy.get_time()
        self.assertTrue(self.group.execute(plan, wait=True), f"{what}: execution failed")
        figure(f"{what}: planned in {seconds:.3f} s, {plan.joint_trajectory.points[-1].time_from_start.to_sec():.2f} s "
               f"trajectory executed in {rospy.get_time() - sim0:.2f} s of sim time")
        return plan

    def test_1_joint_goal(self):
        self.group.set_named_target("home")
        plan = self.go("joint goal (home)")
        planned = fk(TOOL, plan.joint_trajectory.joint_names, plan.joint_trajectory.points[-1].positions, FRAME)
        truth = settled_pose(self.body, TOOL)
        off = math.dist(truth[0], planned[0])
        tf_off = math.dist(tf_pose(self.tf, FRAME, TOOL)[0], truth[0])
        figure(f"joint goal: end effector {off * 1000:.1f} mm from the planned pose by ground truth, "
               f"TF {tf_off * 1000:.1f} mm")
        self.assertLess(off, WITHIN)
        self.assertLess(tf_off, 0.005)

    def test_2_position_goal(self):
        target = fk(TOOL, ARM, [0.4, 0.3, 0.2, -0.3], FRAME)[0]
        self.group.set_position_target(list(target), TOOL)
        self.go("position goal")
        self.group.clear_pose_targets()
        truth = settled_pose(self.body, TOOL)[0]
        off = math.dist(truth, target)
        figure(f"position goal: end effector {off * 1000:.1f} mm from the target by ground truth")
        self.assertLess(off, WITHIN, f"the end effector is {off * 1000:.1f} mm from the position goal")

    def test_3_compute_ik_and_fk(self):
        from geometry_msgs.msg import PoseStamped
        from moveit_msgs.msg import PositionIKRequest
        from moveit_msgs.srv import GetPositionIK

        joints = [-0.5, 0.2, 0.3, 0.1]
        position, orientation = fk(TOOL, ARM, joints, FRAME)
        pose = PoseStamped()
        pose.header.frame_id = FRAME
        (pose.pose.position.x, pose.pose.position.y, pose.pose.position.z) = position
        pose.pose.orientation.w = 1.0  # position only (kinematics.yaml: position_only_ik)
        request = PositionIKRequest(group_name="arm", ik_link_name=TOOL, pose_stamped=pose)
        request.timeout = rospy.Duration(1.0)
        answer = rospy.ServiceProxy("/compute_ik", GetPositionIK)(ik_request=request)
        self.assertEqual(answer.error_code.val, 1, f"compute_ik: error code {answer.error_code.val}")
        names = list(answer.solution.joint_state.name)
        solved = [answer.solution.joint_state.position[names.index(j)] for j in ARM]
        self.assertLess(math.dist(fk(TOOL, ARM, solved, FRAME)[0], position), 0.002, f"IK solution {solved}")

    def test_4_moveit_commander_under_each_python(self):
        for python in ("/usr/bin/python3", sys.executable):
            started = time.monotonic()
            proc = subprocess.run([python, "-c", SCRIPT], capture_output=True, text=True, timeout=120)
            lines = [line for line in proc.stdout.splitlines() if line.startswith("RESULT ")]
            self.assertEqual(proc.returncode, 0, f"{python}: exit {proc.returncode}: {proc.stderr[-1500:]}")
            self.assertTrue(lines, f"{python}: no result: {proc.stdout[-500:]} {proc.stderr[-1500:]}")
            result = json.loads(lines[-1][len("RESULT "):])
            self.assertTrue(result["planned"], f"{python}: no plan to 'home'")
            self.assertEqual(result["jacobian_type"], "ndarray", f"{python}: {result}")
            self.assertEqual(result["jacobian_shape"], [6, 4], f"{python}: {result}")
            self.assertTrue(any(abs(v) > 1e-3 for row in result["jacobian"] for v in row), f"{python}: a zero Jacobian")
            figure(f"moveit_commander under {python}: planned, Jacobian {result['jacobian_shape']} ndarray "
                   f"({time.monotonic() - started:.1f} s)")


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "moveit_published", MoveItPublished, sys.argv)
