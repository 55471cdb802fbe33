#!/usr/bin/env python3
"""A user's launch file written for Gazebo (tests/data/gazebo_way/*.launch) runs unchanged: the world loads,
each robot spawns at its pose, its controllers start through controller_manager's spawner, its
mobile_base_controller/cmd_vel drives it (and no other robot), its laser sees the wall.

Parameters: ~robots: [{model: NAME, ns: NAMESPACE ("" for the root), x: X, y: Y}] as the launch file spawns
them, all facing +y; the wall's near face is the plane y = 5 (wall.world).
"""
import math
import sys
import unittest

import rospy
import rostest
from controller_manager_msgs.srv import ListControllers
from gazebo_msgs.srv import GetModelState, GetWorldProperties
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState, LaserScan
from simtest import Latest, assert_upright, wait_for as wait, yaw_of

WALL_Y = 5.0
DRIVE = 0.8  # m each robot drives forward (0.4 m/s for 2 s), judged on its body (/gazebo/get_model_state)
DRIVE_TIMEOUT = 60.0  # s wall: a drive of 2 s of sim time, on a 4x slower machine


class GazeboWayTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_gazebo_way")
        cls.robots = rospy.get_param("~robots")
        rospy.wait_for_service("/gazebo/get_model_state", 60.0)
        cls.get_state = rospy.ServiceProxy("/gazebo/get_model_state", GetModelState)

    def state(self, model):
        resp = self.get_state(model, "world")
        self.assertTrue(resp.success, resp.status_message)
        return resp

    def test_1_spawned_at_the_pose_with_controllers_running(self):
        world = rospy.ServiceProxy("/gazebo/get_world_properties", GetWorldProperties)
        names = wait(lambda: (n := world().model_names) and all(r["model"] in n for r in self.robots) and n,
                     60.0, "every robot spawned")
        self.assertIn("wall", names)
        for robot in self.robots:
            s = self.state(robot["model"])
            self.assertAlmostEqual(s.pose.position.x, robot["x"], delta=0.05)
            self.assertAlmostEqual(s.pose.position.y, robot["y"], delta=0.05)
            self.assertAlmostEqual(yaw_of(s.pose.orientation), 1.57, delta=0.03)
            ns = robot["ns"]
            service = f"{ns}/controller_manager/list_controllers"
            rospy.wait_for_service(service, 30.0)
            listing = rospy.ServiceProxy(service, ListControllers)

            def running():
                states = {c.name: c.state for c in listing().controller}
                return states.get("mobile_base_controller") == "running" and \
                    states.get("joint_state_controller") == "running" and states
            states = wait(running, 60.0, f"{ns} controllers running (spawner)")
            self.assertEqual(len(states), 2)
            claimed = {c.name: [(r.hardware_interface, list(r.resources)) for r in c.claimed_resources]
                       for c in listing().controller}
            self.assertEqual(claimed["joint_state_controller"], [("hardware_interface::JointStateInterface", [])])
            self.assertEqual(claimed["mobile_base_controller"][0][0], "hardware_interface::VelocityJointInterface")
            joints = Latest(f"{ns}/joint_states", JointState)
            msg = wait(joints.get, 10.0, f"{ns}/joint_states")
            self.assertIn("front_left_wheel_joint", msg.name)

    def test_2_laser_sees_the_wall(self):
        for robot in self.robots:
            scan = Latest(f"{robot['ns']}/scan", LaserScan)
            msg = wait(scan.get, 20.0, f"{robot['ns']}/scan")
            middle = msg.ranges[len(msg.ranges) // 2]
            s = self.state(robot["model"])
            expected = WALL_Y - s.pose.position.y
            # the middle ray of an even sample count is half an increment off the heading
            self.assertAlmostEqual(middle, expected / math.cos(msg.angle_increment / 2), delta=0.05)

    def test_3_cmd_vel_drives_only_its_robot(self):
        for robot in self.robots:
            ns = robot["ns"]
            odom = Latest(f"{ns}/mobile_base_controller/odom", Odometry)
            wait(odom.get, 20.0, f"{ns}/mobile_base_controller/odom")
            others = {r["model"]: self.state(r["model"]).pose.position for r in self.robots if r is not robot}
            start = self.state(robot["model"]).pose.position
            pub = rospy.Publisher(f"{ns}/mobile_base_controller/cmd_vel", Twist, queue_size=1)
            wait(lambda: pub.get_num_connections() > 0, 10.0, f"{ns}/mobile_base_controller/cmd_vel subscriber")
            cmd = Twist()
            cmd.linear.x = 0.4

            def driven():
                """Commanded until the body has moved DRIVE, not for a time: on a loaded machine the commands
                reach the simulator late (and its cmd_vel_timeout of 0.25 s brakes between late ones)."""
                pub.publish(cmd)  # the YAML's cmd_vel_timeout is 0.25 s: keep commanding
                p = self.state(robot["model"]).pose.position
                return math.hypot(p.x - start.x, p.y - start.y) >= DRIVE
            wait(driven, DRIVE_TIMEOUT, f"{robot['model']} to drive {DRIVE} m on {ns}/mobile_base_controller/cmd_vel",
                 poll=0.05)
            # stopped: the zero command arrives (its cmd_vel_timeout brakes it anyway) before the next robot
            def stopped():
                pub.publish(Twist())
                v = self.state(robot["model"]).twist.linear
                return math.hypot(v.x, v.y) < 0.01
            wait(stopped, 10.0, f"{robot['model']} at rest after the drive")
            end_pose = self.state(robot["model"]).pose
            assert_upright(end_pose, 0.0, f"{robot['model']} after the drive")
            end = end_pose.position
            self.assertGreater(end.y - start.y, 0.4, f"{robot['model']} drove forward (+y)")
            self.assertLess(end.y, WALL_Y - 0.2)
            self.assertGreater(odom.get().pose.pose.position.x, 0.3, "controller odometry counts forward")
            for name, position in others.items():
                now = self.state(name).pose.position
                self.assertLess(math.hypot(now.x - position.x, now.y - position.y), 0.02, f"{name} stayed")
            pub.unregister()


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_gazebo_way", GazeboWayTest, sys.argv)
