#!/usr/bin/env python3
"""librealsense_gazebo_plugin.so as its users launch it: /camera/color (rgb8), /camera/infra1 and infra2 (8UC1)
and /camera/depth (16UC1 in mm) with their camera_info (centre at width/2, height/2) in the optical frames named;
the depth image's middle reads the box's face 1.2 m ahead (1200 mm), the colour image is red there."""
import sys
import unittest

import numpy as np
import rospy
import rostest
from sensor_msgs.msg import CameraInfo, Image
from simtest import Latest, figure, wait_for


class RealSenseTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_realsense")
        cls.images = {s: Latest(f"/camera/{s}/image_raw", Image) for s in ("color", "infra1", "infra2", "depth")}
        cls.infos = {s: Latest(f"/camera/{s}/camera_info", CameraInfo) for s in ("color", "depth")}

    def test_streams_and_depth(self):
        msgs = {s: wait_for(latest.get, 30.0, f"/camera/{s}/image_raw") for s, latest in self.images.items()}
        self.assertEqual([msgs[s].encoding for s in ("color", "infra1", "infra2", "depth")],
                         ["rgb8", "8UC1", "8UC1", "16UC1"])
        self.assertEqual(msgs["depth"].header.frame_id, "d435_depth_optical_frame")
        depth = np.frombuffer(msgs["depth"].data, np.uint16).reshape(120, 160)
        middle = int(depth[60, 80])
        figure(f"RealSense depth at the image's middle: {middle} mm (the box's face: 1200 mm)")
        self.assertAlmostEqual(middle, 1200, delta=3)
        color = np.frombuffer(msgs["color"].data, np.uint8).reshape(120, 160, 3)
        self.assertGreater(int(color[60, 80, 0]), 150)
        info = wait_for(self.infos["depth"].get, 30.0, "depth camera_info")
        self.assertEqual((info.K[2], info.K[5]), (80.0, 60.0))
        self.assertAlmostEqual(info.K[0], 0.5 * 160 / np.tan(0.5 * 1.211), places=3)


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_realsense", RealSenseTest, sys.argv)
