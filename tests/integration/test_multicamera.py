#!/usr/bin/env python3
"""A stereo pair through ROS (libgazebo_ros_multicamera.so): each camera publishes its image and camera_info under
<cameraName>/left and /right, the right one's P[3] = -f * hackBaseline, and the red box's vertical edges appear
shifted between the two images by the disparity the geometry gives, f * baseline / depth (pixels).

Parameters: ~face_x (m, the box's near face), ~camera_x (m, the cameras' x), ~edges_y ([left, right] edge y, m),
~baseline (m).
"""
import sys
import unittest

import numpy as np
import rospy
import rostest
from sensor_msgs.msg import CameraInfo, Image
from simtest import Latest, figure, wait_for


def red_columns(msg):
    """(first, last) image columns where the middle row is red (the box's face)."""
    image = np.frombuffer(msg.data, np.uint8).reshape(msg.height, msg.width, 3).astype(int)
    row = image[msg.height // 2]
    red = (row[:, 0] > 150) & (row[:, 1] < 80) & (row[:, 2] < 80)
    columns = np.flatnonzero(red)
    assert columns.size, "no red in the middle row"
    return columns[0], columns[-1]


class MultiCameraTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_multicamera")
        cls.images = {side: Latest(f"/stereo/{side}/image_raw", Image) for side in ("left", "right")}
        cls.infos = {side: Latest(f"/stereo/{side}/camera_info", CameraInfo) for side in ("left", "right")}

    def test_camera_infos_carry_the_baseline(self):
        left = wait_for(self.infos["left"].get, 30.0, "left camera_info")
        right = wait_for(self.infos["right"].get, 30.0, "right camera_info")
        f = left.K[0]
        self.assertAlmostEqual(f, 320 / (2 * np.tan(1.047 / 2)), places=3)
        self.assertEqual(left.P[3], 0.0)
        self.assertAlmostEqual(right.P[3], -f * rospy.get_param("~baseline"), places=6)
        self.assertEqual(left.header.frame_id, "camera_link")

    def test_disparity_of_the_box_edges(self):
        left = wait_for(self.images["left"].get, 30.0, "left image")
        right = wait_for(self.images["right"].get, 30.0, "right image")
        info = wait_for(self.infos["right"].get, 30.0, "right camera_info")
        f, baseline = info.K[0], -info.P[3] / info.K[0]
        depth = rospy.get_param("~face_x") - rospy.get_param("~camera_x")
        expected = f * baseline / depth
        (l0, l1), (r0, r1) = red_columns(left), red_columns(right)
        measured = ((l0 - r0) + (l1 - r1)) / 2.0
        figure(f"stereo disparity of the box's edges: {l0 - r0} and {l1 - r1} px (mean {measured:.2f}), geometry "
               f"f*B/Z = {f:.2f}*{baseline:.3f}/{depth:.2f} = {expected:.2f} px, error {measured - expected:+.2f} px")
        self.assertAlmostEqual(l0 - r0, expected, delta=1.0)
        self.assertAlmostEqual(l1 - r1, expected, delta=1.0)
        # each camera sees the box where its own pose puts it: the left camera sees it further right
        cx = info.K[2]
        y_left = rospy.get_param("~edges_y")[0]
        predicted = cx - f * (y_left - baseline / 2) / depth - 1  # Gazebo's cx counts from 1
        self.assertAlmostEqual(l0, predicted, delta=1.5)


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_multicamera", MultiCameraTest, sys.argv)
