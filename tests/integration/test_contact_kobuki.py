#!/usr/bin/env python3
"""A Kobuki driven into a box: its centre bumper is PRESSED when its body meets the box (ground truth: the gap
between the body's cylinder and the box's face), none before, RELEASED when it backs away; libgazebo_ros_bumper's
bumper_states carries the contact (the lumped collision's name, normals from the box toward the robot, positions
on the face, a force pushing the robot back) and is empty before; the wheels never drop, no cliff is seen.

Parameters: ~box_face_x (m, the box's near face), ~body_radius (m, base_link's cylinder about base_footprint).
"""
import sys
import threading
import time
import unittest

import rospy
import rostest
from gazebo_msgs.msg import ContactsState
from geometry_msgs.msg import Twist
from kobuki_msgs.msg import BumperEvent, CliffEvent, WheelDropEvent
from rosgraph_msgs.msg import Clock
from simtest import Latest, Truth, figure, wait_for

CMD = "/mobile_base/commands/velocity"
SPEED = 0.1  # m/s toward the box
TOUCH = 0.004  # m: no PRESSED while the body is farther than this from the face (1 update at 0.1 m/s: 2 mm)
MET = 0.001  # m: the body meets the face (PyBullet's contact margin)


class Events:
    """Every message of a topic with the sim time it arrived at (callbacks only store)."""

    def __init__(self, topic, kind, clock):
        self.lock, self.items, self.clock = threading.Lock(), [], clock
        rospy.Subscriber(topic, kind, self._keep, queue_size=100)

    def _keep(self, msg):
        now = self.clock.get()
        with self.lock:
            self.items.append((now.clock.to_sec() if now else 0.0, msg))

    def all(self):
        with self.lock:
            return list(self.items)


class ContactKobukiTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_contact_kobuki")
        cls.face = rospy.get_param("~box_face_x")
        cls.radius = rospy.get_param("~body_radius")
        cls.clock = Latest("/clock", Clock)
        cls.truth = Truth()
        cls.bumper = Events("/mobile_base/events/bumper", BumperEvent, cls.clock)
        cls.cliff = Events("/mobile_base/events/cliff", CliffEvent, cls.clock)
        cls.drops = Events("/mobile_base/events/wheel_drop", WheelDropEvent, cls.clock)
        cls.states = Events("/bumper_states", ContactsState, cls.clock)
        cls.cmd = rospy.Publisher(CMD, Twist, queue_size=1)
        wait_for(cls.truth.last, 60.0, "ground truth")

    def gap(self, sample):
        return self.face - (sample.x + self.radius)

    def gap_at(self, t):
        """The body's gap to the face at sim time ``t`` (the ground-truth sample at or just before it)."""
        before = [s for s in self.truth.between(0.0, t)]
        self.assertTrue(before, f"no ground truth before {t}")
        return self.gap(before[-1])

    def drive(self, speed, until, timeout):
        msg = Twist()
        msg.linear.x = speed
        deadline = time.monotonic() + timeout
        while not until():
            self.assertLess(time.monotonic(), deadline, f"timed out driving at {speed} m/s")
            self.cmd.publish(msg)
            rospy.sleep(0.05)

    def test_bump_and_back_away(self):
        wait_for(lambda: self.states.all(), 20.0, "bumper_states while nothing touches")
        self.assertEqual([m for _, m in self.states.all() if m.states], [], "contacts before anything was touched")
        start = self.truth.last()
        self.assertGreater(self.gap(start), 0.3)
        self.drive(SPEED, lambda: any(m.state == BumperEvent.PRESSED for _, m in self.bumper.all()), 60.0)
        pressed_at, pressed = next((t, m) for t, m in self.bumper.all() if m.state == BumperEvent.PRESSED)
        self.assertEqual(pressed.bumper, BumperEvent.CENTER)
        touched = next(s for s in self.truth.between(0.0, 1e9) if self.gap(s) <= MET)
        gap_at_event = self.gap_at(pressed_at)
        figure(f"bumper PRESSED at sim {pressed_at:.3f} s (as received) with the body {1000 * gap_at_event:+.1f} mm "
               f"from the box; the body met it ({1000 * MET:.0f} mm) at {touched.t:.3f} s: "
               f"{pressed_at - touched.t:+.3f} s before the event arrived")
        self.assertLessEqual(gap_at_event, TOUCH, "PRESSED before the body met the box")
        self.assertLess(pressed_at - touched.t, 0.06, "PRESSED long after the body met the box (updates at 50 Hz)")
        # keep pushing for a while: bumper_states shows the contact as gazebo_ros_bumper would
        t0 = pressed_at
        self.drive(SPEED, lambda: (self.clock.get().clock.to_sec() if self.clock.get() else 0) > t0 + 0.5, 30.0)
        touching = [m for t, m in self.states.all() if t > t0 and m.states]
        self.assertTrue(touching, "bumper_states empty while pressed against the box")
        msg = touching[-1]
        self.assertEqual(msg.header.frame_id, "base_footprint")
        state = msg.states[0]
        self.assertTrue(state.collision1_name.endswith("::base_footprint::base_footprint_fixed_joint_lump__"
                                                       "base_link_collision"), state.collision1_name)
        self.assertEqual(state.collision2_name, "box::link::collision")
        for p, n, d in zip(state.contact_positions, state.contact_normals, state.depths):
            self.assertAlmostEqual(p.x, self.face, delta=0.005)
            self.assertLess(n.x, -0.99, "the normal points from the box toward the robot")
            self.assertGreaterEqual(d, 0.0)
        self.assertLess(state.total_wrench.force.x, -0.1, "the box pushes the robot back")
        figure(f"bumper_states while pressed: {len(state.contact_positions)} points at x "
               f"{state.contact_positions[0].x:.4f} m (face {self.face}), force {state.total_wrench.force.x:.2f} N")
        # back away
        self.drive(-SPEED, lambda: any(m.state == BumperEvent.RELEASED for _, m in self.bumper.all()), 30.0)
        released_at = next(t for t, m in self.bumper.all() if m.state == BumperEvent.RELEASED)
        gap_released = self.gap_at(released_at)
        figure(f"bumper RELEASED at sim {released_at:.3f} s with the body {1000 * gap_released:+.1f} mm from the box")
        self.assertGreater(gap_released, -0.001)
        self.assertLess(gap_released, 0.02, "RELEASED long after the body left the box")
        self.cmd.publish(Twist())
        self.assertEqual([m.bumper for _, m in self.bumper.all()], [BumperEvent.CENTER, BumperEvent.CENTER])
        self.assertEqual(self.drops.all(), [], "a wheel dropped on flat ground")
        self.assertEqual(self.cliff.all(), [], "a cliff on flat ground")


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_contact_kobuki", ContactKobukiTest, sys.argv)
