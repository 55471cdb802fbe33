#!/usr/bin/env python3
"""pick_place suite: ``rosrun diffbot_sim pick_place`` run as a user runs it, against launch/manipulator.launch
in fast mode, judged by the box's ground truth (/gazebo/link_states: the box, the base and the wrist in one
message, one physics step):

- the node exits 0 (every step succeeded);
- while the base drives with the box (after the pick), the box is more than 3 cm above the table tops;
- the box moves with the gripper: its distance to gripper_tcp_link (the wrist's ground truth + the URDF's fixed
  wrist -> tcp offset; Gazebo lumps that frame) stays constant within 1 cm while carried;
- the box ends on place_table within 2 cm of the place point, resting (its centre at the rest height) and
  upright.
"""
import math
import os
import subprocess
import sys
import threading
import unittest

import rospy
import rostest
from controller_manager_msgs.srv import ListControllers
from gazebo_msgs.msg import LinkStates
from gazebo_msgs.srv import GetLinkState

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from simtest import wait_for
from traittest import settled, sim_now

from diffbot_sim.check.arm_check import forward_kinematics
from diffbot_sim.control.pick_place import Scene
from diffbot_sim.description.urdf_model import parse_urdf
from diffbot_sim.transforms import compose, inverse, roll_pitch_from_quaternion

MODEL = "diffbot_arm"
BOX = "pick_box::link"
TABLE_TOP = 0.12  # m, both tables (worlds/pick_place.world)
NODE_TIMEOUT = 90.0  # s wall
DRIVING = 0.02  # m/s: the base counts as driving above this (or turning above 0.1 rad/s)


class Sample:
    __slots__ = ("t", "box", "box_q", "base", "base_yaw_rate", "base_speed", "tcp")

    def __init__(self, t, box, box_q, base, base_speed, base_yaw_rate, tcp):
        self.t, self.box, self.box_q, self.base = t, box, box_q, base
        self.base_speed, self.base_yaw_rate, self.tcp = base_speed, base_yaw_rate, tcp


