#!/usr/bin/env python3
"""Helper process of loop_modes.test (not a test itself): a controller that steers by odometry alone.

    odom_follower.py        (started by test_loop_modes.py as its own process: its own node, /odom_follower)

It subscribes ``/odom`` only (no sensor topic) and publishes ``/cmd_vel`` from a rospy.Timer of 0.1 s of sim
time: the shape of a waypoint tour or a path follower. While ``/odom_follower/active`` (std_msgs/Bool) is true it
drives a 1.2 m square from where the first odometry after the activation says it is, turning towards each
corner in turn, and burns ~15 ms of CPU per tick as a real controller's computation would; when it turns false
it publishes a zero Twist once. A jump back of sim time (reset_simulation) starts the square again. Prints
``READY`` when its /cmd_vel publisher is connected to the simulator.
"""
import math
import sys
import threading
import time

import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from std_msgs.msg import Bool

from diffbot_sim.transforms import yaw_from_quaternion

SIDE = 1.2  # m
SPEED = 0.25  # m/s
REACHED = 0.08  # m: a corner this close is passed


class Follower:
    def __init__(self):
        self.lock = threading.Lock()
        self.pose = None
        self.active = False
        self.corners = None
        self.last_time = 0.0
        self.cmd = rospy.Publisher("/cmd_vel", Twist, queue_size=1)
        rospy.Subscriber("/odom", Odometry, self._odom, queue_size=1)
        rospy.Subscriber("/odom_follower/active", Bool, self._active, queue_size=1)
        self.timer = rospy.Timer(rospy.Duration(0.1), self._tick, reset=True)  # survives reset_simulation

    def _odom(self, msg):
        if msg.header.stamp.to_sec() > rospy.get_time() + 0.05:
            return  # stamped ahead of the clock: sent before a reset_simulation, a pose of the last run
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        with self.lock:
            self.pose = (p.x, p.y, yaw_from_quaternion(q.x, q.y, q.z, q.w))

    def _active(self, msg):
        with self.lock:
            # The square starts from the first odometry after this: the pose kept from before a reset is the
            # last run's end (a square built on it once took the fast path 1.76 m off the real-time one).
            self.active, self.corners, self.pose = msg.data, None, None
        if not msg.data:
            self.cmd.publish(Twist())

    def _tick(self, _event):
        now = rospy.get_time()
        with self.lock:
            if now < self.last_time:  # reset_simulation: start the square again, from odometry after it
                self.corners, self.pose = None, None
            self.last_time = now
            if not self.active or self.pose is None:
                return
            x, y, yaw = self.pose
            if self.corners is None:
                c, s = math.cos(yaw), math.sin(yaw)
                square = [(SIDE, 0.0), (SIDE, SIDE), (0.0, SIDE), (0.0, 0.0)] * 3
                self.corners = [(x + c * u - s * v, y + s * u + c * v) for u, v in square]
            while self.corners and math.hypot(self.corners[0][0] - x, self.corners[0][1] - y) < REACHED:
                self.corners.pop(0)
            target = self.corners[0] if self.corners else None
        end = time.monotonic() + 0.015
        work = 1.0
        while time.monotonic() < end:  # the controller's computation: CPU, not sleep
            work = math.sin(work) + 1.0
        twist = Twist()
        if target is not None:
            error = math.atan2(target[1] - y, target[0] - x) - yaw
            error = math.atan2(math.sin(error), math.cos(error))
            twist.angular.z = max(-1.5, min(1.5, 2.5 * error))
            twist.linear.x = SPEED if abs(error) < 0.5 else 0.05
        self.cmd.publish(twist)


def main():
    rospy.init_node("odom_follower")
    follower = Follower()
    deadline = time.monotonic() + 30.0
    while follower.cmd.get_num_connections() == 0:
        if time.monotonic() > deadline or rospy.is_shutdown():
            print("no subscriber of /cmd_vel within 30 s", flush=True)
            return 1
        time.sleep(0.02)
    print("READY", flush=True)
    rospy.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
