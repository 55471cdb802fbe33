#!/usr/bin/env python3
"""A car-like robot's own Gazebo launch file (tests/data/car_way) runs unchanged and the robot drives straight and
in an arc, judged by ground truth: its world API where its launch file puts Gazebo (``~gazebo``), its controllers
started by its spawner, ``/clock`` global; straight ahead without turning; at steering angle δ the rear axle's
middle runs on the circle the steering geometry gives (radius L / tan δ) without sliding sideways.

Parameters: ~gazebo (the world API's namespace), ~model, ~ns (the controller manager's namespace), ~wheelbase
(m), ~rear_axle ([x, y] of the rear axle's middle in the body frame), ~rest_height (m, base_link above ground),
~track (m, a SteerBotHardwareGazebo base's steering axes apart), ~arc_speed (m/s) and ~arc_seconds (s).
"""
import math
import sys
import time
import unittest

import rospy
import rostest
from controller_manager_msgs.srv import ListControllers
from gazebo_msgs.srv import GetModelState, GetWorldProperties
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from simtest import Latest, figure, wait_for, yaw_of

from diffbot_sim.check import arc_check

COMMAND_RATE = 20.0  # Hz wall; the controller's cmd_vel_timeout is 0.5 s
STRAIGHT_SPEED, STRAIGHT_SECONDS = 0.3, 3.0


class CarLikeTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_car_like")
        cls.gazebo = rospy.get_param("~gazebo").rstrip("/")
        cls.model = rospy.get_param("~model")
        cls.ns = rospy.get_param("~ns").rstrip("/")
        cls.wheelbase = rospy.get_param("~wheelbase")
        cls.rear_axle = tuple(rospy.get_param("~rear_axle"))
        cls.rest_height = rospy.get_param("~rest_height")
        # a SteerBotHardwareGazebo base: its YAML, whose linkage sets the real front wheels' angles
        cls.steer_bot = rospy.get_param(cls.ns + "/steer_bot_hardware_gazebo", None)
        cls.track = rospy.get_param("~track", 0.0)
        # m/s, s: "no lateral slip at low speed": a car whose wheels all turn at one speed (SteerBotHardwareGazebo)
        # scrubs in a turn with a force that grows with speed (Gazebo's SetVelocity couples each wheel by its inertia)
        cls.arc_speed = rospy.get_param("~arc_speed", arc_check.ARC_SPEED)
        cls.arc_seconds = rospy.get_param("~arc_seconds", arc_check.ARC_SECONDS)
        rospy.wait_for_service(cls.gazebo + "/get_model_state", 60.0)
        cls.state = rospy.ServiceProxy(cls.gazebo + "/get_model_state", GetModelState)
        cls.cmd = rospy.Publisher(cls.ns + "/ackermann_steering_controller/cmd_vel", Twist, queue_size=1)
        cls.odom = Latest(cls.ns + "/ackermann_steering_controller/odom", Odometry)

    def body(self):
        resp = self.state(self.model, "world")
        self.assertTrue(resp.success, resp.status_message)
        p, q = resp.pose.position, resp.pose.orientation
        v, w = resp.twist.linear, resp.twist.angular
        return (p.x, p.y, p.z), (q.x, q.y, q.z, q.w), (v.x, v.y), w.z

    def sim_time(self):
        return rospy.ServiceProxy(self.gazebo + "/get_world_properties", GetWorldProperties)().sim_time

    def drive(self, linear, steer, seconds):
        """Send (linear, steer) at COMMAND_RATE for ``seconds`` of sim time, sampling the rear axle's ground truth
        on the way; then stop and wait for the body to come to rest."""
        samples, end = [], self.sim_time() + seconds
        deadline = time.monotonic() + 20 * seconds + 30
        msg = Twist()
        msg.linear.x, msg.angular.z = linear, steer
        while True:
            now = self.sim_time()
            if now >= end:
                break
            self.assertLess(time.monotonic(), deadline, "sim time stalled while driving")
            self.cmd.publish(msg)
            (x, y, z), q, v, w = self.body()
            samples.append((now, arc_check.axle_sample(now, (x, y), yaw_of(_Q(q)), v, w, self.rear_axle), z))
            rospy.sleep(1.0 / COMMAND_RATE)
        self.odom_while_driving = self.odom.get()
        self.cmd.publish(Twist())
        wait_for(lambda: math.hypot(*self.body()[2]) < 0.01 or self.cmd.publish(Twist()), 30.0, "the body stopped")
        return samples

    def test_1_world_api_where_the_launch_file_put_gazebo_and_controllers_running(self):
        world = rospy.ServiceProxy(self.gazebo + "/get_world_properties", GetWorldProperties)
        wait_for(lambda: self.model in world().model_names, 60.0, f"{self.model} spawned ({self.gazebo})")
        listing = rospy.ServiceProxy(self.ns + "/controller_manager/list_controllers", ListControllers)
        rospy.wait_for_service(self.ns + "/controller_manager/list_controllers", 30.0)

        def running():
            states = {c.name: c.state for c in listing().controller}
            return states.get("ackermann_steering_controller") == "running" and \
                states.get("joint_state_publisher") == "running"
        wait_for(running, 60.0, "the spawner started both controllers")
        clock = Latest("/clock", Clock)
        wait_for(clock.get, 10.0, "/clock (global, wherever Gazebo's node is)")
        wait_for(lambda: abs(self.body()[0][2] - self.rest_height) < 0.01 and math.hypot(*self.body()[2]) < 0.01,
                 60.0, f"the body at rest at its height {self.rest_height} m after the drop")

    def test_2_straight(self):
        start = self.body()
        samples = self.drive(STRAIGHT_SPEED, 0.0, STRAIGHT_SECONDS)
        end = self.body()
        travelled = math.hypot(end[0][0] - start[0][0], end[0][1] - start[0][1])
        turned = abs(yaw_of(_Q(end[1])) - yaw_of(_Q(start[1])))
        figure(f"{self.model} straight: {travelled:.3f} m for {STRAIGHT_SPEED * STRAIGHT_SECONDS:.2f} m commanded, "
               f"heading changed {turned:.4f} rad")
        commanded = STRAIGHT_SPEED * STRAIGHT_SECONDS
        self.assertAlmostEqual(travelled, commanded, delta=0.1 * commanded)
        self.assertLess(turned, 0.02)
        worst = max(abs(arc_check.slip_angle(s)) for _, s, _ in samples)
        self.assertLess(worst, arc_check.MAX_SLIP)
        self.assertLess(max(abs(z - self.rest_height) for *_, z in samples), 0.02, "the body stays on its wheels")

    def test_3_arc_at_the_geometry_radius_without_slip(self):
        for steer in (arc_check.ARC_STEER, -arc_check.ARC_STEER):
            samples = self.drive(self.arc_speed, steer, self.arc_seconds)
            steady = [s for t, s, _ in samples if t >= samples[0][0] + 1.0]  # past the steering's travel
            radius_range = None
            if self.steer_bot is not None:  # the body turns between the radii its two front wheels imply
                from diffbot_sim.control.steer_bot_hardware import linkage_angles, steer_bot_config

                cfg = steer_bot_config(self.steer_bot, rospy.get_param(self.ns + "/gains"), self.ns)
                radius_range = arc_check.front_wheel_radii(self.wheelbase, self.track, *linkage_angles(steer, cfg))
            result = arc_check.arc(steady, self.wheelbase, steer, radius_range=radius_range)
            if radius_range:
                figure(f"{self.model} front wheels at steer {steer:+.2f} imply radii {abs(radius_range[0]):.3f} and "
                       f"{abs(radius_range[1]):.3f} m")
            odom = self.odom_while_driving
            figure(f"{self.model} arc at steer {steer:+.2f} rad: radius {result.radius:.3f} m (geometry "
                   f"{result.expected:.3f} m, error {100 * (result.radius / result.expected - 1):+.2f} %), slip up to "
                   f"{result.max_slip:.4f} rad, turned {result.turned:.2f} rad; odometry's yaw rate "
                   f"{odom.twist.twist.angular.z:+.3f} rad/s (geometry {self.arc_speed / result.expected:.3f}), at "
                   f"{self.arc_speed:g} m/s")
            self.assertTrue(result.passed, "; ".join(result.failures))
            self.assertGreater(result.turned * steer, 0, "turned toward the steered side (REP 103: + is left)")
            self.assertLess(max(abs(z - self.rest_height) for *_, z in samples), 0.02)


def _Q(q):
    class Quat:
        pass
    out = Quat()
    out.x, out.y, out.z, out.w = q
    return out


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_car_like", CarLikeTest, sys.argv)