class PickPlace(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_pick_place")
        rospy.wait_for_service("/controller_manager/list_controllers", 60)
        listing = rospy.ServiceProxy("/controller_manager/list_controllers", ListControllers)
        wait_for(lambda: {c.name for c in listing().controller if c.state == "running"} >=
                 {"arm_controller", "gripper_controller", "joint_state_controller"}, 60,
                 "the spawner to start the controllers")
        model = parse_urdf(rospy.get_param("/robot_description"))
        fk = forward_kinematics(model, {})
        cls.wrist_to_tcp = compose(inverse(fk["wrist_link"]), fk["gripper_tcp_link"])
        cls.root = model.root
        cls.lock = threading.Lock()
        cls.samples = []
        cls.sub = rospy.Subscriber("/gazebo/link_states", LinkStates, cls._keep, queue_size=5)
        wait_for(lambda: cls.samples, 30, "/gazebo/link_states")
        cls.start = cls.samples[-1]
        log = os.path.join(os.environ.get("ROS_LOG_DIR", "/tmp"), "pick_place_node.log")
        with open(log, "w") as out:
            # as a user runs it: rosrun, the environment of this shell (ROS_MASTER_URI of the test's master)
            cls.process = subprocess.run(["rosrun", "diffbot_sim", "pick_place"], stdout=out, stderr=subprocess.STDOUT,
                                         timeout=NODE_TIMEOUT)
        with open(log) as text:
            cls.node_output = text.read()
        cls.sub.unregister()
        with cls.lock:
            cls.samples = list(cls.samples)
        # Where the box ended: its ground truth once at rest after the node's exit (within 0.5 mm over 0.3 s of sim
        # time), not the last link_states message this node had taken in, which on a busy machine can be from
        # before the box was let go.
        rospy.wait_for_service("/gazebo/get_link_state", 30)
        link_state = rospy.ServiceProxy("/gazebo/get_link_state", GetLinkState)

        def box_pose():
            resp = link_state(BOX, "")
            if not resp.success:
                raise AssertionError(f"get_link_state {BOX}: {resp.status_message}")
            p, q = resp.link_state.pose.position, resp.link_state.pose.orientation
            return [p.x, p.y, p.z, q.x, q.y, q.z, q.w]
        rest = settled(box_pose, 0.0005, what="the placed box")
        cls.end = Sample(sim_now(), tuple(rest[:3]), tuple(rest[3:]), None, None, None, None)

    @classmethod
    def _keep(cls, msg):
        index = {name: i for i, name in enumerate(msg.name)}
        try:
            box, base, wrist = index[BOX], index[f"{MODEL}::{cls.root}"], index[f"{MODEL}::wrist_link"]
        except KeyError:
            return

        def pose(i):
            p, q = msg.pose[i].position, msg.pose[i].orientation
            return (p.x, p.y, p.z), (q.x, q.y, q.z, q.w)
        twist = msg.twist[base]
        tcp = compose(pose(wrist), cls.wrist_to_tcp)[0]
        sample = Sample(rospy.get_time(), pose(box)[0], pose(box)[1], pose(base)[0],
                        math.hypot(twist.linear.x, twist.linear.y), abs(twist.angular.z), tcp)
        with cls.lock:
            cls.samples.append(sample)

    def carried(self):
        """Samples while the base drives with the box: once the base has stood at the pick table (within 1 cm of
        its grasping pose) and driven 2 cm away from it, until it stands at the place table (within 2 cm of its
        placing pose: then the box is lowered and let go, and the base may still creep while the arm moves),
        every sample with the base moving."""
        scene = Scene()
        pick_base = (scene.pick[0] - scene.standoff, scene.pick[1])
        arrived = next((i for i, s in enumerate(self.samples) if math.dist(s.base[:2], pick_base) < 0.01), None)
        self.assertIsNotNone(arrived, f"the base never reached the pick table {pick_base} ({len(self.samples)} "
                             f"samples from {self.samples[0].t:.2f} to {self.samples[-1].t:.2f} s, the base last at "
                             f"{self.samples[-1].base})")
        leaving = next((i for i in range(arrived, len(self.samples))
                        if math.dist(self.samples[i].base[:2], pick_base) > 0.02), None)
        self.assertIsNotNone(leaving, "the base never drove away from the pick table")
        place_base = (scene.place[0] + scene.standoff, scene.place[1])
        there = next((i for i in range(leaving, len(self.samples))
                      if math.dist(self.samples[i].base[:2], place_base) < 0.02), len(self.samples))
        return [s for s in self.samples[leaving:there] if s.base_speed > DRIVING or s.base_yaw_rate > 0.1]

    def test_1_node_succeeds(self):
        self.assertEqual(self.process.returncode, 0, f"pick_place exited {self.process.returncode}:\n"
                         + "\n".join(self.node_output.splitlines()[-15:]))
        self.assertIn("done: ", self.node_output)

    def test_2_box_lifted_while_the_base_drives(self):
        carried = self.carried()
        self.assertGreater(len(carried), 50, "too few samples of the base driving with the box")
        lowest = min(carried, key=lambda s: s.box[2])
        clearance = lowest.box[2] - Scene().object_size / 2.0 - TABLE_TOP
        self.assertGreater(clearance, 0.03, f"the box was {clearance * 100:.1f} cm above the table height at "
                           f"({lowest.box[0]:.2f}, {lowest.box[1]:.2f}) while the base drove (base at "
                           f"({lowest.base[0]:.2f}, {lowest.base[1]:.2f}))")
        print(f"pick_place: lowest box while driving with it: {clearance * 100:.1f} cm above the tables, "
              f"{len(carried)} samples", flush=True)
        travelled = math.dist(carried[0].box[:2], carried[-1].box[:2])
        self.assertGreater(travelled, 0.8, f"the box went only {travelled:.2f} m while the base drove")

    def test_3_box_moves_with_the_gripper(self):
        carried = self.carried()
        distances = [math.dist(s.box, s.tcp) for s in carried]
        print(f"pick_place: box to gripper_tcp_link while carried: {min(distances):.4f}..{max(distances):.4f} m",
              flush=True)
        self.assertLess(max(distances) - min(distances), 0.01,
                        f"the box's distance to gripper_tcp_link varied {min(distances):.4f}..{max(distances):.4f} m "
                        "while carried (it slipped or was left behind)")
        self.assertLess(max(distances), 0.03, f"the box is {max(distances):.3f} m from the gripper's centre")

    def test_4_box_ends_on_the_place_table(self):
        scene = Scene()
        end = self.end
        off = math.dist(end.box[:2], scene.place[:2])
        print(f"pick_place: the box ended {off * 100:.2f} cm from the place point, centre at z {end.box[2]:.4f}",
              flush=True)
        place_base = (scene.place[0] + scene.standoff, scene.place[1])
        arrived = [s for s in self.samples if math.dist(s.base[:2], place_base) < 0.01]
        if arrived:  # where the box was while the base stood at the place table, and where it ended
            first, last = arrived[0], arrived[-1]
            print(f"pick_place: base at the place table from ({first.base[0]:.4f}, {first.base[1]:.4f}) to "
                  f"({last.base[0]:.4f}, {last.base[1]:.4f}); the box from ({first.box[0]:.4f}, {first.box[1]:.4f}, "
                  f"{first.box[2]:.4f}) to ({last.box[0]:.4f}, {last.box[1]:.4f}, {last.box[2]:.4f})", flush=True)
        self.assertLess(off, 0.02, f"the box ended at ({end.box[0]:.3f}, {end.box[1]:.3f}), {off * 100:.1f} cm from "
                        f"the place point {scene.place[:2]}")
        self.assertAlmostEqual(end.box[2], scene.place[2], delta=0.005,
                               msg=f"the box's centre is at z {end.box[2]:.4f}, not resting on place_table")
        roll, pitch = roll_pitch_from_quaternion(*end.box_q)
        self.assertLess(max(abs(roll), abs(pitch)), 0.05, f"the box is tilted (roll {roll:.3f}, pitch {pitch:.3f})")
        moved = math.dist(self.start.box[:2], end.box[:2])
        self.assertGreater(moved, 1.0, f"the box moved only {moved:.2f} m")


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "pick_place", PickPlace, sys.argv)
