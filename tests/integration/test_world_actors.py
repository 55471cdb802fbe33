#!/usr/bin/env python3
"""world_actors suite: an <actor> walks its script (its pose in model_states where the script puts it at that
sim time) and the laser sees it there (Gazebo's CPU lasers do not); a model moved by /gazebo/set_model_state at
30 Hz, as learning stages move obstacles, is seen at the pose set."""
import math
import sys
import threading
import unittest

import rospy
import rostest
from gazebo_msgs.msg import ModelState, ModelStates
from gazebo_msgs.srv import GetModelState
from geometry_msgs.msg import Pose
from sensor_msgs.msg import LaserScan
from simtest import wait_for

LASER_OFFSET = 0.05  # m: laser_robot.urdf's laser_link, ahead of the robot's origin (0.113 m up)
NEAR_FACE = 1.75  # m: the walker's near face (x = 2.0 - half its 0.5 m width)
CUBE_HALF = 0.15  # m: half the mover cube's side
FIRST_FRAME = 1.0 / 30.0 + 0.02  # s: Gazebo's first actor frame (1/30 s), and the pairing's 0.02 s


class Scans:
    def __init__(self):
        self.lock = threading.Lock()
        self.scans = []
        self.sub = rospy.Subscriber("/scan", LaserScan, self._keep, queue_size=20)

    def _keep(self, msg):
        with self.lock:
            self.scans.append(msg)

    def after(self, t):
        with self.lock:
            return [s for s in self.scans if s.header.stamp.to_sec() >= t]


def range_at(scan, bearing):
    k = int(round((bearing - scan.angle_min) / scan.angle_increment)) % len(scan.ranges)
    return scan.ranges[k]


class WorldActors(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_world_actors")
        rospy.wait_for_service("/gazebo/get_model_state", 30)
        cls.get_state = rospy.ServiceProxy("/gazebo/get_model_state", GetModelState)
        cls.scans = Scans()
        cls.states = []
        cls.lock = threading.Lock()
        rospy.Subscriber("/gazebo/model_states", ModelStates, cls._keep_states, queue_size=50)

    @classmethod
    def _keep_states(cls, msg):
        now = rospy.get_time()
        if now > 0.0:  # received before this node's first /clock: no time to pair it with
            with cls.lock:
                cls.states.append((now, msg))

    def laser_x(self):
        """The laser's x [m] from the robot's ground truth (it stands at the origin facing +x)."""
        robot = self.get_state("laser_robot", "")
        self.assertTrue(robot.success, robot.status_message)
        self.assertLess(abs(robot.pose.position.x), 0.01, "the robot is not where it was spawned")
        return robot.pose.position.x + LASER_OFFSET

    def test_1_the_walker_is_a_model_and_the_laser_sees_it(self):
        state = self.get_state("walker", "")
        self.assertTrue(state.success, state.status_message)
        laser_x = self.laser_x()
        seen = 0
        # A scan is paired with the walker's pose in the model_states this node received within 0.02 s of the
        # scan's stamp, by this node's clock: model_states have no stamp. A message received before this
        # node's first /clock (its clock still reads 0) cannot be dated and is dropped (_keep_states): once it
        # paired the first step's scan (t = 0.004 s) with a pose from a later sim time.
        start = rospy.get_time()
        wait_for(lambda: rospy.get_time() > start + 6.0, 60, "6 s of sim time")
        for scan in self.scans.after(start):
            t = scan.header.stamp.to_sec()
            with self.lock:
                near = [m for (s, m) in self.states if abs(s - t) < 0.02 and "walker" in m.name]
            if not near:
                continue
            pose = near[-1].pose[near[-1].name.index("walker")].position
            if t < FIRST_FRAME:
                # Gazebo's Actor::Update draws its first frame 1/30 s into the run: the walker stands at its
                # <pose> (the origin, around the laser, which then sees nothing of it) until then
                continue
            self.assertAlmostEqual(pose.x, 2.0, delta=0.01, msg=f"at t={t:.3f} the walker is not on its path")
            if abs(pose.y) > 1.0:
                continue
            bearing = math.atan2(pose.y, NEAR_FACE - laser_x)
            want = (NEAR_FACE - laser_x) / math.cos(bearing)
            got = range_at(scan, bearing)
            self.assertAlmostEqual(got, want, delta=0.05, msg=f"at t={t:.2f} the walker (y={pose.y:.2f}) is seen at "
                                   f"{got:.3f} m, its near face is at {want:.3f} m")
            seen += 1
        self.assertGreater(seen, 5, "too few scans with the walker in front of the laser")

    def test_2_a_model_moved_by_set_model_state_is_seen_where_it_was_set(self):
        laser_x = self.laser_x()
        pub = rospy.Publisher("/gazebo/set_model_state", ModelState, queue_size=10)
        wait_for(lambda: pub.get_num_connections() > 0, 10, "set_model_state subscribed")
        rate = rospy.Rate(30)
        checked = 0
        for k in range(90):  # 3 s of sim time, the cube circling 1.2 m ahead of the robot
            angle = -0.6 + 1.2 * k / 90
            msg = ModelState(model_name="mover", pose=Pose(), reference_frame="world")
            msg.pose.position.x, msg.pose.position.y, msg.pose.position.z = 1.2 * math.cos(angle), \
                1.2 * math.sin(angle), 0.15
            msg.pose.orientation.w = 1.0
            pub.publish(msg)
            rate.sleep()
            if k % 15 == 14:  # a scan after the last set: the beam at the cube's centre hits its near face
                t = rospy.get_time()
                scan = wait_for(lambda: self.scans.after(t), 10, "a scan after the set")[0]
                x, y = msg.pose.position.x, msg.pose.position.y
                bearing = math.atan2(y, x - laser_x)
                want = (x - CUBE_HALF - laser_x) / math.cos(bearing)
                got = range_at(scan, bearing)
                self.assertAlmostEqual(got, want, delta=0.06, msg=f"the cube set at angle {angle:.2f} is "
                                       f"seen at {got:.3f} m, its near face at {want:.3f} m")
                checked += 1
        self.assertGreaterEqual(checked, 5)


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "world_actors", WorldActors, sys.argv)
