"""``libgazebo_ros_openni_kinect.so`` on a ``<sensor type="depth">`` (ROS 1), and ``libgazebo_ros_camera.so``
on one (ROS 2): a colour image, a depth image and an organised point cloud, rendered in one pass.

ROS 1 topics under ``<robotNamespace>/<cameraName>``: ``imageTopicName`` (ir/image_raw, rgb8),
``cameraInfoTopicName`` (ir/camera_info), ``depthImageTopicName`` (depth/image_raw: 32FC1 metres, NaN outside
(``pointCloudCutoff`` 0.4, ``pointCloudCutoffMax`` 5.0); ``useDepth16UC1Format``: 16UC1 millimetres, 0
invalid), ``depthImageCameraInfoTopicName`` (depth/camera_info), ``pointCloudTopicName`` (points:
PointCloud2 x y z rgb in the optical convention, NaN points outside the cutoffs, ``is_dense`` false).
ROS 2: ``<camera_name>/image_raw``, ``camera_info``, ``depth/image_raw`` (below ``min_depth`` 0.4: -inf, at
or beyond ``max_depth``: +inf, REP 117), ``depth/camera_info``, ``points``. The depth is z-depth along the
optical axis (REP 118). Rendered only while the image, depth or points topic has a subscriber; the cloud
is built only while ``points`` has one.
"""
import math

import numpy as np
from sensor_msgs.msg import CameraInfo, Image, PointCloud2

from diffbot_sim.messages import common as ros_msgs
from diffbot_sim.plugins.base import summary_key
from diffbot_sim.plugins.camera_base import CameraBase
from diffbot_sim.sensors import camera as cam


class DepthCamera(CameraBase):
    filename = "libgazebo_ros_openni_kinect.so"

    def __init__(self, ctx, sensor, cfg, tags):
        super().__init__(ctx, sensor, cfg, tags)
        ros2 = tags.dialect == "ros2"
        if ros2:
            self.filename = "libgazebo_ros_camera.so (depth)"
        v = tags.values
        self.ros2 = ros2
        self.low = v.get("cutoff", 0.4)
        self.high = v.get("cutoff_max", math.inf if ros2 else 5.0)
        self.depth16 = bool(v.get("depth16", False)) and not ros2
        names = (("image_raw", "camera_info", "depth/image_raw", "depth/camera_info", "points") if ros2 else
                 ("ir/image_raw", "ir/camera_info", "depth/image_raw", "depth/camera_info", "points"))
        keys = ("image_topic", "info_topic", "depth_topic", "depth_info_topic", "points_topic")
        topics = [self.topic(k, n) for k, n in zip(keys, names)]
        self.image_pub = ctx.publisher(topics[0], Image)
        self.info_pub = ctx.publisher(topics[1], CameraInfo)
        self.depth_pub = ctx.publisher(topics[2], Image)
        self.depth_info_pub = ctx.publisher(topics[3], CameraInfo)
        self.points_pub = ctx.publisher(topics[4], PointCloud2)
        self.image = ros_msgs.ImageBuilder(self.frame, cfg.width, cfg.height, "rgb8", 3)
        self.depth = ros_msgs.ImageBuilder(self.frame, cfg.width, cfg.height,
                                           "16UC1" if self.depth16 else "32FC1", 2 if self.depth16 else 4)
        self.info = ros_msgs.camera_info(self.frame, self.intrinsics)
        self.depth_info = ros_msgs.camera_info(self.frame, self.intrinsics)
        self.cloud = ros_msgs.PointCloudBuilder(self.frame, cfg.width, cfg.height, cam.CLOUD_FIELDS,
                                                cam.CLOUD_POINT_STEP)
        self.focal = cam.focal_length(cfg.width, cfg.hfov)

    def publishers(self):
        return [self.image_pub, self.info_pub, self.depth_pub, self.depth_info_pub, self.points_pub]

    def depth_image(self, depth):
        """The published depth: NaN outside (low, high) (ROS 1), or -inf/+inf (ROS 2); 16UC1 mm, 0 invalid."""
        if self.ros2:
            out = np.array(depth, np.float32, copy=True)
            with np.errstate(invalid="ignore"):
                out[np.isnan(out) | (out >= self.high)] = np.inf
                out[out <= self.low] = -np.inf
            return out
        out = cam.cutoff(depth, self.low, self.high)
        if self.depth16:
            return np.where(np.isnan(out), 0, np.rint(out * 1000.0)).astype("<u2")
        return out

    def after_step(self, now, stamp, transforms):
        if not self.due(now):
            return
        want_image = self.image_pub.get_num_connections()
        want_depth = self.depth_pub.get_num_connections()
        want_points = self.points_pub.get_num_connections()
        if want_image or want_depth or want_points:
            rgb, depth = self.render()
            if want_image:
                self.image_pub.publish(self.image.build(stamp, rgb.tobytes()))
            if want_depth:
                self.depth_pub.publish(self.depth.build(stamp, self.depth_image(depth).tobytes()))
            if want_points:
                points = cam.cloud_points(cam.cutoff(depth, self.low, self.high), self.focal)
                dense = bool(np.isfinite(points).all())
                self.points_pub.publish(self.cloud.build(stamp, cam.cloud_bytes(points, rgb), dense))
        for pub, msg in ((self.info_pub, self.info), (self.depth_info_pub, self.depth_info)):
            if pub.get_num_connections():
                msg.header.stamp = stamp
                pub.publish(msg)

    def summary(self):
        out = super().summary()
        out[summary_key("camera", self.cfg.name) + "/depth_topic"] = self.depth_pub.resolved_name
        out[summary_key("camera", self.cfg.name) + "/points_topic"] = self.points_pub.resolved_name
        return out


def create(ctx, sensor, plugin_element, params):
    """The depth camera of ``sensor`` (openni_kinect tags).

    Raises:
        ConfigError: a value that cannot be used. ModelError: the sensor's link is not in the model.
    """
    cfg = cam.parse_sensor(sensor.element, sensor.path, sensor.name)
    tags = cam.read_plugin(plugin_element, sensor.path)
    tags.dialect = "ros1"
    if sensor.type != "depth":
        ctx.warnings.append(f"{sensor.path}: libgazebo_ros_openni_kinect.so on a '{sensor.type}' sensor; "
                            "simulated as a depth camera")
    return DepthCamera(ctx, sensor, cfg, tags)
