#!/usr/bin/env python3
"""A known load on a force-torque joint (tests/data/robots/ft_load.urdf): libgazebo_ros_ft_sensor.so reports the
force and torque the joint applies on the 2 kg load, in the load's frame, the torque about the joint: m g up and
-m g * 0.1 about y (the centre of mass 0.1 m beside it; g the world's, /gazebo/get_physics_properties); its
gaussianNoise has the stddev asked; the
<sensor type="force_torque"> measuring parent_to_child reads the negation."""
import statistics
import sys
import threading
import unittest

import rospy
import rostest
from geometry_msgs.msg import WrenchStamped
from simtest import figure, wait_for

MASS, ARM = 2.0, 0.1


class Samples:
    def __init__(self, topic):
        self.lock, self.items = threading.Lock(), []
        rospy.Subscriber(topic, WrenchStamped, self._keep, queue_size=1000)

    def _keep(self, msg):
        with self.lock:
            self.items.append(msg)

    def get(self, count):
        with self.lock:
            return list(self.items[-count:]) if len(self.items) >= count else None


def values(msg):
    w = msg.wrench
    return (w.force.x, w.force.y, w.force.z, w.torque.x, w.torque.y, w.torque.z)


class ForceTorqueTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_force_torque")
        cls.plain, cls.noisy, cls.ros2 = Samples("/ft_sensor"), Samples("/ft_noisy"), Samples("/ft_ros2/wrench")
        from gazebo_msgs.srv import GetPhysicsProperties
        rospy.wait_for_service("/gazebo/get_physics_properties", 60.0)
        global G
        G = -rospy.ServiceProxy("/gazebo/get_physics_properties", GetPhysicsProperties)().gravity.z

    def test_known_load(self):
        msgs = wait_for(lambda: self.plain.get(50), 60.0, "50 wrenches on /ft_sensor")
        last = values(msgs[-1])
        expected = (0.0, 0.0, MASS * G, 0.0, -MASS * G * ARM, 0.0)
        error = max(abs(a - b) for a, b in zip(last, expected))
        figure(f"wrench of the 2 kg load: force ({last[0]:.4f}, {last[1]:.4f}, {last[2]:.4f}) N, torque "
               f"({last[3]:.4f}, {last[4]:.4f}, {last[5]:.4f}) N m; expected (0, 0, {MASS * G:.4f}) and "
               f"(0, {-MASS * G * ARM:.4f}, 0): largest error {error:.2e}")
        for got, want in zip(last, expected):
            self.assertAlmostEqual(got, want, delta=0.002)
        self.assertEqual(msgs[-1].header.frame_id, "load")

    def test_noise_has_its_stddev(self):
        msgs = wait_for(lambda: self.noisy.get(400), 60.0, "400 noisy wrenches")
        fz = [m.wrench.force.z for m in msgs]
        spread = statistics.pstdev(fz)
        figure(f"gaussianNoise 0.5: force z stddev {spread:.3f} over {len(fz)} samples, mean {statistics.mean(fz):.3f}")
        self.assertAlmostEqual(spread, 0.5, delta=0.06)
        self.assertAlmostEqual(statistics.mean(fz), MASS * G, delta=0.1)

    def test_sensor_parent_to_child_is_negated(self):
        msgs = wait_for(lambda: self.ros2.get(5), 60.0, "/ft_ros2/wrench")
        v = values(msgs[-1])
        self.assertAlmostEqual(v[2], -MASS * G, delta=0.01)
        self.assertAlmostEqual(v[4], MASS * G * ARM, delta=0.01)


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_force_torque", ForceTorqueTest, sys.argv)
