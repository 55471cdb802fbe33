#!/usr/bin/env python3
"""The cameras of tests/data/robots/camera_robot.urdf in tests/data/worlds/camera_room.world, through ROS:
CameraInfo is Gazebo's K and P; the red box's near face shows at the pixel K predicts from the ground truth
(Gazebo's 1-based centre: the 0-based index is one less; +-1 px), in red; the depth image reads the distance
to that face along the optical axis (+-1 cm) and NaN where nothing is; the organised cloud's point there is
the face centre in the optical frame and red; images come at the sensor's 10 Hz of sim time. Callbacks only
record; waits poll with deadlines."""
import math
import struct
import sys
import threading
import time
import unittest

import numpy as np
import rospy
import rostest
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, Image, PointCloud2

from diffbot_sim.sensors import camera as cam

SIM = "/bullet_sim"
CAMERA_IN_FOOTPRINT = (0.1, 0.0, 0.083)  # base_footprint -> base_link 0.033 up, base_link -> camera (0.1, 0, 0.05)
FACE_CENTRE = (1.3, 0.0, 0.2)  # the red box's near face (world file's comment)


class Recorder:
    def __init__(self, keep=50):
        self.lock = threading.Lock()
        self.msgs = []
        self.keep = keep

    def __call__(self, msg):
        with self.lock:
            self.msgs = (self.msgs + [msg])[-self.keep:]

    def latest(self):
        with self.lock:
            return self.msgs[-1] if self.msgs else None

    def all(self):
        with self.lock:
            return list(self.msgs)


class CameraTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_camera")
        cls.rec = {name: Recorder() for name in ("image", "info", "depth", "depth_info", "points", "truth")}
        topics = (("/front_camera/image_raw", Image, "image"), ("/front_camera/camera_info", CameraInfo, "info"),
                  ("/depth_camera/depth/image_raw", Image, "depth"),
                  ("/depth_camera/depth/camera_info", CameraInfo, "depth_info"),
                  ("/depth_camera/depth/points", PointCloud2, "points"), (SIM + "/ground_truth", Odometry, "truth"))
        cls.subs = [rospy.Subscriber(t, c, cls.rec[k], queue_size=5) for t, c, k in topics]

    def wait_for(self, name, count=1, timeout=20.0):
        deadline = time.monotonic() + timeout
        while len(self.rec[name].all()) < count:
            if time.monotonic() > deadline or rospy.is_shutdown():
                self.fail(f"timed out after {timeout} s waiting for {count} {name} messages")
            time.sleep(0.01)
        return self.rec[name].latest()

    def face_in_optical(self):
        """The red face's centre in the camera's optical frame, from the ground truth of the base."""
        truth = self.wait_for("truth")
        p, q = truth.pose.pose.position, truth.pose.pose.orientation
        rot = cam.quaternion_matrix((q.x, q.y, q.z, q.w))
        camera = np.array([p.x, p.y, p.z]) + rot @ np.array(CAMERA_IN_FOOTPRINT)
        body = rot.T @ (np.array(FACE_CENTRE) - camera)
        return cam.body_to_optical(tuple(body))

    def predicted_pixel(self, info):
        u, v = cam.project(info.K, self.face_in_optical())
        return u - 1.0, v - 1.0  # Gazebo's K counts from 1

    def test_camera_info_is_gazebos(self):
        info = self.wait_for("info")
        f = 320 / (2 * math.tan(1.047 / 2))
        self.assertEqual((info.width, info.height, info.header.frame_id), (320, 240, "camera_optical_frame"))
        np.testing.assert_allclose(info.K, [f, 0, 160.5, 0, f, 120.5, 0, 0, 1], atol=1e-6)
        np.testing.assert_allclose(info.P, [f, 0, 160.5, -f * 0.07, 0, f, 120.5, 0, 0, 0, 1, 0], atol=1e-6)
        self.assertEqual(info.distortion_model, "plumb_bob")
        self.assertEqual(len(info.D), 5)

    def test_image_shows_the_red_box_where_k_says(self):
        info = self.wait_for("info")
        msg = self.wait_for("image", 3)
        self.assertEqual((msg.width, msg.height, msg.encoding, msg.step), (320, 240, "rgb8", 960))
        self.assertEqual(msg.header.frame_id, "camera_optical_frame")
        rgb = np.frombuffer(msg.data, np.uint8).reshape(240, 320, 3)
        u, v = self.predicted_pixel(info)
        pixel = rgb[int(round(v)), int(round(u))]
        self.assertTrue(pixel[0] > 150 and pixel[1] < 60 and pixel[2] < 60, f"pixel {pixel} at ({u:.1f}, {v:.1f})")
        red = (rgb[:, :, 0] > 150) & (rgb[:, :, 1] < 60) & (rgb[:, :, 2] < 60)
        cols = np.nonzero(red[int(round(v))])[0]
        rows = np.nonzero(red[:, int(round(u))])[0]
        # The face's horizontal centre (the top face is hidden, the side faces too: it is straight ahead).
        self.assertAlmostEqual((cols.min() + cols.max()) / 2.0, u, delta=1.0)
        self.assertAlmostEqual((rows.min() + rows.max()) / 2.0, v, delta=1.5)
        blue = (rgb[:, :, 2] > 150) & (rgb[:, :, 0] < 60) & (rgb[:, :, 1] < 60)
        self.assertTrue(blue[:, :40].any(), "the blue box (Gazebo/Blue script) shows on the left")

    def test_images_at_sensor_rate_in_sim_time(self):
        self.wait_for("image", 6)
        msgs = self.rec["image"].all()
        # Every image published is on the 10 Hz grid of sim time: none early, late or twice. Published messages
        # are numbered (header.seq), so an image lost on the way here (a loaded machine starves this node's
        # receiving thread, and its queue of 5 drops the oldest) is a jump in seq, not a late image: each gap
        # must be 0.1 s per image published.
        stamps = np.array([m.header.stamp.to_sec() for m in msgs])
        published = np.diff([m.header.seq for m in msgs])
        gaps = np.diff(stamps)
        self.assertTrue(np.all(published >= 1), f"images out of order or twice: seq steps {published}")
        self.assertTrue(np.all(np.abs(gaps - 0.1 * published) < 0.011), f"gaps {gaps} for seq steps {published}")
        # Stamped in sim time: the next image after the clock's now is stamped within a second of it.
        now = rospy.get_time()
        deadline = time.monotonic() + 20.0
        while not any(m.header.stamp.to_sec() >= now for m in self.rec["image"].all()):
            if time.monotonic() > deadline or rospy.is_shutdown():
                self.fail(f"timed out after 20 s waiting for an image stamped after sim time {now:.2f}")
            time.sleep(0.01)
        stamp = min(m.header.stamp.to_sec() for m in self.rec["image"].all() if m.header.stamp.to_sec() >= now)
        self.assertLess(stamp - now, 1.0, f"the first image after sim time {now:.2f} is stamped {stamp:.2f}")

    def test_depth_image_reads_the_distance(self):
        info = self.wait_for("depth_info")
        msg = self.wait_for("depth")
        self.assertEqual((msg.width, msg.height, msg.encoding, msg.step), (160, 120, "32FC1", 640))
        depth = np.frombuffer(msg.data, "<f4").reshape(120, 160)
        face = self.face_in_optical()
        u, v = cam.project(info.K, face)
        self.assertAlmostEqual(float(depth[int(round(v - 1)), int(round(u - 1))]), face[2], delta=0.01)
        self.assertTrue(np.isnan(depth[0, 0]), "sky is NaN")

    def test_point_cloud_point_is_the_face(self):
        info = self.wait_for("depth_info")
        msg = self.wait_for("points")
        self.assertEqual((msg.width, msg.height, msg.point_step, msg.is_dense), (160, 120, 32, False))
        self.assertEqual([f.name for f in msg.fields], ["x", "y", "z", "rgb"])
        face = self.face_in_optical()
        u, v = cam.project(info.K, face)
        i, j = int(round(u - 1)), int(round(v - 1))
        x, y, z = struct.unpack_from("<3f", msg.data, (j * 160 + i) * 32)
        self.assertAlmostEqual(z, face[2], delta=0.01)
        # Lateral position of the pixel's ray at the face: within one pixel's width of the face centre.
        self.assertAlmostEqual(x, face[0], delta=1.5 * face[2] / info.K[0])
        self.assertAlmostEqual(y, face[1], delta=1.5 * face[2] / info.K[0])
        r, g, b = msg.data[(j * 160 + i) * 32 + 16:(j * 160 + i) * 32 + 19]
        self.assertTrue(r > 150 and g < 60 and b < 60)


if __name__ == "__main__":
    rostest.rosrun("diffbot_sim", "test_camera", CameraTest, sys.argv)
